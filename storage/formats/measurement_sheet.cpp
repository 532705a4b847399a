#include "storage/formats/measurement_sheet.hpp"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "storage/formats/sheet_drawing.hpp"

namespace bodyscan::storage {

StatusOr<LengthUnit> parse_length_unit(std::string_view text) {
  if (text == "mm") return LengthUnit::kMillimetre;
  if (text == "cm") return LengthUnit::kCentimetre;
  if (text == "in" || text == "inch") return LengthUnit::kInch;
  return invalid_argument("unit: expected mm, cm or in, got '" + std::string(text) + "'");
}

const char* unit_symbol(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kCentimetre: return "cm";
    case LengthUnit::kInch: return "in";
    case LengthUnit::kMillimetre: break;
  }
  return "mm";
}

double from_mm(double mm, LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kCentimetre: return mm / 10;
    case LengthUnit::kInch: return mm / 25.4;
    case LengthUnit::kMillimetre: break;
  }
  return mm;
}

std::string format_length(double mm, LengthUnit unit) {
  char b[32];
  std::snprintf(b, sizeof b, unit == LengthUnit::kMillimetre ? "%.1f" : "%.2f", from_mm(mm, unit));
  return b;
}

std::vector<SheetEntry> sheet_entries(const BodyMeasurements& body) {
  std::vector<SheetEntry> out;
  out.reserve(body.measurements.size());
  for (const BodyMeasurement& m : body.measurements) {
    SheetEntry e;
    e.iso_clause = m.iso_clause, e.name = m.name, e.label = m.label, e.kind = m.kind;
    e.value_mm = m.value_mm;
    e.flagged = m.estimated();
    e.path = m.path, e.closed = m.closed;
    out.push_back(std::move(e));
  }
  return out;
}

std::string csv_field(const std::string& s) {
  std::string v = s;
  if (!v.empty() && (v[0] == '=' || v[0] == '+' || v[0] == '-' || v[0] == '@' || v[0] == '\t' || v[0] == '\r'))
    v.insert(v.begin(), '\'');
  if (v.find_first_of(",\"\r\n") == std::string::npos) return v;
  std::string q = "\"";
  for (char c : v) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + '"';
}

std::string sheet_csv(const MeasurementSheet& sheet, LengthUnit unit) {
  std::string out = "iso_clause,name,label,value,unit,flagged,source,customer_ref,scan_id,taken_at\r\n";
  for (const SheetEntry& e : sheet.entries) {
    for (const std::string& f :
         {e.iso_clause, e.name, e.label, format_length(e.value_mm, unit), std::string(unit_symbol(unit)),
          std::string(e.flagged ? "yes" : "no"), e.source, sheet.customer_ref, sheet.scan_id})
      out += csv_field(f), out += ',';
    out += csv_field(sheet.taken_at);
    out += "\r\n";
  }
  return out;
}

nlohmann::json sheet_json(const MeasurementSheet& sheet, LengthUnit unit) {
  nlohmann::json j = {{"schema", "bodyscan.sheet/1"},
                      {"customer_ref", sheet.customer_ref},
                      {"scan_id", sheet.scan_id},
                      {"taken_at", sheet.taken_at},
                      {"operator", sheet.operator_name},
                      {"unit", unit_symbol(unit)},
                      {"measurements", nlohmann::json::array()},
                      {"by_clause", nlohmann::json::object()}};
  for (const SheetEntry& e : sheet.entries) {
    const double scale = unit == LengthUnit::kMillimetre ? 10 : 100;  // as the sheet prints it
    j["measurements"].push_back({{"iso_clause", e.iso_clause.empty() ? nlohmann::json() : nlohmann::json(e.iso_clause)},
                                 {"name", e.name},
                                 {"label", e.label},
                                 {"kind", e.kind},
                                 {"value", std::round(from_mm(e.value_mm, unit) * scale) / scale},
                                 {"flagged", e.flagged},
                                 {"source", e.source}});
    // A clause can name both sides (thigh left and right): the first keeps it.
    if (!e.iso_clause.empty() && !j["by_clause"].contains(e.iso_clause)) j["by_clause"][e.iso_clause] = e.name;
  }
  return j;
}

using drawing::kMargin;
using drawing::kPageH;
using drawing::kPageW;

