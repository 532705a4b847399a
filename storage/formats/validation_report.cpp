#include "storage/formats/validation_report.hpp"

#include <cairo-pdf.h>
#include <cairo.h>

#include <cstdio>

#include "storage/formats/sheet_drawing.hpp"

namespace bodyscan::storage {

namespace {

std::string millimetres(double mm) {
  char text[32];
  std::snprintf(text, sizeof text, "%+.1f", mm);
  return text;
}

// Short enough for the verdict column: "within", "needs 7 more", "mean outside".
std::string verdict_text(const nlohmann::json& row) {
  const std::string v = row.at("verdict").get<std::string>();
  if (v == "within") return "within";
  if (v == "outside") return "mean outside";
  return "needs " + std::to_string(row.at("more_subjects").get<int>()) + " more";
}

// One row's cells; an error if the row lacks a field.
struct Cells {
  std::string label, clause, subjects, mean, interval, allowance, verdict, measured_by;
  bool within = false;
};

StatusOr<Cells> cells(const nlohmann::json& row) {
  try {
    Cells c;
    c.label = row.at("label").get<std::string>();
    c.clause = row.at("iso_clause").get<std::string>();
    c.subjects = std::to_string(row.at("subjects").get<int>());
    c.mean = millimetres(row.at("mean_difference_mm").get<double>());
    c.interval = row.at("ci_low_mm").is_null() ? "—"
                                               : millimetres(row.at("ci_low_mm").get<double>()) + " to " +
                                                     millimetres(row.at("ci_high_mm").get<double>());
    char allowance[32];
    std::snprintf(allowance, sizeof allowance, "±%.0f", row.at("allowance_mm").get<double>());
    c.allowance = allowance;
    c.verdict = verdict_text(row);
    c.within = row.at("verdict").get<std::string>() == "within";
    for (const auto& who : row.at("measured_by"))
      c.measured_by += (c.measured_by.empty() ? "" : ", ") + who.get<std::string>();
    return c;
  } catch (const nlohmann::json::exception& e) {
    return invalid_argument(std::string("validation report: a row is incomplete: ") + e.what());
  }
}

}  // namespace

StatusOr<std::string> validation_report_pdf(const nlohmann::json& report, const std::string& shop_name,
                                            const std::string& made_at) {
  using drawing::kMargin;
  using drawing::kPageH;
  using drawing::kPageW;
  if (!report.is_object() || !report.contains("measurements") || !report["measurements"].is_array())
    return invalid_argument("validation report: no measurements");
  std::vector<Cells> rows;
  for (const auto& row : report["measurements"]) {
    ASSIGN_OR_RETURN(Cells c, cells(row));
    rows.push_back(std::move(c));
  }
  std::string out;
  cairo_surface_t* surface = cairo_pdf_surface_create_for_stream(drawing::append_to_string, &out, kPageW, kPageH);
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_TITLE, "Scanner validation against tape (ISO 20685-1)");
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, "bodyscan");
  cairo_t* cr = cairo_create(surface);
  drawing::Page page(cr);

  // Columns: measurement, clause, customers, mean, interval, allowance, verdict.
  // Numbers end at their column's x; text starts at it.
  const double x_label = kMargin, x_clause = 200, x_n = 300, x_mean = 345, x_ci = 430, x_allow = 475, x_verdict = 485;
  const double row_h = 26, bottom = kPageH - 70;
  double y = 0;
  int page_number = 0;
  auto header = [&] {
    ++page_number;
    cairo_set_source_rgb(cr, 0, 0, 0);
    page.text(kMargin, 60, "Scanner validation against tape (ISO 20685-1)", 16, true);
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
    page.text(
        kMargin, 78,
        (shop_name.empty() ? "" : shop_name + " · ") + made_at.substr(0, 10) + " · page " + std::to_string(page_number),
        9);
    y = 100;
    if (page_number == 1) {
      const std::string lines[] = {
          std::to_string(report.value("customers", 0)) + " customers, " +
              std::to_string(report.value("tape_values", 0)) +
              " tape values. Mean: of scan minus tape, mm; interval: its 95 % confidence (Student t).",
          "Within: the interval lies inside ± the allowance (ISO 20685-1). Needs N more: customers still to measure",
          "both ways, if mean and spread hold. Clause: ISO 8559-1."};
      for (const std::string& line : lines) page.text(kMargin, y, line, 9), y += 12;
      y += 10;
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    page.text(x_label, y, "Measurement", 8.5, true);
    page.text(x_clause, y, "Clause", 8.5, true);
    page.text(x_n, y, "Customers", 8.5, true, true);
    page.text(x_mean, y, "Mean", 8.5, true, true);
    page.text(x_ci, y, "95 % interval", 8.5, true, true);
    page.text(x_allow, y, "Allowed", 8.5, true, true);
    page.text(x_verdict, y, "Verdict", 8.5, true);
    cairo_set_line_width(cr, 0.5);
    cairo_move_to(cr, kMargin, y + 5);
    cairo_line_to(cr, kPageW - kMargin, y + 5);
    cairo_stroke(cr);
    y += 20;
  };
  header();
  if (rows.empty()) page.text(kMargin, y, "No tape measurements entered yet.", 10);
  for (size_t i = 0; i < rows.size(); ++i) {
    if (y + row_h > bottom) {
      cairo_show_page(cr);
      header();
    }
    const Cells& c = rows[i];
    if (i % 2 == 0) {
      cairo_set_source_rgb(cr, 0.94, 0.95, 0.97);
      cairo_rectangle(cr, kMargin - 4, y - 11, kPageW - 2 * kMargin + 8, row_h);
      cairo_fill(cr);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    page.text(x_label, y, c.label, 9);
    page.text(x_clause, y, c.clause, 9);
    page.text(x_n, y, c.subjects, 9, false, true);
    page.text(x_mean, y, c.mean, 9, false, true);
    page.text(x_ci, y, c.interval, 9, false, true);
    page.text(x_allow, y, c.allowance, 9, false, true);
    if (c.within)
      cairo_set_source_rgb(cr, 0.05, 0.45, 0.2);
    else
      cairo_set_source_rgb(cr, 0.6, 0.25, 0.0);
    page.text(x_verdict, y, c.verdict, 9, true);
    cairo_set_source_rgb(cr, 0.35, 0.35, 0.35);
    page.text(x_label + 8, y + 10, c.measured_by.empty() ? "" : "tape: " + c.measured_by, 7);
    y += row_h;
  }
  cairo_set_source_rgb(cr, 0.45, 0.45, 0.45);
  page.text(kMargin, kPageH - 28,
            "bodyscan · one customer counts once per measurement, with their newest scan's tape value", 7);
  const Status finished = drawing::finish_pdf(cr, surface, "validation report");
  if (!finished.ok()) return finished;
  return out;
}

}  // namespace bodyscan::storage
