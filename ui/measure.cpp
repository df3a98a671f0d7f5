#include "ui/measure.h"

#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/integrator/integrator.h"
#include "renderer/metrics/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pdflab::ui {

static_assert(kDropReasonCount + 1 == std::tuple_size_v<decltype(ViewLayer::drop_pixels)>,
              "one drop count per reason, and one for several");

const char* view_mode_label(ViewMode mode) {
  switch (mode) {
    case ViewMode::Image: return "image";
    case ViewMode::RelativeError: return "relative standard error";
    case ViewMode::Difference: return "difference to reference";
    case ViewMode::Drops: return "dropped samples";
    case ViewMode::Count: break;
  }
  return "?";
}

ViewMode next_view_mode(ViewMode mode) {
  return static_cast<ViewMode>((static_cast<int>(mode) + 1) % kViewModeCount);
}


std::string reference_size_mismatch(const ReferenceImage& reference, int render_width, int render_height) {
  if (!reference.loaded() || (reference.width == render_width && reference.height == render_height)) return {};
  char text[160];
  std::snprintf(text, sizeof text, "The reference is %dx%d but the render is %dx%d: no error can be measured.",
                reference.width, reference.height, render_width, render_height);
  return text;
}

double Figures::plot_error() const {
  if (!valid) return 0.0;
  return std::sqrt(std::max(0.0, against_reference ? relmse : estimated_relmse));
}

Figures compute_figures(const ImageInfo& info, const std::vector<float>& rgb, const ReferenceImage* reference,
                        bool unbiased) {
  Figures f;
  if (info.preview || info.spp == 0) return f;
  f.valid = true;
  f.spp = info.spp;
  f.seconds = info.seconds;
  f.unbiased = unbiased;
  f.mean_relative_standard_error = info.mean_relative_standard_error;
  f.estimated_relmse = info.estimated_relmse;
  f.estimated_efficiency = unbiased ? efficiency(f.estimated_relmse, f.seconds) : 0.0;
  if (reference && reference->loaded() && reference->width == info.width && reference->height == info.height &&
      reference->rgb.size() == rgb.size()) {
    f.against_reference = true;
    f.rmse = rmse(rgb, reference->rgb);
    const RelMseMeasure m = measure_relmse(rgb, reference->rgb, reference->has_variance() ? reference->variance
                                                                                          : std::vector<float>{});
    f.relmse = m.corrected;
    f.relmse_interval = m.interval;
    f.relmse_raw = m.raw;
    f.reference_share = m.reference_share();
    f.reference_corrected = m.reference_corrected;
    f.efficiency = efficiency(f.relmse, f.seconds);
  }
  return f;
}

bool ConvergenceRecorder::record(std::uint64_t generation, const std::string& label, bool estimated,
                                 std::uint32_t spp, double seconds, double error) {
  if (!started_ || generation != generation_ || label != live_.label || estimated != live_.estimated) {
    live_ = Curve{label, estimated, {}};
    generation_ = generation;
    started_ = true;
  }
  if (spp == 0 || !(error > 0.0) || !std::isfinite(error) || !(seconds > 0.0)) return false;
  if (!live_.points.empty() && static_cast<double>(spp) < live_.points.back().spp * kMinSppStep) return false;
  live_.points.push_back({static_cast<double>(spp), seconds, error});
  return true;
}

bool ConvergenceRecorder::pin() {
  if (live_.points.size() < 2) return false;
  if (pins_.size() >= kMaxPins) pins_.erase(pins_.begin());
  pins_.push_back(live_);
  return true;
}

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

