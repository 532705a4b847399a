// The ISO 20685-1 validation report against statistics worked out here by hand
// from printed Student t values.
#include "pipeline/tape_validation.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include "tests/test_data.hpp"

namespace bodyscan::pipeline {
namespace {

// t(0.975, dof) from a printed table.
constexpr double kT4 = 2.7764451, kT5 = 2.5705818, kT6 = 2.4469119;

TEST(TapeValidation, StatisticsOfTheDifferences) {
  // Mean 1; squares about it 1 + 4 + 4 + 1 + 0 = 10, so sd = sqrt(10 / 4).
  const DifferenceStats s = difference_stats({2, -1, 3, 0, 1});
  const double sd = std::sqrt(2.5), half = kT4 * sd / std::sqrt(5.0);
  EXPECT_EQ(s.n, 5u);
  EXPECT_NEAR(s.mean, 1, 1e-12);
  EXPECT_NEAR(s.sd, sd, 1e-12);
  EXPECT_NEAR(s.ci_low, 1 - half, 1e-6);
  EXPECT_NEAR(s.ci_high, 1 + half, 1e-6);

  const DifferenceStats one = difference_stats({4.5});
  EXPECT_EQ(one.n, 1u);
  EXPECT_EQ(one.mean, 4.5);
  EXPECT_EQ(one.ci_low, 4.5);
  EXPECT_EQ(one.ci_high, 4.5);
  EXPECT_EQ(difference_stats({}).n, 0u);
}

TEST(TapeValidation, TheVerdictAndTheCustomersStillNeeded) {
  const DifferenceStats s = difference_stats({2, -1, 3, 0, 1});  // interval about [-0.96, 2.96]
  EXPECT_EQ(judge(s, 4).verdict, Verdict::kWithin);
  EXPECT_EQ(judge(s, 4).more_subjects, 0u);

  // Allowance 2.5: the margin for the half width is 1.5. With sd = sqrt(2.5), six
  // customers give a half width of t5 sd / sqrt 6 = 1.66, seven t6 sd / sqrt 7 = 1.46.
  const double sd = std::sqrt(2.5);
  ASSERT_GT(kT5 * sd / std::sqrt(6.0), 1.5);
  ASSERT_LT(kT6 * sd / std::sqrt(7.0), 1.5);
  const Judgement more = judge(s, 2.5);
  EXPECT_EQ(more.verdict, Verdict::kMoreSubjects);
  EXPECT_EQ(more.more_subjects, 2u);

  // The mean alone past the allowance: no number of customers helps.
  EXPECT_EQ(judge(difference_stats({5, 6, 4, 5}), 4).verdict, Verdict::kOutsideAllowance);
  EXPECT_EQ(judge(difference_stats({-3, -5, -4}), 4).verdict, Verdict::kOutsideAllowance);  // on the edge, spread
  // One customer: no interval yet, one more needed for one.
  EXPECT_EQ(judge(difference_stats({1}), 4).verdict, Verdict::kTooFew);
  EXPECT_EQ(judge(difference_stats({1}), 4).more_subjects, 1u);
  EXPECT_EQ(judge(difference_stats({}), 4).more_subjects, 2u);
}

storage::ScanResults results(double waist_mm, double stature_mm) {
  storage::ScanResults r;
  r.files["mesh.glb"] = "glb";
  storage::MeasurementRecord stature, waist;
  stature.name = "stature", stature.label = "Stature", stature.kind = "height", stature.iso_clause = "5.1.1";
  stature.value_mm = stature_mm;
  waist.name = "waist_girth", waist.label = "Waist girth", waist.kind = "girth", waist.iso_clause = "5.3.10";
  waist.value_mm = waist_mm;
  r.measurements = {stature, waist};
  return r;
}

storage::TapeMeasurement tape(const std::string& scan, const std::string& name, double value_mm,
                              const std::string& who) {
  storage::TapeMeasurement t;
  t.scan_id = scan, t.name = name, t.value_mm = value_mm, t.measured_by = who;
  return t;
}

TEST(TapeValidation, TheReportCountsEachCustomerOnceWithTheirNewestScan) {
  const std::string dir = testing::temp_dir() + "/tape-archive";
  std::filesystem::remove_all(dir);
  auto archive = storage::Archive::open(dir);
  ASSERT_TRUE(archive.ok()) << archive.status().message();
  storage::Archive& ar = **archive;
  // Five customers; scan minus tape for the waist 2, -1, 3, 0, 1 as above, once
  // the first customer's second scan replaces the 10 of their first.
  const double waist_differences[] = {10, -1, 3, 0, 1};
  std::string first_customer, first_scan;
  for (int i = 0; i < 5; ++i) {
    auto c = ar.add_customer("Customer " + std::to_string(i), std::nullopt, "op");
    ASSERT_TRUE(c.ok());
    auto scan = ar.begin_scan(c->id, "op", {{"name", "thesis"}}, "");
    ASSERT_TRUE(scan.ok());
    const double waist = 800 + 10 * i;
    ASSERT_TRUE(ar.complete_scan(*scan, results(waist, 1700 + i)).ok());
    ASSERT_TRUE(
        ar.put_tape_measurement(tape(*scan, "waist_girth", waist - waist_differences[i], i < 3 ? "Ada" : "Ben"), "op")
            .ok());
    if (i == 0) first_customer = c->id, first_scan = *scan;
  }
  // The first customer comes again: their older scan's waist no longer counts.
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  auto again = ar.begin_scan(first_customer, "op", {{"name", "thesis"}}, "");
  ASSERT_TRUE(again.ok());
  ASSERT_TRUE(ar.complete_scan(*again, results(900, 1701)).ok());
  ASSERT_TRUE(ar.put_tape_measurement(tape(*again, "waist_girth", 898, "Ada"), "op").ok());  // difference 2 again
  // A stature on one customer only, on the older scan: still theirs to count.
  ASSERT_TRUE(ar.put_tape_measurement(tape(first_scan, "stature", 1697, "Ben"), "op").ok());

  auto report = validate_against_tape(ar);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_EQ(report->customers, 5u);
  EXPECT_EQ(report->tape_values, 6u);
  ASSERT_EQ(report->measurements.size(), 2u);
  // In the automatic set's order: stature, then the waist.
  const MeasurementValidation& stature = report->measurements[0];
  EXPECT_EQ(stature.name, "stature");
  EXPECT_EQ(stature.allowance_mm, 4);
  EXPECT_EQ(stature.stats.n, 1u);
  EXPECT_NEAR(stature.stats.mean, 3, 1e-9);
  EXPECT_EQ(stature.judgement.verdict, Verdict::kTooFew);
  const MeasurementValidation& waist = report->measurements[1];
  EXPECT_EQ(waist.label, "Waist girth");
  EXPECT_EQ(waist.iso_clause, "5.3.10");
  EXPECT_EQ(waist.allowance_mm, 9);
  EXPECT_EQ(waist.stats.n, 5u);
  EXPECT_NEAR(waist.stats.mean, 1, 1e-9);
  EXPECT_NEAR(waist.stats.ci_high, 1 + kT4 * std::sqrt(2.5) / std::sqrt(5.0), 1e-6);
  EXPECT_EQ(waist.judgement.verdict, Verdict::kWithin);
  EXPECT_EQ(waist.measured_by, (std::vector<std::string>{"Ada", "Ben"}));
}

}  // namespace
}  // namespace bodyscan::pipeline
