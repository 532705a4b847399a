// bodyscan sheet: the measurement sheet of a body mesh (the automatic ISO 8559-1
// set) as PDF, CSV or JSON, in mm, cm or inches.
#include <cstdio>
#include <ctime>
#include <string>

#include "core/command_line.hpp"
#include "recon/io/atomic_file.hpp"
#include "recon/io/ply.hpp"
#include "recon/measure/body_measurements.hpp"
#include "storage/formats/measurement_sheet.hpp"

namespace bodyscan::cli {

namespace {

constexpr const char* kUsage =
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
    "Exit status: 0 written, 1 the mesh or the measurements failed, 2 bad arguments.\n";

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

int run_sheet(int argc, char** argv) {
  std::string in, out, unit_text = "cm";
  storage::MeasurementSheet sheet;
  BodyMeasureOptions mo;
  CommandLine cl("bodyscan sheet", kUsage);
  cl.positional("MESH.ply", &in, /*required=*/false);
  cl.option("-o|--output", &out);
  cl.option("--unit", &unit_text);
  cl.option("--floor", &mo.floor_y);
  cl.option("--customer", &sheet.customer_ref);
  cl.option("--scan", &sheet.scan_id);
  cl.option("--date", &sheet.taken_at);
  cl.option("--operator", &sheet.operator_name);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  auto unit = storage::parse_length_unit(unit_text);
  if (!unit.ok()) return cl.fail(unit.status().message());
  if (in.empty() || out.empty()) return cl.fail("give a MESH.ply and -o OUT");
  if (!ends_with(out, ".pdf") && !ends_with(out, ".csv") && !ends_with(out, ".json"))
    return cl.fail("output '" + out + "' must end in .pdf, .csv or .json");
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
