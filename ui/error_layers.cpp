#include "ui/error_layers.h"

#include "renderer/integrator/integrator.h"
#include "renderer/math.h"

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

namespace {

std::uint8_t to_byte(float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

void put(std::vector<std::uint8_t>& rgba, std::size_t pixel, const Colour& c, std::uint8_t alpha) {
  std::uint8_t* p = &rgba[4 * pixel];
  p[0] = to_byte(c[0]);
  p[1] = to_byte(c[1]);
  p[2] = to_byte(c[2]);
  p[3] = alpha;
}

}  // namespace

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

}  // namespace pdflab::ui
