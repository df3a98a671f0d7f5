#pragma once
// Small statistics toolkit for the statistical tests and the viewer's in-app
// chi-square check: chi-square p-values
// (regularised incomplete gamma), multiple-testing corrections and normal
// quantiles, and linear least squares. Double precision throughout; nothing
// here is on a hot path.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace pdflab::stats {

// Regularised lower and upper incomplete gamma functions P(a, x) and
// Q(a, x) = 1 - P(a, x), for a > 0 and x >= 0.
double gamma_p(double a, double x);
double gamma_q(double a, double x);

// Probability that a chi-square variable with `dof` degrees of freedom is at
// least `statistic` (the test's p-value).
double chi_square_survival(double statistic, double dof);

// Per-test significance level that keeps the family-wise error rate at
// `family_alpha` over `tests` independent tests: 1 - (1 - alpha)^(1/tests).
double sidak_alpha(double family_alpha, int tests);

// Two-sided standard normal tail probability P(|Z| >= z).
double normal_two_sided_tail(double z);
// The z with P(|Z| >= z) = alpha (0 < alpha < 1).
double normal_two_sided_quantile(double alpha);

struct ChiSquareResult {
  double statistic = 0.0;
  int dof = 0;                     // cells after pooling, minus one
  double p_value = 1.0;
  int cells = 0;                   // cells that entered the statistic (after pooling)
  int pooled_cells = 0;            // cells merged because their expected count was below the minimum
  std::uint64_t zero_cell_hits = 0;  // samples in cells whose expected count is exactly zero
};

// Pearson's chi-square goodness of fit. Cells with expected count 0 are left
// out of the statistic; any sample in one is reported in zero_cell_hits (the
// sampler produced a direction its pdf calls impossible). Cells with expected
// count below `min_expected` are pooled into one cell (merged into the smallest
// regular cell if the pool itself stays below the minimum).
ChiSquareResult chi_square_test(const std::vector<std::uint64_t>& observed, const std::vector<double>& expected,
                                double min_expected = 5.0);

// Linear least squares: the coefficients c minimising
// sum_i (y_i - sum_j c_j X_ij)^2, with the design matrix X given row by row
// (`columns` values per point, so design.size() == y.size() * columns). Solved
// through the normal equations with the columns scaled to unit length and
// partial pivoting (the fits here have two or three columns). nullopt when the
// points do not determine the coefficients: fewer points than columns, a
// column that is zero or a combination of the others, or a size mismatch.
std::optional<std::vector<double>> least_squares(std::span<const double> design, std::size_t columns,
                                                 std::span<const double> y);

// The polynomial y = c_0 + c_1 x + ... + c_degree x^degree of least squares
// (coefficients from c_0 up); nullopt as for least_squares (for example fewer
// distinct x than coefficients).
std::optional<std::vector<double>> polynomial_fit(std::span<const double> x, std::span<const double> y, int degree);

}  // namespace pdflab::stats
