// bodyscan sheet: the measurement sheet of a body mesh (the automatic ISO 8559-1
// set) as PDF, CSV or JSON, in mm, cm or inches.
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include "recon/io/atomic_file.hpp"
#include "recon/io/ply.hpp"
#include "recon/measure/body_measurements.hpp"
#include "storage/formats/measurement_sheet.hpp"

namespace bodyscan::cli {

namespace {

void usage(FILE* out) {
  std::fputs(
      "usage: bodyscan sheet MESH.ply -o OUT.pdf|OUT.csv|OUT.json [options]\n"
      "\n"
      "Measures the body (mm, Y up, facing any way) and writes its measurement sheet: the\n"
      "automatic ISO 8559-1 set, each with its clause. The PDF is one A4 page with\n"
      "front and side silhouettes and the measured lines drawn on them.\n"
      "\n"
      "  --unit mm|cm|in        the sheet's unit (default cm)\n"
      "  --floor Y              the floor's height (default: the mesh's lowest point)\n"
      "  --customer REF         the customer's reference printed on the sheet\n"
      "  --scan ID              the scan's id\n"
      "  --date TEXT            when the scan was taken (default: now, UTC)\n"
      "  --operator NAME        who took it\n"
      "\n"
      "Exit status: 0 written, 1 the mesh or the measurements failed, 2 bad arguments.\n",
      out);
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

int run_sheet(int argc, char** argv) {
  std::string in, out, unit_text = "cm";
  storage::MeasurementSheet sheet;
  BodyMeasureOptions mo;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* name) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "bodyscan sheet: %s needs a value\n", name);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      usage(stdout);
      return 0;
    } else if (a == "-o" || a == "--output") {
      out = value("-o");
    } else if (a == "--unit") {
      unit_text = value("--unit");
    } else if (a == "--floor") {
      const char* v = value("--floor");
      char* end = nullptr;
      mo.floor_y = std::strtod(v, &end);
      if (end == v || *end != '\0') {
        std::fprintf(stderr, "bodyscan sheet: --floor expects a height in mm, got '%s'\n", v);
        return 2;
      }
    } else if (a == "--customer") {
      sheet.customer_ref = value("--customer");
    } else if (a == "--scan") {
      sheet.scan_id = value("--scan");
    } else if (a == "--date") {
      sheet.taken_at = value("--date");
    } else if (a == "--operator") {
      sheet.operator_name = value("--operator");
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "bodyscan sheet: unknown option '%s'\n", a.c_str());
      usage(stderr);
      return 2;
    } else if (in.empty()) {
      in = a;
    } else {
      std::fprintf(stderr, "bodyscan sheet: more than one input file ('%s')\n", a.c_str());
      return 2;
    }
  }
  auto unit = storage::parse_length_unit(unit_text);
  if (!unit.ok()) {
    std::fprintf(stderr, "bodyscan sheet: %s\n", unit.status().message().c_str());
    return 2;
  }
  if (in.empty() || out.empty()) {
    usage(stderr);
    return 2;
  }
  if (!ends_with(out, ".pdf") && !ends_with(out, ".csv") && !ends_with(out, ".json")) {
    std::fprintf(stderr, "bodyscan sheet: output '%s' must end in .pdf, .csv or .json\n", out.c_str());
    return 2;
  }
  if (sheet.taken_at.empty()) {
    char b[32];
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", &utc);
    sheet.taken_at = b;
  }
  auto mesh = read_ply_mesh(in);
  if (!mesh.ok()) {
    std::fprintf(stderr, "bodyscan sheet: %s\n", mesh.status().message().c_str());
    return 1;
  }
  auto body = measure_body(*mesh, mo);
  if (!body.ok()) {
    std::fprintf(stderr, "bodyscan sheet: %s: %s\n", in.c_str(), body.status().message().c_str());
    return 1;
  }
  sheet.entries = storage::sheet_entries(*body);
  std::string bytes;
  if (ends_with(out, ".csv")) {
    bytes = storage::sheet_csv(sheet, *unit);
  } else if (ends_with(out, ".json")) {
    bytes = storage::sheet_json(sheet, *unit).dump(1);
  } else {
    auto pdf = storage::sheet_pdf(sheet, *mesh, *unit);
    if (!pdf.ok()) {
      std::fprintf(stderr, "bodyscan sheet: %s\n", pdf.status().message().c_str());
      return 1;
    }
    bytes = std::move(*pdf);
  }
  const Status written = write_file_atomically(out, bytes);
  if (!written.ok()) {
    std::fprintf(stderr, "bodyscan sheet: %s\n", written.message().c_str());
    return 1;
  }
  std::printf("wrote %s: %zu measurements in %s\n", out.c_str(), sheet.entries.size(), storage::unit_symbol(*unit));
  return 0;
}

}  // namespace bodyscan::cli
