// The measurement sheet clothing staff take away: one row per measurement, keyed by
// its ISO 8559-1 clause and its name, in the unit the shop works in. As CSV (for a
// spreadsheet or a pattern system), JSON (for software), and a printable one-page
// PDF with the customer reference, the date, front and side silhouettes with the
// measured lines drawn on them, and the table.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>
#include <string_view>
#include <vector>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "recon/measure/body_measurements.hpp"

namespace bodyscan::storage {

enum class LengthUnit { kMillimetre, kCentimetre, kInch };

// "mm", "cm", "in" or "inch".
StatusOr<LengthUnit> parse_length_unit(std::string_view text);
const char* unit_symbol(LengthUnit unit);  // "mm", "cm", "in"
double from_mm(double mm, LengthUnit unit);
// The value as the sheet prints it: 0.1 mm, 0.01 cm or 0.01 in.
std::string format_length(double mm, LengthUnit unit);

struct SheetEntry {
  std::string iso_clause;  // "" where the standard has none we could confirm
  std::string name;        // snake_case id, e.g. "waist_girth"
  std::string label;       // for people, e.g. "Waist girth"
  std::string kind;        // "girth", "height", "surface_length", "distance", "arc"
  double value_mm = 0;
  bool flagged = false;               // an estimate: filled-in skin could move it past kEstimateThresholdMm
  std::string source = "automatic";   // or "saved by <user>"
  std::vector<Eigen::Vector3d> path;  // what to draw on the silhouettes (mm)
  bool closed = false;
};

struct MeasurementSheet {
  std::string customer_ref;  // the customer's pseudonymous reference
  std::string scan_id;
  std::string taken_at;  // ISO 8601, e.g. "2026-11-22T10:15:00Z"
  std::string operator_name;
  std::vector<SheetEntry> entries;
};

// The automatic set's entries, in its order.
std::vector<SheetEntry> sheet_entries(const BodyMeasurements& body);

// A CSV field: quoted when it holds a separator, a quote or a line break, and
// defused when a spreadsheet would run it as a formula (=, +, -, @ first).
std::string csv_field(const std::string& s);

// RFC 4180 CSV with a header row: iso_clause, name, label, value, unit, flagged,
// source, customer_ref, scan_id, taken_at.
std::string sheet_csv(const MeasurementSheet& sheet, LengthUnit unit);
// {"schema": "bodyscan.sheet/1", customer_ref, scan_id, taken_at, operator, unit,
//  "measurements": [...], "by_clause": {"5.3.10": "waist_girth", ...}}.
nlohmann::json sheet_json(const MeasurementSheet& sheet, LengthUnit unit);
// One A4 page (more when the table is long). `mesh` gives the silhouettes; an
// empty mesh leaves them out.
StatusOr<std::string> sheet_pdf(const MeasurementSheet& sheet, const TriangleMesh& mesh, LengthUnit unit);

}  // namespace bodyscan::storage