StatusOr<std::string> sheet_pdf(const MeasurementSheet& sheet, const TriangleMesh& mesh, LengthUnit unit) {
  if (!mesh.is_consistent()) return invalid_argument("sheet: the mesh's indices or attributes are inconsistent");
  std::string out;
  cairo_surface_t* surface = cairo_pdf_surface_create_for_stream(drawing::append_to_string, &out, kPageW, kPageH);
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_TITLE,
                                 ("Body measurements " + sheet.customer_ref).c_str());
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, "bodyscan");
  cairo_t* cr = cairo_create(surface);
  drawing::Page page(cr);

  const double table_x = mesh.empty() ? kMargin : 300, table_right = kPageW - kMargin, row_h = 12.5;
  size_t next = 0;
  int page_no = 1;
  bool any_flagged = false;
  for (const SheetEntry& e : sheet.entries) any_flagged |= e.flagged;
  do {
    if (page_no > 1) cairo_show_page(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    page.text(kMargin, 62, "Body measurements", 18, true);
    std::string meta = "Customer " + sheet.customer_ref + "    Scan " + sheet.scan_id + "    " + sheet.taken_at;
    page.text(kMargin, 82, meta, 9);
    std::string meta2 = "Unit: " + std::string(unit_symbol(unit)) +
                        (sheet.operator_name.empty() ? "" : "    Operator " + sheet.operator_name) +
                        "    ISO 8559-1 clauses; girths as a tape takes them";
    page.text(kMargin, 95, meta2, 8);
    if (page_no > 1) page.text(table_right, 62, "page " + std::to_string(page_no), 8, false, true);
    cairo_set_line_width(cr, 0.5);
    cairo_move_to(cr, kMargin, 104);
    cairo_line_to(cr, table_right, 104);
    cairo_stroke(cr);

    if (page_no == 1 && !mesh.empty()) {
      // Front above, side below, at one scale that fits the left column.
      Eigen::Vector3f lo = mesh.vertices[0], hi = lo;
      for (const Vec3f& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      const Eigen::Vector3f size = hi - lo;
      const double col_w = table_x - kMargin - 20, top = 134, gap = 24, view_h = (kPageH - top - gap - 60) / 2;
      const double scale = std::min({col_w / size.x(), col_w / size.z(), view_h / size.y()});
      cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
      page.text(kMargin, top - 12, "front", 7);
      page.text(kMargin, top + view_h + gap - 12, "left side", 7);
      drawing::draw_body(page, mesh, drawing::kFront, sheet.entries, kMargin + (col_w - size.x() * scale) / 2, top,
                         scale, true);
      drawing::draw_body(page, mesh, drawing::kLeftSide, sheet.entries, kMargin + (col_w - size.z() * scale) / 2,
                         top + view_h + gap, scale, false);
    }

    double y = 125;
    cairo_set_source_rgb(cr, 0, 0, 0);
    page.text(table_x, y, "#", 7.5, true);
    page.text(table_x + 14, y, "ISO", 7.5, true);
    page.text(table_x + 50, y, "Measurement", 7.5, true);
    page.text(table_right, y, unit_symbol(unit), 7.5, true, true);
    y += row_h;
    for (; next < sheet.entries.size() && y < kPageH - 70; ++next, y += row_h) {
      const SheetEntry& e = sheet.entries[next];
      if (next % 2 == 0) {
        cairo_set_source_rgb(cr, 0.94, 0.95, 0.97);
        cairo_rectangle(cr, table_x - 3, y - row_h + 3.5, table_right - table_x + 6, row_h);
        cairo_fill(cr);
      }
      cairo_set_source_rgb(cr, 0, 0, 0);
      page.text(table_x, y, std::to_string(next + 1), 7.5);
      page.text(table_x + 14, y, e.iso_clause.empty() ? "-" : e.iso_clause, 7.5);
      page.text(table_x + 50, y, e.label + (e.flagged ? " \u2020" : ""), 7.5);
      page.text(table_right, y, format_length(e.value_mm, unit), 7.5, false, true);
    }
    if (next >= sheet.entries.size() && any_flagged) {
      cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
      page.text(table_x, y + 6, "\u2020 an estimate: skin the cameras did not see (filled in) could move it", 6.5);
      char amount[64];
      std::snprintf(amount, sizeof amount, "  by more than %g mm; check it by hand", kEstimateThresholdMm);
      page.text(table_x, y + 14, amount, 6.5);
    }
    cairo_set_source_rgb(cr, 0.4, 0.4, 0.4);
    page.text(kMargin, kPageH - 30, "bodyscan - 3-D body scan measurements (ISO 20685-1 scan-derived)", 6.5);
    ++page_no;
  } while (next < sheet.entries.size());

  const Status finished = drawing::finish_pdf(cr, surface, "sheet");
  if (!finished.ok()) return finished;
  return out;
}

}  // namespace bodyscan::storage
