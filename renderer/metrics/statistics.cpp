#include "renderer/metrics/statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace pdflab::stats {

namespace {

constexpr double kEps = 1e-16;
constexpr int kMaxIterations = 100000;

// x^a e^-x / Gamma(a), the common factor of both expansions, in logs so that
// large a (hundreds of degrees of freedom) neither overflows nor underflows early.
double gamma_prefactor(double a, double x) { return std::exp(a * std::log(x) - x - std::lgamma(a)); }

// P(a, x) = prefactor * sum_n x^n / (a (a+1) ... (a+n)). Every term is positive,
// so it converges without cancellation; fast while x < a + 1.
double lower_series(double a, double x) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < kMaxIterations; ++n) {
    term *= x / (a + n);
    sum += term;
    if (term < sum * kEps) break;
  }
  return sum * gamma_prefactor(a, x);
}

// Q(a, x) as the continued fraction 1/(x+1-a- 1(1-a)/(x+3-a- 2(2-a)/(x+5-a- ...))),
// evaluated forwards with the modified Lentz method; fast while x >= a + 1.
double upper_continued_fraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < kMaxIterations; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < kEps) break;
  }
  return h * gamma_prefactor(a, x);
}

}  // namespace

double gamma_p(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) throw std::domain_error("gamma_p: needs a > 0 and x >= 0");
  if (x == 0.0) return 0.0;
  if (x < a + 1.0) return lower_series(a, x);
  return 1.0 - upper_continued_fraction(a, x);
}

double gamma_q(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) throw std::domain_error("gamma_q: needs a > 0 and x >= 0");
  if (x == 0.0) return 1.0;
  // Each side computes its own small tail directly, so tiny p-values keep
  // their relative precision instead of becoming 1 - (1 - p).
  if (x < a + 1.0) return 1.0 - lower_series(a, x);
  return upper_continued_fraction(a, x);
}

double chi_square_survival(double statistic, double dof) {
  if (!(dof > 0.0)) throw std::domain_error("chi_square_survival: dof must be positive");
  return gamma_q(0.5 * dof, std::max(0.0, 0.5 * statistic));
}

double sidak_alpha(double family_alpha, int tests) {
  if (tests < 1) throw std::domain_error("sidak_alpha: needs at least one test");
  // -expm1(log1p(-alpha)/n) is 1 - (1-alpha)^(1/n) without cancellation for large n.
  return -std::expm1(std::log1p(-family_alpha) / tests);
}

double normal_two_sided_tail(double z) { return std::erfc(std::fabs(z) / std::sqrt(2.0)); }

double normal_two_sided_quantile(double alpha) {
  if (!(alpha > 0.0 && alpha < 1.0)) throw std::domain_error("normal_two_sided_quantile: alpha in (0, 1)");
  // The tail is monotone in z: bisection is slow but cannot go wrong.
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (normal_two_sided_tail(mid) > alpha) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

ChiSquareResult chi_square_test(const std::vector<std::uint64_t>& observed, const std::vector<double>& expected,
                                double min_expected) {
  if (observed.size() != expected.size()) throw std::invalid_argument("chi_square_test: size mismatch");
  ChiSquareResult r;
  struct Cell {
    double observed, expected;
  };
  std::vector<Cell> cells;
  Cell pool{0.0, 0.0};
  for (std::size_t i = 0; i < observed.size(); ++i) {
    const double o = static_cast<double>(observed[i]);
    const double e = expected[i];
    if (!(e > 0.0)) {
      r.zero_cell_hits += observed[i];
      continue;
    }
    if (e < min_expected) {
      pool.observed += o;
      pool.expected += e;
      ++r.pooled_cells;
    } else {
      cells.push_back({o, e});
    }
  }
  if (pool.expected > 0.0) {
    if (pool.expected >= min_expected || cells.empty()) {
      cells.push_back(pool);
    } else {
      auto smallest = std::min_element(cells.begin(), cells.end(),
                                       [](const Cell& a, const Cell& b) { return a.expected < b.expected; });
      smallest->observed += pool.observed;
      smallest->expected += pool.expected;
    }
  }
  for (const Cell& c : cells) {
    const double diff = c.observed - c.expected;
    r.statistic += diff * diff / c.expected;
  }
  r.cells = static_cast<int>(cells.size());
  r.dof = r.cells - 1;
  r.p_value = r.dof > 0 ? chi_square_survival(r.statistic, r.dof) : 1.0;
  return r;
}

std::optional<std::vector<double>> least_squares(std::span<const double> design, std::size_t columns,
                                                 std::span<const double> y) {
  const std::size_t n = y.size(), k = columns;
  if (k == 0 || n < k || design.size() != n * k) return std::nullopt;
  for (double v : design)
    if (!std::isfinite(v)) return std::nullopt;
  for (double v : y)
    if (!std::isfinite(v)) return std::nullopt;
  // Columns scaled to unit length: the normal equations of x and x^2 with x in
  // the thousands would otherwise span many orders of magnitude.
  std::vector<double> scale(k, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < k; ++j) scale[j] += design[i * k + j] * design[i * k + j];
  for (double& s : scale) {
    if (!(s > 0.0)) return std::nullopt;  // a zero column
    s = 1.0 / std::sqrt(s);
  }
  // [X^T X | X^T y] of the scaled columns.
  std::vector<double> m(k * (k + 1), 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t r = 0; r < k; ++r) {
      const double xr = design[i * k + r] * scale[r];
      for (std::size_t c = 0; c < k; ++c) m[r * (k + 1) + c] += xr * design[i * k + c] * scale[c];
      m[r * (k + 1) + k] += xr * y[i];
    }
  // Gauss-Jordan with partial pivoting. The scaled matrix has a unit diagonal,
  // so a pivot this small means the columns are (nearly) dependent.
  constexpr double kSingular = 1e-12;
  for (std::size_t c = 0; c < k; ++c) {
    std::size_t pivot = c;
    for (std::size_t r = c + 1; r < k; ++r)
      if (std::fabs(m[r * (k + 1) + c]) > std::fabs(m[pivot * (k + 1) + c])) pivot = r;
    if (!(std::fabs(m[pivot * (k + 1) + c]) > kSingular)) return std::nullopt;
    if (pivot != c)
      for (std::size_t j = 0; j <= k; ++j) std::swap(m[c * (k + 1) + j], m[pivot * (k + 1) + j]);
    const double p = m[c * (k + 1) + c];
    for (std::size_t j = 0; j <= k; ++j) m[c * (k + 1) + j] /= p;
    for (std::size_t r = 0; r < k; ++r) {
      if (r == c) continue;
      const double f = m[r * (k + 1) + c];
      for (std::size_t j = 0; j <= k; ++j) m[r * (k + 1) + j] -= f * m[c * (k + 1) + j];
    }
  }
  std::vector<double> out(k);
  for (std::size_t j = 0; j < k; ++j) out[j] = m[j * (k + 1) + k] * scale[j];
  return out;
}

std::optional<std::vector<double>> polynomial_fit(std::span<const double> x, std::span<const double> y, int degree) {
  if (degree < 0 || x.size() != y.size()) return std::nullopt;
  const std::size_t k = static_cast<std::size_t>(degree) + 1;
  std::vector<double> design(x.size() * k);
  for (std::size_t i = 0; i < x.size(); ++i) {
    double power = 1.0;
    for (std::size_t j = 0; j < k; ++j, power *= x[i]) design[i * k + j] = power;
  }
  return least_squares(design, k, y);
}

}  // namespace pdflab::stats
