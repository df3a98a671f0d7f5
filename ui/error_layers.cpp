#include "ui/error_layers.h"

#include "renderer/error.h"
#include "renderer/integrator/integrator.h"
#include "renderer/math.h"
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
    case ViewMode::BestWeight: return "best weight (predicted)";
    case ViewMode::TechniqueShare: return "which technique found the light";
    case ViewMode::GuidingTree: return "path guiding's spatial tree";
    case ViewMode::Count: break;
  }
  return "?";
}

ViewMode parse_view_mode(const std::string& name) {
  static constexpr const char* kNames[kViewModeCount] = {"image",       "heatmap",         "difference",  "drops",
                                                        "best-weight", "technique-share", "guiding-tree"};
  for (int i = 0; i < kViewModeCount; ++i)
    if (name == kNames[i]) return static_cast<ViewMode>(i);
  throw InputError("--view '" + name +
                   "' is not a view mode (image, heatmap, difference, drops, best-weight, technique-share, guiding-tree)");
}

bool view_mode_exports(ViewMode mode) {
  return mode != ViewMode::Image && mode != ViewMode::Drops && mode != ViewMode::GuidingTree;
}

ViewMode next_view_mode(ViewMode mode) {
  return static_cast<ViewMode>((static_cast<int>(mode) + 1) % kViewModeCount);
}

const char* error_metric_label(ViewMode mode, ErrorMetric metric) {
  if (mode == ViewMode::RelativeError) {
    switch (metric) {
      case ErrorMetric::Absolute: return "standard error (absolute)";
      case ErrorMetric::Squared: return "variance of the mean (squared)";
      case ErrorMetric::Relative: return "relative standard error";
      case ErrorMetric::RelativeSquared: return "relative variance (relative squared)";
      default: return "?";
    }
  }
  switch (metric) {
    case ErrorMetric::Signed: return "error (signed)";
    case ErrorMetric::Absolute: return "absolute error";
    case ErrorMetric::Squared: return "squared error";
    case ErrorMetric::Relative: return "relative absolute error";
    case ErrorMetric::RelativeSquared: return "relative squared error";
    case ErrorMetric::Count: break;
  }
  return "?";
}

bool view_offers_metric(ViewMode mode, ErrorMetric metric) {
  if (metric == ErrorMetric::Count) return false;
  return mode == ViewMode::Difference || (mode == ViewMode::RelativeError && metric != ErrorMetric::Signed);
}

ViewRange sanitized(const ViewRange& range, bool signed_metric) {
  ViewRange r = range;
  const auto usable = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (signed_metric) {
    if (!usable(r.hi)) r.hi = 1.0;
    r.lo = -r.hi;
    return r;
  }
  if (!usable(r.lo) && !usable(r.hi)) r = {r.automatic, 1e-3, 1.0};
  if (!usable(r.lo)) r.lo = r.hi / 1e3;
  if (!usable(r.hi)) r.hi = r.lo * 1e3;
  if (r.lo > r.hi) std::swap(r.lo, r.hi);
  r.lo = std::max(r.lo, 1e-30);
  if (!(r.hi >= r.lo * kMinRangeRatio)) r.hi = r.lo * kMinRangeRatio;
  return r;
}

LayerOptions default_heat_map_options() {
  LayerOptions o;
  o.metric = ErrorMetric::Relative;
  o.range = {false, 1e-3, 10.0};
  return o;
}

LayerOptions default_difference_options() {
  LayerOptions o;
  o.metric = ErrorMetric::Signed;
  o.range = {true, 1e-3, 1.0};
  return o;
}


std::string reference_size_mismatch(const ReferenceImage& reference, int render_width, int render_height) {
  if (!reference.loaded() || (reference.width == render_width && reference.height == render_height)) return {};
  char text[160];
  std::snprintf(text, sizeof text, "The reference is %dx%d but the render is %dx%d: no error can be measured.",
                reference.width, reference.height, render_width, render_height);
  return text;
}

