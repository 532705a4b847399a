// Student's t against closed forms (1 and 2 degrees of freedom) and against the
// printed two-sided 95 % table.
#include "core/student_t.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

namespace bodyscan {
namespace {

TEST(StudentT, CdfMatchesTheClosedFormsForOneAndTwoDegreesOfFreedom) {
  const double pi = std::acos(-1.0);
  for (double t : {-30.0, -4.0, -1.0, -0.25, 0.0, 0.3, 1.0, 2.5, 12.0, 300.0}) {
    // One degree of freedom is the Cauchy distribution; two has an algebraic cdf.
    EXPECT_NEAR(student_t_cdf(t, 1), 0.5 + std::atan(t) / pi, 1e-12) << t;
    EXPECT_NEAR(student_t_cdf(t, 2), 0.5 + t / (2 * std::sqrt(2 + t * t)), 1e-12) << t;
  }
}

TEST(StudentT, QuantileMatchesThePrintedTable) {
  // t(0.975, dof), as printed in statistical tables to 8 digits.
  const std::pair<double, double> table[] = {{1, 12.7062047},  {2, 4.30265273},  {5, 2.57058184},  {9, 2.26215716},
                                             {10, 2.22813885}, {29, 2.04522964}, {39, 2.02269092}, {100, 1.98397152}};
  for (const auto& [dof, t] : table) {
    EXPECT_NEAR(student_t_quantile(0.975, dof), t, 5e-8) << dof;
    EXPECT_NEAR(student_t_quantile(0.025, dof), -t, 5e-8) << dof;
  }
  // Many degrees of freedom: the normal distribution's 1.959964.
  EXPECT_NEAR(student_t_quantile(0.975, 1e7), 1.95996398, 1e-6);
}

TEST(StudentT, QuantileInvertsTheCdf) {
  for (double dof : {1.0, 3.0, 7.5, 40.0})
    for (double p : {0.001, 0.1, 0.5, 0.8, 0.999})
      EXPECT_NEAR(student_t_cdf(student_t_quantile(p, dof), dof), p, 1e-10);
}

TEST(StudentT, OutsideItsDomainIsNotANumber) {
  EXPECT_TRUE(std::isnan(student_t_quantile(0, 5)));
  EXPECT_TRUE(std::isnan(student_t_quantile(1, 5)));
  EXPECT_TRUE(std::isnan(student_t_quantile(0.9, 0)));
  EXPECT_TRUE(std::isnan(student_t_cdf(1, -1)));
}

}  // namespace
}  // namespace bodyscan
