// The ISO 20685-1 validation report as a PDF for the shop's files: per
// measurement, the mean scan-minus-tape difference over the customers, its 95 %
// confidence interval, the standard's allowance, the verdict and who took the tape
// values. The statistics come from pipeline/tape_validation.hpp, in the JSON form
// the API serves (GET /api/validation).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "core/status.hpp"

namespace bodyscan::storage {

// `report`: {"customers", "tape_values", "measurements": [{"label", "iso_clause",
// "subjects", "mean_difference_mm", "ci_low_mm", "ci_high_mm" (null below two
// customers), "allowance_mm", "verdict", "more_subjects", "measured_by": [...]}]}.
// A4 pages, as many as the rows need. An error if a row lacks a field.
StatusOr<std::string> validation_report_pdf(const nlohmann::json& report, const std::string& shop_name,
                                            const std::string& made_at);

}  // namespace bodyscan::storage
