#pragma once
// The false-colour layers drawn over or instead of the image: relative
// standard error, difference to the reference, dropped samples.
#include "renderer/metrics/reference.h"
#include "renderer/session/session.h"
#include "ui/colour_scale.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace pdflab::ui {

enum class ViewMode : std::uint8_t { Image, RelativeError, Difference, Drops, Count };
inline constexpr int kViewModeCount = static_cast<int>(ViewMode::Count);
const char* view_mode_label(ViewMode mode);
ViewMode next_view_mode(ViewMode mode);

// The reference (renderer/metrics/reference.h): mean, variance, sidecar.
using ReferenceImage = pdflab::Reference;

// Empty when the sizes agree; otherwise a sentence saying which is which.
std::string reference_size_mismatch(const ReferenceImage& reference, int render_width, int render_height);

// Luminance of (image - reference) per pixel.
std::vector<float> luminance_difference(const std::vector<float>& rgb, const std::vector<float>& reference);
// A half range for the difference view: the 99th percentile of |d|, made nice,
// so a few fireflies do not wash the rest out.
double difference_half_range(const std::vector<float>& difference);

// A false-colour layer as RGBA8, row 0 at the top, drawn over (Drops) or
// instead of (the others) the image. Returns false with the reason in `why`
// when the mode cannot be shown for this image (a preview, no reference, ...).
struct ViewLayer {
  std::vector<std::uint8_t> rgba;
  int width = 0, height = 0;
  ColourScale scale;  // for the colour bar (unused for Drops)
  std::array<std::uint64_t, 4> drop_pixels{};  // Drops: pixels per reason (+ several, last)
};
bool build_view_layer(ViewMode mode, const PublishedImage& image, const ReferenceImage* reference, ViewLayer& out,
                      std::string& why);

}  // namespace pdflab::ui