namespace {

std::uint8_t to_byte(float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

void put(std::vector<std::uint8_t>& rgba, std::size_t pixel, const Colour& c, std::uint8_t alpha) {
  std::uint8_t* p = &rgba[4 * pixel];
  p[0] = to_byte(c[0]);
  p[1] = to_byte(c[1]);
  p[2] = to_byte(c[2]);
  p[3] = alpha;
}

float metric_value(ErrorMetric metric, double error, double value) {
  const double e = std::abs(error);
  switch (metric) {
    case ErrorMetric::Signed: return static_cast<float>(error);
    case ErrorMetric::Absolute: return static_cast<float>(e);
    case ErrorMetric::Squared: return static_cast<float>(e * e);
    case ErrorMetric::Relative: return static_cast<float>(e / (std::abs(value) + kRelMseEpsilon));
    case ErrorMetric::RelativeSquared: return static_cast<float>(e * e / (value * value + kRelMseEpsilon));
    case ErrorMetric::Count: break;
  }
  return 0.0f;
}

// The `q` quantile of the finite values (positive ones only if `positive`); NaN when there is none.
double quantile(const std::vector<float>& values, double q, bool positive) {
  std::vector<float> a;
  a.reserve(values.size());
  for (float v : values)
    if (std::isfinite(v) && (!positive || v > 0.0f)) a.push_back(v);
  if (a.empty()) return NAN;
  const std::size_t k = std::min(a.size() - 1, static_cast<std::size_t>(q * static_cast<double>(a.size())));
  std::nth_element(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(k), a.end());
  return a[k];
}

const char* metric_title(ViewMode mode, ErrorMetric metric) {
  if (mode == ViewMode::RelativeError) {
    switch (metric) {
      case ErrorMetric::Absolute: return "standard error of the mean, luminance (log)";
      case ErrorMetric::Squared: return "variance of the mean, luminance (log)";
      case ErrorMetric::RelativeSquared: return "variance / (mean + 0.01)^2 per pixel (log)";
      default: return "relative standard error per pixel (log)";
    }
  }
  switch (metric) {
    case ErrorMetric::Signed: return "luminance: image - reference";
    case ErrorMetric::Absolute: return "|image - reference|, luminance (log)";
    case ErrorMetric::Squared: return "(image - reference)^2, luminance (log)";
    case ErrorMetric::Relative: return "|image - reference| / (reference + 0.01) (log)";
    case ErrorMetric::RelativeSquared: return "(image - reference)^2 / (reference^2 + 0.01) (log)";
    case ErrorMetric::Count: break;
  }
  return "?";
}

}  // namespace

std::vector<float> luminance_difference(const std::vector<float>& rgb, const std::vector<float>& reference) {
  return difference_values(rgb, reference, ErrorMetric::Signed);
}

double difference_half_range(const std::vector<float>& difference) {
  std::vector<float> a(difference.size());
  std::transform(difference.begin(), difference.end(), a.begin(), [](float v) { return std::abs(v); });
  const double q = quantile(a, 0.99, false);
  return std::isfinite(q) ? nice_ceiling(std::max(q, 1e-6)) : 1.0;
}

std::vector<float> heat_map_values(const PublishedImage& image, ErrorMetric metric) {
  const std::vector<float>& rse = image.relative_standard_error;
  std::vector<float> v(rse.size());
  const bool have_mean = image.rgb.size() >= 3 * rse.size();
  for (std::size_t p = 0; p < v.size(); ++p) {
    // The map is sqrt(variance of the mean) / (mean + 0.01), of the luminance (metrics.h).
    const double mean = have_mean ? luminance(&image.rgb[3 * p]) : 0.0;
    const double standard_error = static_cast<double>(rse[p]) * (mean + kRelMseEpsilon);
    switch (metric) {
      case ErrorMetric::Absolute: v[p] = static_cast<float>(standard_error); break;
      case ErrorMetric::Squared: v[p] = static_cast<float>(standard_error * standard_error); break;
      case ErrorMetric::RelativeSquared: v[p] = rse[p] * rse[p]; break;
      default: v[p] = rse[p]; break;
    }
  }
  return v;
}

std::vector<float> difference_values(const std::vector<float>& rgb, const std::vector<float>& reference,
                                     ErrorMetric metric) {
  std::vector<float> v(std::min(rgb.size(), reference.size()) / 3);
  for (std::size_t p = 0; p < v.size(); ++p) {
    const double r = luminance(&reference[3 * p]);
    v[p] = metric_value(metric, luminance(&rgb[3 * p]) - r, r);
  }
  return v;
}

ColourScale error_scale(ViewMode mode, const LayerOptions& options, const std::vector<float>& values) {
  const bool signed_metric = options.metric == ErrorMetric::Signed && mode == ViewMode::Difference;
  ViewRange range = sanitized(options.range, signed_metric);
  ColourScale s;
  if (signed_metric) {
    s = difference_scale(range.automatic ? difference_half_range(values) : range.hi);
  } else {
    if (range.automatic) {
      const double hi = quantile(values, 0.99, true), lo = quantile(values, 0.01, true);
      if (std::isfinite(hi)) {
        range.hi = nice_ceiling(hi);
        range.lo = std::clamp(nice_floor(lo), range.hi * 1e-6, range.hi / 10.0);
      } else {
        range.lo = 1e-3;
        range.hi = 1.0;
      }
    }
    s.logarithmic = true;
    s.lo = range.lo;
    s.hi = range.hi;
  }
  s.title = metric_title(mode, options.metric);
  return s;
}

ColourScale best_weight_scale(const WeightMaps& maps) {
  ColourScale s;
  s.diverging = true;
  s.hi = 0.5;
  s.lo = -0.5;
  s.label_offset = 0.5;
  s.title = "predicted best weight of " + maps.a + " (0: all " + maps.b + ", 1: all " + maps.a + ")";
  return s;
}

ColourScale technique_share_scale(const WeightMaps& maps) {
  ColourScale s;
  s.lo = 0.0;
  s.hi = 1.0;
  s.title = "share of the light found by " + maps.a + "'s directions (0: all by " + maps.b + ")";
  return s;
}

namespace {

// The weight views: from the viewer's prediction, not from the published image.
bool build_weight_layer(ViewMode mode, const WeightMaps* maps, ViewLayer& out, std::string& why) {
  if (!maps || maps->a.empty()) {
    why = maps && !maps->why.empty() ? maps->why : "render a mixture of two techniques";
    return false;
  }
  const std::size_t pixels = static_cast<std::size_t>(maps->width) * static_cast<std::size_t>(maps->height);
  const int block = std::max(1, maps->block), blocks_x = (maps->width + block - 1) / block;
  const std::size_t cells = static_cast<std::size_t>(blocks_x * ((maps->height + block - 1) / block));
  if (maps->share_a.size() != pixels || maps->best_weight.size() != cells || pixels == 0) {
    why = maps->why.empty() ? "waiting for the prediction" : maps->why;
    return false;
  }
  out.width = maps->width;
  out.height = maps->height;
  out.rgba.assign(4 * pixels, 0);
  out.drop_pixels = {};
  out.scale = mode == ViewMode::BestWeight ? best_weight_scale(*maps) : technique_share_scale(*maps);
  for (int y = 0; y < maps->height; ++y)
    for (int x = 0; x < maps->width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(maps->width) + static_cast<std::size_t>(x);
      const float v = mode == ViewMode::BestWeight
                          ? maps->best_weight[static_cast<std::size_t>((y / block) * blocks_x + x / block)]
                          : maps->share_a[p];
      // Nothing to say there: dark grey, so it does not read as a value.
      if (v < 0.0f) put(out.rgba, p, {0.2f, 0.2f, 0.2f}, 255);
      else put(out.rgba, p, out.scale.colour(mode == ViewMode::BestWeight ? v - 0.5 : v), 255);
    }
  return true;
}

// Path guiding's S-tree over the image: each leaf a translucent colour, the
// borders between leaves (and around what no leaf holds) drawn solid.
bool build_guiding_layer(const GuidingLeafMap* map, ViewLayer& out, std::string& why) {
  const std::size_t pixels = map ? static_cast<std::size_t>(map->width) * static_cast<std::size_t>(map->height) : 0;
  if (!map || pixels == 0 || map->leaf.size() != pixels) {
    why = "render a strategy with guided (its training builds the tree), e.g. nee-mis+mix:cosine=0.5,guided=0.5";
    return false;
  }
  out.width = map->width;
  out.height = map->height;
  out.rgba.assign(4 * pixels, 0);
  out.drop_pixels = {};
  const auto row = static_cast<std::size_t>(map->width);
  for (int y = 0; y < map->height; ++y)
    for (int x = 0; x < map->width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * row + static_cast<std::size_t>(x);
      const std::int32_t leaf = map->leaf[p];
      if (leaf < 0) continue;  // transparent: the image shows
      const bool border = (x + 1 < map->width && map->leaf[p + 1] != leaf) || (y + 1 < map->height && map->leaf[p + row] != leaf);
      if (border) put(out.rgba, p, {0.05f, 0.05f, 0.05f}, 230);
      else put(out.rgba, p, guiding_leaf_colour(leaf), 110);
    }
  return true;
}

}  // namespace

bool build_view_layer(ViewMode mode, const PublishedImage& image, const ReferenceImage* reference, ViewLayer& out,
                      std::string& why, const LayerOptions* given, const WeightMaps* maps,
                      const GuidingLeafMap* leaves) {
  if (mode == ViewMode::BestWeight || mode == ViewMode::TechniqueShare) return build_weight_layer(mode, maps, out, why);
  if (mode == ViewMode::GuidingTree) return build_guiding_layer(leaves, out, why);
  const LayerOptions options = given ? *given
                                     : (mode == ViewMode::Difference ? default_difference_options()
                                                                     : default_heat_map_options());
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
      const std::vector<float> v = heat_map_values(image, options.metric);
      out.scale = error_scale(mode, options, v);
      for (std::size_t p = 0; p < pixels; ++p) put(out.rgba, p, out.scale.colour(v[p]), 255);
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
      const std::vector<float> d = difference_values(image.rgb, reference->rgb, options.metric);
      out.scale = error_scale(mode, options, d);
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

}  // namespace pdflab::ui
