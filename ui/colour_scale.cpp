#include "ui/colour_scale.h"

#include "renderer/integrator/integrator.h"

#include <algorithm>
#include <cmath>

namespace pdflab::ui {

double LogRange::position(double v) const {
  if (!(v > 0.0)) return 0.0;
  return (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
}

LogRange log_range(const std::vector<double>& values) {
  double mn = 0.0, mx = 0.0;
  bool any = false;
  for (double v : values) {
    if (!(v > 0.0) || !std::isfinite(v)) continue;
    mn = any ? std::min(mn, v) : v;
    mx = any ? std::max(mx, v) : v;
    any = true;
  }
  if (!any) return {};
  LogRange r;
  // A tiny epsilon keeps an exact power of ten on its own decade.
  r.lo = std::pow(10.0, std::floor(std::log10(mn) + 1e-9));
  r.hi = std::pow(10.0, std::ceil(std::log10(mx) - 1e-9));
  if (r.hi <= r.lo) r.hi = r.lo * 10.0;
  return r;
}

namespace {

Colour lerp_stops(const Colour* stops, int count, double t) {
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * (count - 1);
  const int i = std::min(static_cast<int>(t), count - 2);
  const float f = static_cast<float>(t - i);
  Colour c;
  for (int k = 0; k < 3; ++k) c[k] = stops[i][k] + (stops[i + 1][k] - stops[i][k]) * f;
  return c;
}

}  // namespace

Colour sequential_colour(double t) {
  // Hand-placed stops, lightness rising steadily from near black to pale yellow.
  static constexpr Colour kStops[] = {{0.02f, 0.01f, 0.08f}, {0.23f, 0.06f, 0.43f}, {0.52f, 0.13f, 0.50f},
                                      {0.82f, 0.25f, 0.38f}, {0.98f, 0.52f, 0.25f}, {0.99f, 0.87f, 0.55f}};
  return lerp_stops(kStops, 6, t);
}

Colour diverging_colour(double t) {
  static constexpr Colour kStops[] = {{0.17f, 0.32f, 0.80f}, {0.55f, 0.68f, 0.95f}, {0.92f, 0.92f, 0.92f},
                                      {0.95f, 0.60f, 0.48f}, {0.78f, 0.12f, 0.15f}};
  return lerp_stops(kStops, 5, (std::clamp(std::isfinite(t) ? t : 0.0, -1.0, 1.0) + 1.0) * 0.5);
}

Colour guiding_leaf_colour(int leaf) {
  // Hues a golden angle apart, at two lightnesses by turns.
  const double hue = std::fmod(static_cast<double>(leaf) * 0.6180339887498949, 1.0) * 6.0;
  const double f = hue - std::floor(hue), lightness = leaf % 2 ? 0.75 : 1.0;
  const double q = 1.0 - f;
  double r = 0.0, g = 0.0, b = 0.0;
  switch (static_cast<int>(hue)) {
    case 0: r = 1.0, g = f, b = 0.0; break;
    case 1: r = q, g = 1.0, b = 0.0; break;
    case 2: r = 0.0, g = 1.0, b = f; break;
    case 3: r = 0.0, g = q, b = 1.0; break;
    case 4: r = f, g = 0.0, b = 1.0; break;
    default: r = 1.0, g = 0.0, b = q; break;
  }
  return {static_cast<float>(r * lightness), static_cast<float>(g * lightness), static_cast<float>(b * lightness)};
}

Colour drop_reason_colour(int reason) {
  switch (static_cast<DropReason>(reason)) {
    case DropReason::PdfZero: return {1.0f, 0.25f, 0.85f};            // magenta
    case DropReason::PdfNotFinite: return {0.2f, 0.9f, 1.0f};         // cyan
    case DropReason::RadianceNotFinite: return {1.0f, 0.85f, 0.1f};   // yellow
    default: break;
  }
  return kSeveralDropReasonsColour;
}

double ColourScale::position(double v) const {
  if (!std::isfinite(v)) return v > 0.0 ? 1.0 : 0.0;
  double t;
  if (diverging) t = (v / hi + 1.0) * 0.5;
  else if (logarithmic) t = v > 0.0 ? (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : 0.0;
  else t = (v - lo) / (hi - lo);
  return std::clamp(t, 0.0, 1.0);
}

Colour ColourScale::colour(double v) const {
  const double t = position(v);
  return diverging ? diverging_colour(2.0 * t - 1.0) : sequential_colour(t);
}

std::vector<LegendTick> legend_ticks(const ColourScale& scale) {
  std::vector<LegendTick> ticks;
  if (scale.logarithmic && !scale.diverging) {
    // Both ends, and round values between them: the decades, or 1-2-5 steps
    // when the range spans less than two decades. None crowds an end.
    const double l0 = std::log10(scale.lo), l1 = std::log10(scale.hi);
    const bool few_decades = l1 - l0 < 2.0 - 1e-9;
    static constexpr double kSteps[] = {1.0, 2.0, 5.0};
    std::vector<double> inner;
    for (int e = static_cast<int>(std::floor(l0)) - 1; e <= static_cast<int>(std::ceil(l1)); ++e)
      for (int k = 0; k < (few_decades ? 3 : 1); ++k) {
        const double v = kSteps[k] * std::pow(10.0, e);
        const double t = scale.position(v);
        if (v > scale.lo * (1.0 + 1e-9) && v < scale.hi * (1.0 - 1e-9) && t > 0.12 && t < 0.88) inner.push_back(v);
      }
    // At most five between the ends: every other one (or third...) of a long run.
    std::size_t step = 1;
    while (inner.size() / step > 5) ++step;
    ticks.push_back({0.0, tick_label(scale.lo)});
    for (std::size_t i = 0; i < inner.size(); i += step) ticks.push_back({scale.position(inner[i]), tick_label(inner[i])});
    ticks.push_back({1.0, tick_label(scale.hi)});
  } else if (scale.diverging) {
    for (double f : {-1.0, -0.5, 0.0, 0.5, 1.0}) {
      std::string label = tick_label(f * scale.hi + scale.label_offset);
      if (f > 0.0 && scale.label_offset == 0.0) label = "+" + label;
      ticks.push_back({scale.position(f * scale.hi), label});
    }
  } else {
    for (int i = 0; i <= 4; ++i) {
      const double v = scale.lo + (scale.hi - scale.lo) * i / 4.0;
      ticks.push_back({scale.position(v), tick_label(v)});
    }
  }
  return ticks;
}

ColourScale relative_error_scale() {
  ColourScale s;
  s.logarithmic = true;
  s.lo = 1e-3;
  s.hi = 10.0;
  s.title = "relative standard error per pixel (log)";
  return s;
}

ColourScale difference_scale(double half_range) {
  ColourScale s;
  s.diverging = true;
  s.hi = half_range > 0.0 && std::isfinite(half_range) ? half_range : 1.0;
  s.lo = -s.hi;
  s.title = "luminance: image - reference";
  return s;
}

std::vector<std::size_t> labels_that_fit(const std::vector<float>& centre, const std::vector<float>& width, float bar,
                                         float gap) {
  const std::size_t n = std::min(centre.size(), width.size());
  std::vector<std::size_t> keep;
  if (n == 0) return keep;
  // A label's left edge, clamped so it stays on the bar as the drawing does.
  const auto left = [&](std::size_t i) { return std::clamp(centre[i] - width[i] * 0.5f, 0.0f, std::max(0.0f, bar - width[i])); };
  keep.push_back(0);
  if (n == 1) return keep;
  const float last_left = left(n - 1);
  float right = left(0) + width[0];
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (left(i) < right + gap || left(i) + width[i] + gap > last_left) continue;
    keep.push_back(i);
    right = left(i) + width[i];
  }
  keep.push_back(n - 1);
  return keep;
}

}  // namespace pdflab::ui
