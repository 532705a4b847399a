#include "storage/formats/customer_sheet.hpp"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "storage/formats/sheet_drawing.hpp"

namespace bodyscan::storage {

StatusOr<Locale> parse_locale(std::string_view text) {
  const std::string_view language = text.substr(0, text.find_first_of("-_"));
  if (language == "en") return Locale::kEnglish;
  if (language == "de") return Locale::kGerman;
  return invalid_argument("locale: en or de (the languages shipped), not '" + std::string(text) + "'");
}

const char* locale_tag(Locale locale) { return locale == Locale::kGerman ? "de" : "en"; }

namespace {

struct PlainName {
  std::string_view name, en, de;
};

// The automatic set's measurements as a customer says them. Sided ones are named
// without their side here; plain_label adds it.
constexpr std::array<PlainName, 25> kPlainNames = {{
    {"stature", "Height", "Körpergröße"},
    {"cervical_height", "Height to the back of the neck", "Nackenhöhe"},
    {"crotch_height", "Inside leg", "Schrittlänge"},
    {"neck_girth", "Neck", "Halsumfang"},
    {"neck_base_girth", "Collar (base of the neck)", "Kragenweite"},
    {"chest_girth", "Chest", "Brustumfang"},
    {"bust_girth", "Bust", "Oberweite"},
    {"underbust_girth", "Under-bust", "Unterbrustweite"},
    {"waist_girth", "Waist", "Taillenumfang"},
    {"hip_girth", "Hips", "Hüftumfang"},
    {"max_hip_girth", "Hips at their widest", "Gesäßumfang"},
    {"waist_height", "Waist height", "Taillenhöhe"},
    {"hip_height", "Hip height", "Hüfthöhe"},
    {"thigh_girth", "Thigh", "Oberschenkelumfang"},
    {"mid_thigh_girth", "Mid-thigh", "Oberschenkel Mitte"},
    {"knee_height", "Knee height", "Kniehöhe"},
    {"knee_girth", "Knee", "Knieumfang"},
    {"calf_girth", "Calf", "Wadenumfang"},
    {"min_leg_girth", "Ankle", "Fesselumfang"},
    {"wrist_girth", "Wrist", "Handgelenkumfang"},
    {"upper_arm_girth", "Upper arm", "Oberarmumfang"},
    {"outer_arm_length", "Arm length", "Armlänge"},
    {"shoulder_width", "Shoulder width (across the back)", "Schulterbreite (Rücken)"},
    {"biacromial_breadth", "Shoulder breadth (straight)", "Schulterbreite (gerade)"},
    {"back_neck_to_waist", "Back length (neck to waist)", "Rückenlänge"},
}};

// The words a customer sheet prints, per locale.
struct Words {
  const char* title;
  const char* scanned_on;
  const char* left;
  const char* right;
  const char* estimated_1;
  const char* estimated_2;
  const char* none;
  const char* qr;
  const char* valid_until;
  const char* footer;
  std::array<const char*, 12> months;
};

const Words& words(Locale locale) {
  static const Words en = {"Your body measurements",
                           "Scanned on ",
                           "left",
                           "right",
                           "* Estimated: the cameras could not see all of this line, so part of it",
                           "  is filled in. The shop can check it with a tape measure.",
                           "No measurements were chosen for this sheet.",
                           "Your 3-D model: scan with your phone",
                           "Link valid until ",
                           "Measured with a 3-D body scanner",
                           {"January", "February", "March", "April", "May", "June", "July", "August", "September",
                            "October", "November", "December"}};
  static const Words de = {"Ihre Körpermaße",
                           "Gescannt am ",
                           "links",
                           "rechts",
                           "* Geschätzt: Die Kameras konnten diese Linie nicht ganz sehen, ein Teil",
                           "  ist ergänzt. Das Geschäft kann sie mit dem Maßband nachmessen.",
                           "Für dieses Blatt wurden keine Maße ausgewählt.",
                           "Ihr 3-D-Modell: mit dem Handy scannen",
                           "Link gültig bis ",
                           "Mit einem 3-D-Körperscanner gemessen",
                           {"Januar", "Februar", "März", "April", "Mai", "Juni", "Juli", "August", "September",
                            "Oktober", "November", "Dezember"}};
  return locale == Locale::kGerman ? de : en;
}

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

}  // namespace

std::string plain_label(std::string_view name, Locale locale) {
  std::string_view base = name;
  const char* side = nullptr;
  if (ends_with(name, "_left")) base = name.substr(0, name.size() - 5), side = words(locale).left;
  if (ends_with(name, "_right")) base = name.substr(0, name.size() - 6), side = words(locale).right;
  for (const PlainName& p : kPlainNames)
    if (p.name == base) {
      std::string label(locale == Locale::kGerman ? p.de : p.en);
      return side ? label + " (" + side + ")" : label;
    }
  return "";
}

std::string format_number(double value, int decimals, Locale locale) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", std::clamp(decimals, 0, 6), value);
  std::string s = b;
  if (locale == Locale::kGerman) std::replace(s.begin(), s.end(), '.', ',');
  return s;
}

std::string format_date(std::string_view iso, Locale locale) {
  int y = 0, m = 0, d = 0;
  if (iso.size() < 10 || std::sscanf(std::string(iso.substr(0, 10)).c_str(), "%4d-%2d-%2d", &y, &m, &d) != 3 || m < 1 ||
      m > 12 || d < 1 || d > 31)
    return std::string(iso);
  const char* month = words(locale).months[static_cast<size_t>(m - 1)];
  return std::to_string(d) + (locale == Locale::kGerman ? ". " : " ") + month + " " + std::to_string(y);
}

