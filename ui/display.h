#pragma once
// Shows the mean radiance as a float texture through shaders/display.*.
// Needs a current OpenGL 3.3 core context with glad loaded.
#include "ui/gl_program.h"

#include <cstdint>
#include <string>

namespace pdflab::ui {

struct Viewport {
  int x = 0, y = 0, width = 0, height = 0;  // framebuffer pixels, origin bottom-left
};

// The largest rectangle with the image's aspect ratio inside `area`, centred.
Viewport fit_image(const Viewport& area, int image_width, int image_height);

class ImageDisplay {
 public:
  ImageDisplay() = default;
  ~ImageDisplay();
  ImageDisplay(const ImageDisplay&) = delete;
  ImageDisplay& operator=(const ImageDisplay&) = delete;

  // Compiles the shaders; returns false with the driver's log in `error`.
  bool init(std::string& error);
  void upload(const float* rgb, int width, int height);
  // Tone-maps into an 8-bit target only when the image, exposure or transfer
  // changed; every other frame is a blit. On a software OpenGL (llvmpipe) that
  // halves the frame's cost, which the render workers get back.
  void draw(const Viewport& where, float exposure_ev, bool srgb);
  bool has_image() const { return width_ > 0; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void tone_map(float exposure_ev, bool srgb);

  GlProgram program_;
  std::uint32_t vao_ = 0, texture_ = 0;
  std::uint32_t mapped_texture_ = 0, mapped_fbo_ = 0;  // tone-mapped RGBA8 copy
  bool mapped_stale_ = true;
  float mapped_exposure_ = 0.0f;
  bool mapped_srgb_ = false;
  int exposure_location_ = -1, transfer_location_ = -1, sampler_location_ = -1;
  int width_ = 0, height_ = 0;
};

}  // namespace pdflab::ui
