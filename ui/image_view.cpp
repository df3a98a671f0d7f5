#include "ui/image_view.h"

#include "renderer/math.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pdflab::ui {

Viewport ImageView::place(const Viewport& area, int image_width, int image_height) const {
  if (fit) return fit_image(area, image_width, image_height);
  Viewport v;
  v.x = area.x + static_cast<int>(std::lround(x));
  v.y = area.y + static_cast<int>(std::lround(y));
  v.width = std::max(1, static_cast<int>(std::lround(image_width * zoom)));
  v.height = std::max(1, static_cast<int>(std::lround(image_height * zoom)));
  return v;
}

void ImageView::unfit(const Viewport& area, int image_width, int image_height) {
  if (!fit) return;
  const Viewport v = fit_image(area, image_width, image_height);
  fit = false;
  zoom = image_width > 0 ? static_cast<double>(v.width) / image_width : 1.0;
  x = v.x - area.x;
  y = v.y - area.y;
}

void ImageView::zoom_about(const Viewport& area, int image_width, int image_height, double factor, double px,
                           double py) {
  if (image_width <= 0 || image_height <= 0 || !(factor > 0.0)) return;
  unfit(area, image_width, image_height);
  const double to = std::clamp(zoom * factor, kMinZoom, kMaxZoom);
  const double ax = px - area.x, ay = py - area.y;
  x = ax - (ax - x) * (to / zoom);
  y = ay - (ay - y) * (to / zoom);
  zoom = to;
}

void ImageView::pan(const Viewport& area, int image_width, int image_height, double dx, double dy) {
  if (image_width <= 0 || image_height <= 0) return;
  unfit(area, image_width, image_height);
  x += dx;
  y += dy;
}

void ImageView::actual_size(const Viewport& area, int image_width, int image_height) {
  fit = false;
  zoom = 1.0;
  x = (area.width - image_width) / 2;
  y = (area.height - image_height) / 2;
}

std::string PixelReadout::rgb_text() const {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%g %g %g", rgb[0], rgb[1], rgb[2]);
  return buf;
}

std::string PixelReadout::text() const {
  char buf[256];
  std::string out;
  std::snprintf(buf, sizeof buf, "pixel (%d, %d)  linear%s\n", x, y, preview ? ", preview" : "");
  out += buf;
  out += "RGB  " + rgb_text() + "\n";
  std::snprintf(buf, sizeof buf, "luminance  %g\n", luminance);
  out += buf;
  if (relative_standard_error >= 0.0)
    std::snprintf(buf, sizeof buf, "%u spp, rel. std. error %.2f%%", spp, relative_standard_error * 100.0);
  else
    std::snprintf(buf, sizeof buf, "%u spp", spp);
  out += buf;
  if (has_reference) {
    std::snprintf(buf, sizeof buf, "\nreference  %g %g %g\nerror (luminance)  %+g (%+.2f%%)", reference[0],
                  reference[1], reference[2], luminance - reference_luminance,
                  reference_luminance > 0.0 ? 100.0 * (luminance - reference_luminance) / reference_luminance : 0.0);
    out += buf;
  }
  return out;
}

std::optional<PixelReadout> read_pixel(const PublishedImage& image, const ReferenceImage* reference, int x, int y) {
  const ImageInfo& info = image.info;
  if (x < 0 || y < 0 || x >= info.width || y >= info.height || info.data_width <= 0 || info.data_height <= 0)
    return std::nullopt;
  // A preview holds one value per preview_scale block.
  const int scale = std::max(1, info.preview_scale);
  const int dx = std::min(info.data_width - 1, x / scale), dy = std::min(info.data_height - 1, y / scale);
  const std::size_t at = 3 * (static_cast<std::size_t>(dy) * static_cast<std::size_t>(info.data_width) +
                              static_cast<std::size_t>(dx));
  if (at + 2 >= image.rgb.size()) return std::nullopt;
  PixelReadout r;
  r.x = x;
  r.y = y;
  for (int c = 0; c < 3; ++c) r.rgb[c] = image.rgb[at + static_cast<std::size_t>(c)];
  r.luminance = luminance(r.rgb);
  r.spp = info.spp;
  r.preview = info.preview;
  const std::size_t pixel = static_cast<std::size_t>(y) * static_cast<std::size_t>(info.width) +
                            static_cast<std::size_t>(x);
  if (!info.preview && pixel < image.relative_standard_error.size())
    r.relative_standard_error = image.relative_standard_error[pixel];
  if (reference && reference->width == info.width && reference->height == info.height &&
      3 * pixel + 2 < reference->rgb.size()) {
    r.has_reference = true;
    for (int c = 0; c < 3; ++c) r.reference[c] = reference->rgb[3 * pixel + static_cast<std::size_t>(c)];
    r.reference_luminance = luminance(r.reference);
  }
  return r;
}

}  // namespace pdflab::ui
