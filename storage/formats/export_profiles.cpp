#include "storage/formats/export_profiles.hpp"

namespace bodyscan::storage {

namespace {

// A CSV line of fields (each through csv_field), CRLF-ended.
std::string csv_line(const std::vector<std::string>& fields) {
  std::string out;
  for (size_t i = 0; i < fields.size(); ++i) out += (i ? "," : "") + csv_field(fields[i]);
  return out + "\r\n";
}

bool ends_with(const std::string& s, std::string_view tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// "thigh_girth_left" -> ("thigh_girth", "left"); names without a side keep theirs.
std::pair<std::string, std::string> split_side(const std::string& name) {
  for (const char* side : {"left", "right"}) {
    const std::string tail = std::string("_") + side;
    if (ends_with(name, tail)) return {name.substr(0, name.size() - tail.size()), side};
  }
  return {name, ""};
}

std::string iso8559_csv(const MeasurementSheet& sheet, LengthUnit unit) {
  std::string out = csv_line({"iso_clause", "side", "measurement", "value", "unit", "flagged"});
  for (const SheetEntry& e : sheet.entries) {
    if (e.iso_clause.empty()) continue;
    const auto [measurement, side] = split_side(e.name);
    out += csv_line({e.iso_clause, side, measurement, format_length(e.value_mm, unit), unit_symbol(unit),
                     e.flagged ? "yes" : "no"});
  }
  return out;
}

std::string mtm_order_csv(const MeasurementSheet& sheet, LengthUnit unit) {
  std::vector<std::string> header = {"customer_ref", "scan_id", "measured_on", "unit"};
  std::vector<std::string> row = {sheet.customer_ref, sheet.scan_id, sheet.taken_at.substr(0, 10), unit_symbol(unit)};
  for (const OrderColumn& c : mtm_order_columns()) {
    header.emplace_back(c.column);
    std::string value;  // empty where the scan has no such measurement
    for (const SheetEntry& e : sheet.entries)
      if (e.name == c.measurement) value = format_length(e.value_mm, unit);
    row.push_back(value);
  }
  return csv_line(header) + csv_line(row);
}

}  // namespace

const std::vector<ExportProfile>& export_profiles() {
  static const std::vector<ExportProfile> profiles = {
      {"sheet", "The tailor's sheet", LengthUnit::kMillimetre},
      {"iso8559", "ISO 8559-1, keyed by clause", LengthUnit::kMillimetre},
      {"mtm-order", "Made-to-measure order", LengthUnit::kCentimetre},
  };
  return profiles;
}

StatusOr<ExportProfile> find_export_profile(std::string_view id) {
  std::string known;
  for (const ExportProfile& p : export_profiles()) {
    if (p.id == id) return p;
    known += (known.empty() ? "" : ", ") + p.id;
  }
  return invalid_argument("'profile' is one of " + known);
}

const std::vector<OrderColumn>& mtm_order_columns() {
  // An order form's names for what a tailor measures. Chest is the fullest girth
  // over the chest or bust (5.3.4), seat the fullest over the buttocks (5.3.14),
  // neck where a collar sits (5.3.3), sleeve the outer arm from the shoulder
  // point over the elbow to the wrist (5.7.8), back length from the back neck
  // point to the waist (5.4.5), inside leg the crotch's height (5.1.15).
  static const std::vector<OrderColumn> columns = {
      {"height", "stature"},
      {"neck", "neck_base_girth"},
      {"chest", "bust_girth"},
      {"waist", "waist_girth"},
      {"seat", "max_hip_girth"},
      {"shoulder_width", "shoulder_width"},
      {"back_length", "back_neck_to_waist"},
      {"sleeve_left", "outer_arm_length_left"},
      {"sleeve_right", "outer_arm_length_right"},
      {"bicep_left", "upper_arm_girth_left"},
      {"bicep_right", "upper_arm_girth_right"},
      {"wrist_left", "wrist_girth_left"},
      {"wrist_right", "wrist_girth_right"},
      {"inside_leg", "crotch_height"},
      {"thigh_left", "thigh_girth_left"},
      {"thigh_right", "thigh_girth_right"},
      {"knee_left", "knee_girth_left"},
      {"knee_right", "knee_girth_right"},
      {"calf_left", "calf_girth_left"},
      {"calf_right", "calf_girth_right"},
  };
  return columns;
}

std::string profile_csv(const MeasurementSheet& sheet, const ExportProfile& profile, std::optional<LengthUnit> unit) {
  const LengthUnit u = unit.value_or(profile.default_unit);
  if (profile.id == "iso8559") return iso8559_csv(sheet, u);
  if (profile.id == "mtm-order") return mtm_order_csv(sheet, u);
  return sheet_csv(sheet, u);
}

}  // namespace bodyscan::storage
