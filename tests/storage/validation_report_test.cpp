#include "storage/formats/validation_report.hpp"

#include <gtest/gtest.h>

#include "tests/storage/pdf_text.hpp"

namespace bodyscan::storage {
namespace {

nlohmann::json row(const std::string& label, const std::string& verdict, int more) {
  return {{"label", label},        {"iso_clause", "5.3.10"},
          {"subjects", 12},        {"mean_difference_mm", -1.25},
          {"ci_low_mm", -3.5},     {"ci_high_mm", 1.0},
          {"allowance_mm", 9.0},   {"verdict", verdict},
          {"more_subjects", more}, {"measured_by", {"Ada Tailor", "Ben"}}};
}

TEST(ValidationReport, EveryRowReadsBackFromThePdf) {
  nlohmann::json rows = {row("Waist girth", "within", 0), row("Hip girth", "more_subjects", 7),
                         row("Chest girth", "outside", 0)};
  rows.push_back(row("Stature", "too_few", 1));
  rows.back()["ci_low_mm"] = nullptr;
  rows.back()["ci_high_mm"] = nullptr;
  auto pdf = validation_report_pdf({{"customers", 12}, {"tape_values", 40}, {"measurements", rows}}, "Atelier Nord",
                                   "2026-11-29T10:00:00Z");
  ASSERT_TRUE(pdf.ok()) << pdf.status().message();
  const std::string text = testing::pdf_text(*pdf, true);
  for (const char* expected : {"Scanner validation against tape (ISO 20685-1)", "Atelier Nord", "2026-11-29",
                               "12 customers, 40 tape values", "Waist girth", "-1.2", "-3.5 to +1.0", "±9", "within",
                               "needs 7 more", "mean outside", "needs 1 more", "tape: Ada Tailor, Ben"})
    EXPECT_NE(text.find(expected), std::string::npos) << expected << "\n" << text;
}

TEST(ValidationReport, ManyRowsGoOnMorePages) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 60; ++i) rows.push_back(row("Row " + std::to_string(i), "within", 0));
  auto pdf = validation_report_pdf({{"customers", 3}, {"tape_values", 60}, {"measurements", rows}}, "", "2026-11-29");
  ASSERT_TRUE(pdf.ok());
  const std::string text = testing::pdf_text(*pdf, true);
  EXPECT_NE(text.find("page 2"), std::string::npos);
  EXPECT_NE(text.find("Row 59"), std::string::npos);
}

TEST(ValidationReport, AnIncompleteRowIsAnError) {
  nlohmann::json rows = nlohmann::json::array({row("Waist girth", "within", 0)});
  rows[0].erase("allowance_mm");
  EXPECT_EQ(validation_report_pdf({{"measurements", rows}}, "", "").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(validation_report_pdf(nlohmann::json::array(), "", "").status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace bodyscan::storage