StatusOr<std::string> customer_sheet_pdf(const CustomerSheet& sheet, const TriangleMesh& mesh, LengthUnit unit) {
  using drawing::kMargin;
  using drawing::kPageH;
  using drawing::kPageW;
  if (!mesh.is_consistent()) return invalid_argument("sheet: the mesh's indices or attributes are inconsistent");
  const Words& w = words(sheet.locale);
  std::string out;
  cairo_surface_t* surface = cairo_pdf_surface_create_for_stream(drawing::append_to_string, &out, kPageW, kPageH);
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_TITLE, w.title);
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, "bodyscan");
  cairo_t* cr = cairo_create(surface);
  drawing::Page page(cr);
  Status drawn;

  // The shop: its logo top left, its name beside it (or in its place).
  double name_x = kMargin;
  if (!sheet.shop_logo_png.empty()) {
    drawn = drawing::draw_png(page, sheet.shop_logo_png, kMargin, 30, 150, 50);
    name_x = kMargin + 165;
  }
  cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
  if (drawn.ok() && !sheet.shop_name.empty()) page.text(name_x, 60, sheet.shop_name, 14, true);

  cairo_set_source_rgb(cr, 0, 0, 0);
  page.text(kMargin, 118, w.title, 22, true);
  double y = 142;
  if (!sheet.customer_name.empty()) page.text(kMargin, y, sheet.customer_name, 14), y += 18;
  cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
  page.text(kMargin, y, w.scanned_on + format_date(sheet.taken_at, sheet.locale), 10);
  cairo_set_line_width(cr, 0.5);
  cairo_move_to(cr, kMargin, y + 12);
  cairo_line_to(cr, kPageW - kMargin, y + 12);
  cairo_stroke(cr);

  // The silhouette in the left column, the table in the right; the QR code below
  // the table.
  const double top = y + 40, bottom = kPageH - 60, qr_size = 112;
  const double table_x = mesh.empty() ? kMargin : 270, table_right = kPageW - kMargin;
  if (!mesh.empty()) {
    Eigen::Vector3f lo = mesh.vertices[0], hi = lo;
    for (const Vec3f& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    const Eigen::Vector3f size = hi - lo;
    const double col_w = table_x - kMargin - 24, col_h = bottom - top;
    const double scale = std::min(col_w / size.x(), col_h / size.y());
    drawing::draw_body(page, mesh, drawing::kFront, sheet.entries, kMargin + (col_w - size.x() * scale) / 2, top, scale,
                       true);
  }
  const bool qr = !sheet.link_url.empty();
  const double table_bottom = qr ? bottom - qr_size - 50 : bottom - 30;
  const size_t n = sheet.entries.size();
  const double row_h = n == 0 ? 18 : std::min(18.0, (table_bottom - top) / static_cast<double>(n + 1));
  const double font = std::min(10.5, row_h * 0.62);
  bool any_flagged = false;
  cairo_set_source_rgb(cr, 0, 0, 0);
  y = top;
  if (n == 0) page.text(table_x, y, w.none, 10);
  const int decimals = unit == LengthUnit::kMillimetre ? 0 : 1;
  for (size_t i = 0; i < n; ++i, y += row_h) {
    const SheetEntry& e = sheet.entries[i];
    if (i % 2 == 0) {
      cairo_set_source_rgb(cr, 0.94, 0.95, 0.97);
      cairo_rectangle(cr, table_x - 4, y - row_h * 0.7, table_right - table_x + 8, row_h);
      cairo_fill(cr);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    std::string label = plain_label(e.name, sheet.locale);
    if (label.empty()) label = e.label;
    any_flagged |= e.flagged;
    page.text(table_x, y, std::to_string(i + 1), font * 0.85);
    page.text(table_x + 18, y, label + (e.flagged ? " *" : ""), font);
    page.text(table_right, y,
              format_number(from_mm(e.value_mm, unit), decimals, sheet.locale) + " " + unit_symbol(unit), font, true,
              true);
  }
  cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
  if (any_flagged) {
    page.text(table_x, y + 4, w.estimated_1, 7);
    page.text(table_x, y + 13, w.estimated_2, 7);
  }
  if (qr && drawn.ok()) {
    const double qx = table_right - qr_size, qy = bottom - qr_size - 16;
    drawn = drawing::draw_qr(page, sheet.link_url, qx, qy, qr_size);
    cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
    page.text(qx - 10, qy + qr_size * 0.45, w.qr, 8.5, true, true);
    if (!sheet.link_expires.empty())
      page.text(qx - 10, qy + qr_size * 0.45 + 13, w.valid_until + format_date(sheet.link_expires, sheet.locale), 8,
                false, true);
  }
  cairo_set_source_rgb(cr, 0.45, 0.45, 0.45);
  page.text(kMargin, kPageH - 28, w.footer + (sheet.shop_name.empty() ? "" : " · " + sheet.shop_name), 7);

  const Status finished = drawing::finish_pdf(cr, surface, "sheet");
  if (!drawn.ok()) return drawn;
  if (!finished.ok()) return finished;
  return out;
}

}  // namespace bodyscan::storage
