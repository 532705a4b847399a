// The measurement sheet laid out for where it goes next (docs/archive.md,
// "Export profiles"): the columns, the names and the unit a target expects,
// chosen per export.
//   sheet      the tailor's sheet: a row per measurement (sheet_csv)
//   iso8559    a row per measurement that has an ISO 8559-1 clause, keyed by the
//              clause and the side, for pattern systems that speak the standard
//   mtm-order  a made-to-measure order: one row per scan under the order form's
//              own column names (chest, waist, seat, sleeve, inside leg ...), in cm
//              unless another unit is asked for
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/status.hpp"
#include "storage/formats/measurement_sheet.hpp"

namespace bodyscan::storage {

struct ExportProfile {
  std::string id;     // "sheet", "iso8559", "mtm-order"
  std::string title;  // for people
  LengthUnit default_unit = LengthUnit::kMillimetre;
};

// Every profile, the tailor's sheet first.
const std::vector<ExportProfile>& export_profiles();
// invalid_argument naming the profiles otherwise.
StatusOr<ExportProfile> find_export_profile(std::string_view id);

// The sheet as CSV (RFC 4180, CRLF) in `profile`'s layout, in `unit` (the
// profile's default when none).
std::string profile_csv(const MeasurementSheet& sheet, const ExportProfile& profile,
                        std::optional<LengthUnit> unit = std::nullopt);

// The made-to-measure order's columns: its name and the measurement it takes
// (the automatic set's name), in the order written.
struct OrderColumn {
  const char* column;
  const char* measurement;
};
const std::vector<OrderColumn>& mtm_order_columns();

}  // namespace bodyscan::storage
