// Repeat scans in one visit: a customer scanned twice on the same day is compared
// value by value, so that a customer who swayed or stood differently is scanned
// again while still in the shop. The station asks right after the second scan.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/status.hpp"
#include "storage/archive/archive.hpp"

namespace bodyscan::pipeline {

struct RepeatDifference {
  std::string name, label, kind;
  double value_mm = 0;      // this scan's
  double earlier_mm = 0;    // the earlier scan's
  double tolerance_mm = 0;  // the repeatability it was held to
  double difference() const { return value_mm - earlier_mm; }
};

struct RepeatCheck {
  std::string earlier_scan, earlier_started_at;
  size_t compared = 0;                   // automatic values both scans have
  std::vector<RepeatDifference> beyond;  // those that differ by more than their tolerance
};

// How far two scans of one customer in one visit may differ: `shop_mm` when the
// shop set one (> 0), else the value's ISO 20685-1 allowance (9 mm for the torso's
// girths, 4 for the other girths, the heights and the breadths, 5 for lengths),
// which is what a scanner must hold against the tape.
double repeat_tolerance_mm(const storage::MeasurementRecord& m, double shop_mm);

// Whether two ISO 8601 UTC times fall on the same calendar day where the
// workstation is (its local time zone).
bool same_local_day(std::string_view a_iso, std::string_view b_iso);

// `scan_id` against its customer's latest earlier complete scan of the same
// local day, over the automatic set's current values; nullopt when there is none.
StatusOr<std::optional<RepeatCheck>> check_repeat(const storage::Archive& archive, const std::string& scan_id,
                                                  double shop_mm);

}  // namespace bodyscan::pipeline
