#include "storage/formats/measurement_sheet.hpp"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

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
    e.flagged = m.crosses_filled_hole();
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

namespace {

// The body seen from the front (X to the right, Y up) or from its left side (-Z to
// the right, Y up): which pixels of a raster it covers.
struct View {
  int axis_x = 0;     // 0: X, 2: Z
  double sign_x = 1;  // +1 or -1
  Eigen::Vector2d project(const Eigen::Vector3d& p) const { return {sign_x * p[axis_x], p.y()}; }
};

struct Silhouette {
  int width = 0, height = 0;
  double lo_x = 0, hi_y = 0, mm_per_px = 1;
  std::vector<unsigned char> mask;  // width * height, 255 where the body is
  Eigen::Vector2d to_px(const Eigen::Vector2d& p) const {
    return {(p.x() - lo_x) / mm_per_px, (hi_y - p.y()) / mm_per_px};
  }
};

Silhouette rasterise(const TriangleMesh& mesh, const View& view, double mm_per_px) {
  Silhouette s;
  double lo_x = std::numeric_limits<double>::max(), hi_x = -lo_x, lo_y = lo_x, hi_y = -lo_x;
  for (const Vec3f& v : mesh.vertices) {
    const Eigen::Vector2d p = view.project(v.cast<double>());
    lo_x = std::min(lo_x, p.x()), hi_x = std::max(hi_x, p.x()), lo_y = std::min(lo_y, p.y()),
    hi_y = std::max(hi_y, p.y());
  }
  s.lo_x = lo_x, s.hi_y = hi_y, s.mm_per_px = mm_per_px;
  s.width = static_cast<int>(std::ceil((hi_x - lo_x) / mm_per_px)) + 1;
  s.height = static_cast<int>(std::ceil((hi_y - lo_y) / mm_per_px)) + 1;
  s.mask.assign(static_cast<size_t>(s.width) * static_cast<size_t>(s.height), 0);
  for (const Triangle& t : mesh.triangles) {
    Eigen::Vector2d q[3];
    for (int k = 0; k < 3; ++k) q[k] = s.to_px(view.project(mesh.vertices[t[k]].cast<double>()));
    const double area = (q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x();
    if (area == 0) continue;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}))));
    const int x1 = std::min(s.width - 1, static_cast<int>(std::ceil(std::max({q[0].x(), q[1].x(), q[2].x()}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}))));
    const int y1 = std::min(s.height - 1, static_cast<int>(std::ceil(std::max({q[0].y(), q[1].y(), q[2].y()}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const Eigen::Vector2d c(x + 0.5, y + 0.5);
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k) {
          const Eigen::Vector2d a = q[k], b = q[(k + 1) % 3];
          const double e = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
          inside = area > 0 ? e >= 0 : e <= 0;
        }
        if (inside) s.mask[static_cast<size_t>(y) * static_cast<size_t>(s.width) + static_cast<size_t>(x)] = 255;
      }
  }
  return s;
}

