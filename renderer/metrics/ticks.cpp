#include "renderer/metrics/ticks.h"

#include <cmath>
#include <cstdio>

namespace pdflab {

double nice_ceiling(double v) {
  if (!(v > 0.0) || !std::isfinite(v)) return 1.0;
  const double decade = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * decade >= v) return m * decade;
  return 10.0 * decade;
}

double nice_floor(double v) {
  if (!(v > 0.0) || !std::isfinite(v)) return 1.0;
  const double decade = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * decade <= v) return m * decade;
  return decade;
}

std::vector<double> nice_ticks(double lo, double hi, int max_ticks) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || max_ticks < 2) return ticks;
  const double step = nice_ceiling((hi - lo) / (max_ticks - 1));
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (double t = first; t <= hi + step * 1e-9; t += step) ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);
  return ticks;
}

std::vector<double> decade_ticks(double lo, double hi) {
  std::vector<double> ticks;
  if (!(lo > 0.0) || !(hi >= lo) || !std::isfinite(hi)) return ticks;
  const int first = static_cast<int>(std::ceil(std::log10(lo) - 1e-9));
  const int last = static_cast<int>(std::floor(std::log10(hi) + 1e-9));
  for (int e = first; e <= last; ++e) ticks.push_back(std::pow(10.0, e));
  return ticks;
}

std::string tick_label(double v) {
  if (v == 0.0) return "0";
  char buf[32];
  const double a = std::abs(v);
  // %.3g writes 1000 as 1e+03: four digits from 100 on, so the ticks read 100, 1000.
  std::snprintf(buf, sizeof buf, a >= 1e-3 && a < 1e4 ? (a >= 100.0 ? "%.4g" : "%.3g") : "%.0e", v);
  return buf;
}

}  // namespace pdflab
