// Student's t distribution, for confidence intervals of a mean from a small
// sample (the ISO 20685-1 validation report).
#pragma once

namespace bodyscan {

// P(T <= t) for T with `dof` > 0 degrees of freedom, to about 1e-12.
double student_t_cdf(double t, double dof);

// The t with P(T <= t) = p, for 0 < p < 1 and `dof` > 0; e.g. the two-sided 95 %
// interval's factor is student_t_quantile(0.975, n - 1).
double student_t_quantile(double p, double dof);

}  // namespace bodyscan