cairo_status_t append_to_string(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

class Page {
 public:
  explicit Page(cairo_t* cr) : cr_(cr) {}
  void text(double x, double y, const std::string& s, double size, bool bold = false, bool right = false) {
    cairo_select_font_face(cr_, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr_, size);
    if (right) {
      cairo_text_extents_t ext;
      cairo_text_extents(cr_, s.c_str(), &ext);
      x -= ext.x_advance;
    }
    cairo_move_to(cr_, x, y);
    cairo_show_text(cr_, s.c_str());
  }
  cairo_t* cr() { return cr_; }

 private:
  cairo_t* cr_;
};

constexpr double kPageW = 595.276, kPageH = 841.89, kMargin = 40;  // A4 in points

// The silhouette at (x, y) (top left), `pt_per_mm`, with each entry's path drawn
// and, on the front view, numbered.
void draw_view(Page& page, const TriangleMesh& mesh, const View& view, const MeasurementSheet& sheet, double x,
               double y, double pt_per_mm, bool numbers) {
  constexpr double kPxPerPt = 3;
  const Silhouette s = rasterise(mesh, view, 1 / (pt_per_mm * kPxPerPt));
  cairo_t* cr = page.cr();
  const int stride = cairo_format_stride_for_width(CAIRO_FORMAT_A8, s.width);
  std::vector<unsigned char> rows(static_cast<size_t>(stride) * static_cast<size_t>(s.height), 0);
  for (int r = 0; r < s.height; ++r)
    std::copy_n(s.mask.begin() + static_cast<long>(r) * s.width, s.width, rows.begin() + static_cast<long>(r) * stride);
  cairo_surface_t* mask = cairo_image_surface_create_for_data(rows.data(), CAIRO_FORMAT_A8, s.width, s.height, stride);
  cairo_save(cr);
  cairo_translate(cr, x, y);
  cairo_scale(cr, 1 / kPxPerPt, 1 / kPxPerPt);
  cairo_set_source_rgb(cr, 0.78, 0.82, 0.88);
  cairo_mask_surface(cr, mask, 0, 0);
  cairo_restore(cr);
  cairo_surface_finish(mask);
  cairo_surface_destroy(mask);

  auto at = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d q = s.to_px(view.project(p)) / kPxPerPt;
    return Eigen::Vector2d(x + q.x(), y + q.y());
  };
  cairo_set_line_width(cr, 0.6);
  for (size_t i = 0; i < sheet.entries.size(); ++i) {
    const SheetEntry& e = sheet.entries[i];
    if (e.path.size() < 2 || e.kind == "height") continue;
    cairo_set_source_rgb(cr, e.flagged ? 0.75 : 0.1, 0.2, e.flagged ? 0.1 : 0.55);
    Eigen::Vector2d right_most = at(e.path.front());
    for (size_t k = 0; k < e.path.size(); ++k) {
      const Eigen::Vector2d p = at(e.path[k]);
      (k == 0 ? cairo_move_to : cairo_line_to)(cr, p.x(), p.y());
      if (p.x() > right_most.x()) right_most = p;
    }
    if (e.closed) cairo_close_path(cr);
    cairo_stroke(cr);
    if (numbers) page.text(right_most.x() + 2, right_most.y() + 2, std::to_string(i + 1), 5);
  }
}

}  // namespace

StatusOr<std::string> sheet_pdf(const MeasurementSheet& sheet, const TriangleMesh& mesh, LengthUnit unit) {
  if (!mesh.is_consistent()) return invalid_argument("sheet: the mesh's indices or attributes are inconsistent");
  std::string out;
  cairo_surface_t* surface = cairo_pdf_surface_create_for_stream(append_to_string, &out, kPageW, kPageH);
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_TITLE,
                                 ("Body measurements " + sheet.customer_ref).c_str());
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, "bodyscan");
  cairo_t* cr = cairo_create(surface);
  Page page(cr);

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
      draw_view(page, mesh, View{0, 1}, sheet, kMargin + (col_w - size.x() * scale) / 2, top, scale, true);
      draw_view(page, mesh, View{2, -1}, sheet, kMargin + (col_w - size.z() * scale) / 2, top + view_h + gap, scale,
                false);
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
      page.text(table_x, y + 6, "\u2020 passes over a part of the body the cameras did not see", 6.5);
      page.text(table_x, y + 14, "  (the surface there is filled in); check it by hand", 6.5);
    }
    cairo_set_source_rgb(cr, 0.4, 0.4, 0.4);
    page.text(kMargin, kPageH - 30, "bodyscan - 3-D body scan measurements (ISO 20685-1 scan-derived)", 6.5);
    ++page_no;
  } while (next < sheet.entries.size());

  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS)
    return internal_error(std::string("sheet: Cairo failed: ") + cairo_status_to_string(status));
  return out;
}

}  // namespace bodyscan::storage
