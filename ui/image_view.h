#pragma once
// Looking closely at the image: zoom and pan of the image in its area, and the
// pixel inspector's readout. Plain data in framebuffer pixels (origin
// bottom-left, as glViewport), so tests need no window.
#include "ui/display.h"
#include "ui/measure.h"

#include <optional>
#include <string>

namespace pdflab::ui {

struct ImageView {
  bool fit = true;     // follows the area: the largest whole view (fit_image)
  double zoom = 1.0;   // otherwise: framebuffer pixels per image pixel
  double x = 0.0, y = 0.0;  // and the image's bottom-left corner, relative to the area's

  static constexpr double kMinZoom = 1.0 / 16.0, kMaxZoom = 64.0;
  // Where the image goes in `area` (it may reach past it: draw clipped).
  Viewport place(const Viewport& area, int image_width, int image_height) const;
  // Zooms by `factor`, keeping the image point under (px, py) where it is.
  void zoom_about(const Viewport& area, int image_width, int image_height, double factor, double px, double py);
  void pan(const Viewport& area, int image_width, int image_height, double dx, double dy);
  // One image pixel per framebuffer pixel, centred in the area (whole pixels).
  void actual_size(const Viewport& area, int image_width, int image_height);

 private:
  void unfit(const Viewport& area, int image_width, int image_height);
};

// What the inspector shows for the pixel under the cursor.
struct PixelReadout {
  int x = 0, y = 0;
  float rgb[3] = {0.0f, 0.0f, 0.0f};  // linear, as in the saved PFM
  double luminance = 0.0;
  std::uint32_t spp = 0;
  double relative_standard_error = -1.0;  // -1: not known (a preview)
  bool preview = false;
  bool has_reference = false;
  float reference[3] = {0.0f, 0.0f, 0.0f};
  double reference_luminance = 0.0;
  // The lines shown (and copied by Ctrl+C): the pixel, its linear RGB, luminance, spp and noise, the reference.
  std::string text() const;
  std::string rgb_text() const;  // "0.123457 0.234568 0.345679": %g with 6 digits
};
// Reads pixel (x, y) of the published image (row 0 at the top); nullopt outside
// or without an image. The reference counts only when its size matches.
std::optional<PixelReadout> read_pixel(const PublishedImage& image, const ReferenceImage* reference, int x, int y);

}  // namespace pdflab::ui