std::vector<double> decade_ticks(const LogRange& range) {
  std::vector<double> ticks;
  const int first = static_cast<int>(std::lround(std::log10(range.lo)));
  const int last = static_cast<int>(std::lround(std::log10(range.hi)));
  for (int e = first; e <= last; ++e) ticks.push_back(std::pow(10.0, e));
  return ticks;
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

std::string tick_label(double v) {
  char buf[32];
  if (v == 0.0) return "0";
  const double a = std::abs(v);
  if (a >= 1e-3 && a < 1e4) std::snprintf(buf, sizeof buf, "%g", v);
  else std::snprintf(buf, sizeof buf, "%.0e", v);
  return buf;
}

double luminance(const float* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

std::uint8_t to_byte(float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

void put(std::vector<std::uint8_t>& rgba, std::size_t pixel, const Colour& c, std::uint8_t alpha) {
  std::uint8_t* p = &rgba[4 * pixel];
  p[0] = to_byte(c[0]);
  p[1] = to_byte(c[1]);
  p[2] = to_byte(c[2]);
  p[3] = alpha;
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
    for (double v : decade_ticks(LogRange{scale.lo, scale.hi})) ticks.push_back({scale.position(v), tick_label(v)});
  } else if (scale.diverging) {
    for (double f : {-1.0, -0.5, 0.0, 0.5, 1.0}) {
      std::string label = tick_label(f * scale.hi);
      if (f > 0.0) label = "+" + label;
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

double nice_ceiling(double v) {
  if (!(v > 0.0) || !std::isfinite(v)) return 1.0;
  const double decade = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (v <= m * decade * (1.0 + 1e-9)) return m * decade;
  return 10.0 * decade;
}

std::vector<float> luminance_difference(const std::vector<float>& rgb, const std::vector<float>& reference) {
  std::vector<float> d(std::min(rgb.size(), reference.size()) / 3);
  for (std::size_t p = 0; p < d.size(); ++p)
    d[p] = static_cast<float>(luminance(&rgb[3 * p]) - luminance(&reference[3 * p]));
  return d;
}

double difference_half_range(const std::vector<float>& difference) {
  std::vector<float> a;
  a.reserve(difference.size());
  for (float v : difference)
    if (std::isfinite(v)) a.push_back(std::abs(v));
  if (a.empty()) return 1.0;
  const std::size_t k = std::min(a.size() - 1, static_cast<std::size_t>(0.99 * static_cast<double>(a.size())));
  std::nth_element(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(k), a.end());
  return nice_ceiling(std::max(a[k], 1e-6f));
}

bool build_view_layer(ViewMode mode, const PublishedImage& image, const ReferenceImage* reference, ViewLayer& out,
                      std::string& why) {
  const ImageInfo& info = image.info;
  const std::size_t pixels = static_cast<std::size_t>(info.width) * static_cast<std::size_t>(info.height);
  if (mode == ViewMode::Image) return false;
  if (info.preview || image.relative_standard_error.size() != pixels || image.drop_mask.size() != pixels) {
    why = "waiting for the first full pass";
    return false;
  }
  out.width = info.width;
  out.height = info.height;
  out.rgba.assign(4 * pixels, 0);
  out.drop_pixels = {};
  switch (mode) {
    case ViewMode::RelativeError: {
      if (info.spp < 2) {
        why = "the noise estimate needs 2 samples per pixel";
        return false;
      }
      out.scale = relative_error_scale();
      for (std::size_t p = 0; p < pixels; ++p) put(out.rgba, p, out.scale.colour(image.relative_standard_error[p]), 255);
      return true;
    }
    case ViewMode::Difference: {
      if (!reference || !reference->loaded()) {
        why = "load a reference image (Measure section)";
        return false;
      }
      if (reference->width != info.width || reference->height != info.height) {
        why = reference_size_mismatch(*reference, info.width, info.height);
        return false;
      }
      const std::vector<float> d = luminance_difference(image.rgb, reference->rgb);
      out.scale = difference_scale(difference_half_range(d));
      for (std::size_t p = 0; p < pixels; ++p) put(out.rgba, p, out.scale.colour(d[p]), 255);
      return true;
    }
    case ViewMode::Drops: {
      // Clean pixels darken the image beneath, so the marked ones stand out.
      for (std::size_t p = 0; p < pixels; ++p) {
        const std::uint8_t bits = image.drop_mask[p];
        if (bits == 0) {
          put(out.rgba, p, {0.0f, 0.0f, 0.0f}, 150);
          continue;
        }
        int reason = kDropReasonCount;  // several
        for (int r = 0; r < kDropReasonCount; ++r)
          if (bits == (1u << r)) reason = r;
        ++out.drop_pixels[static_cast<std::size_t>(reason)];
        put(out.rgba, p, drop_reason_colour(reason), 255);
      }
      return true;
    }
    default: break;
  }
  return false;
}

namespace {

bool label_unbiased(const std::string& label) {
  try {
    return Strategy::parse(label).is_unbiased();
  } catch (const std::exception&) {
    return true;  // not a strategy (a test's label): nothing is withheld
  }
}

}  // namespace

void MeasureState::on_image(std::uint64_t current_generation, const std::string& label) {
  const bool unbiased = label_unbiased(label);
  if (!published.info.preview && published.info.spp > 0) {
    if (published.info.generation != history_generation) {
      history.clear();
      history_generation = published.info.generation;
    }
    history.add(published.info.spp, published.info.estimated_relmse);
  }
  figures = compute_figures(published.info, published.rgb, &reference, unbiased);
  figures.estimate_unreliable = history.unreliable();
  if (figures.valid && published.info.generation == current_generation)
    curves.record(published.info.generation, label, !figures.against_reference, figures.spp, figures.seconds,
                  figures.plot_error());
  layer_ok = false;
  layer_why.clear();
}

void MeasureState::set_reference(ReferenceImage image) {
  reference = std::move(image);
  reference_error.clear();
  const bool unbiased = figures.unbiased;
  figures = compute_figures(published.info, published.rgb, &reference, unbiased);
  figures.estimate_unreliable = history.unreliable();
  layer_ok = false;
  layer_why.clear();
}

bool MeasureState::refresh_layer(ViewMode mode) {
  if (mode == layer_mode && (layer_ok || !layer_why.empty() || mode == ViewMode::Image)) return false;
  layer_mode = mode;
  layer_why.clear();
  layer_ok = build_view_layer(mode, published, &reference, layer, layer_why);
  return layer_ok;
}

}  // namespace pdflab::ui
