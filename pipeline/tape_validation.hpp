// ISO 20685-1 validation in the shop: the scanner's automatic values against the
// tape measurements staff took by hand of the same customers. Per measurement,
// the mean scan-minus-tape difference over the customers, its 95 % confidence
// interval, and whether that interval lies within the standard's allowance, as
// the standard judges a scanner; where it does not yet, how many more customers
// it would take if the mean and spread hold.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/status.hpp"
#include "storage/archive/archive.hpp"

namespace bodyscan::pipeline {

// Differences d_i = scan - tape (mm), one per customer.
struct DifferenceStats {
  size_t n = 0;
  double mean = 0;
  double sd = 0;  // sample standard deviation (n - 1); 0 below two
  // The two-sided 95 % confidence interval of the mean, mean -+ t(0.975, n-1) sd /
  // sqrt(n); both equal to the mean below two.
  double ci_low = 0, ci_high = 0;
};
DifferenceStats difference_stats(const std::vector<double>& differences);

enum class Verdict {
  kTooFew,            // fewer than two customers: no interval yet
  kWithin,            // the interval lies within -+ the allowance
  kMoreSubjects,      // the mean lies within, the interval not yet: more customers can settle it
  kOutsideAllowance,  // the mean difference itself is at or past the allowance
};
const char* to_string(Verdict v);

struct Judgement {
  Verdict verdict = Verdict::kTooFew;
  // kMoreSubjects: how many more customers bring the interval within the
  // allowance if the mean and standard deviation stay as measured; kTooFew: the
  // customers still missing for a first interval. 0 otherwise.
  size_t more_subjects = 0;
};
Judgement judge(const DifferenceStats& stats, double allowance_mm);

struct MeasurementValidation {
  std::string name, label, kind, iso_clause;
  double allowance_mm = 0;  // ISO 20685-1's for the measurement (iso20685_allowance_mm)
  DifferenceStats stats;
  Judgement judgement;
  std::vector<std::string> measured_by;  // everyone who took its tape values, sorted
};

struct ValidationReport {
  std::vector<MeasurementValidation> measurements;  // in the automatic set's order
  size_t customers = 0;                             // with at least one tape value
  size_t tape_values = 0;                           // compared (one per customer and measurement)
};

// The report over the archive. A customer counts once per measurement, with the
// tape value of their newest scan that has one; the scan value is that scan's
// current automatic value.
StatusOr<ValidationReport> validate_against_tape(const storage::Archive& archive);

// The report as the API serves it and storage::validation_report_pdf reads it:
// {"customers", "tape_values", "confidence": 0.95, "measurements": [{"name",
// "label", "kind", "iso_clause", "allowance_mm", "subjects", "mean_difference_mm",
// "sd_mm", "ci_low_mm", "ci_high_mm", "verdict", "more_subjects", "measured_by"}]};
// sd and the interval are null below two customers.
nlohmann::json to_json(const ValidationReport& report);

}  // namespace bodyscan::pipeline
