#include "ui/display.h"

#include "shaders/shaders.h"

#include <glad/gl.h>

#include <algorithm>
#include <cmath>

namespace pdflab::ui {

Viewport fit_image(const Viewport& area, int image_width, int image_height) {
  if (area.width <= 0 || area.height <= 0 || image_width <= 0 || image_height <= 0) return {area.x, area.y, 0, 0};
  const double scale = std::min(static_cast<double>(area.width) / image_width,
                                static_cast<double>(area.height) / image_height);
  Viewport v;
  v.width = std::max(1, static_cast<int>(std::lround(image_width * scale)));
  v.height = std::max(1, static_cast<int>(std::lround(image_height * scale)));
  v.x = area.x + (area.width - v.width) / 2;
  v.y = area.y + (area.height - v.height) / 2;
  return v;
}

bool ImageDisplay::init(std::string& error) {
  if (!program_.build(shaders::display_vert, shaders::display_frag, error)) return false;
  exposure_location_ = program_.uniform("exposure");
  transfer_location_ = program_.uniform("transfer");
  sampler_location_ = program_.uniform("mean_radiance");

  glGenVertexArrays(1, &vao_);
  glGenTextures(1, &texture_);
  glBindTexture(GL_TEXTURE_2D, texture_);
  // Read texel for texel by the tone-mapping pass: no filtering.
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

  glGenTextures(1, &mapped_texture_);
  glGenFramebuffers(1, &mapped_fbo_);
  return true;
}

ImageDisplay::~ImageDisplay() {
  // Only valid while the context lives; the viewer destroys us before it.
  if (mapped_fbo_) glDeleteFramebuffers(1, &mapped_fbo_);
  if (mapped_texture_) glDeleteTextures(1, &mapped_texture_);
  if (texture_) glDeleteTextures(1, &texture_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
}

void ImageDisplay::upload(const float* rgb, int width, int height) {
  glBindTexture(GL_TEXTURE_2D, texture_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);  // rows of 3 floats are always 4-byte aligned
  if (width != width_ || height != height_) {
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, width, height, 0, GL_RGB, GL_FLOAT, rgb);
    width_ = width;
    height_ = height;
    glBindTexture(GL_TEXTURE_2D, mapped_texture_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glBindFramebuffer(GL_FRAMEBUFFER, mapped_fbo_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, mapped_texture_, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  } else {
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGB, GL_FLOAT, rgb);
  }
  mapped_stale_ = true;
}

void ImageDisplay::tone_map(float exposure_ev, bool srgb) {
  glBindFramebuffer(GL_FRAMEBUFFER, mapped_fbo_);
  glViewport(0, 0, width_, height_);
  glDisable(GL_BLEND);
  glUseProgram(program_.id());
  glUniform1f(exposure_location_, std::exp2(exposure_ev));
  glUniform1i(transfer_location_, srgb ? 1 : 0);
  glUniform1i(sampler_location_, 0);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture_);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glUseProgram(0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  mapped_stale_ = false;
  mapped_exposure_ = exposure_ev;
  mapped_srgb_ = srgb;
}

void ImageDisplay::draw(const Viewport& where, float exposure_ev, bool srgb) {
  if (!has_image() || where.width <= 0 || where.height <= 0) return;
  if (mapped_stale_ || exposure_ev != mapped_exposure_ || srgb != mapped_srgb_) tone_map(exposure_ev, srgb);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, mapped_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  // Shrinking averages; enlarging keeps pixels square (their noise is the point).
  const bool shrinking = where.width < width_ || where.height < height_;
  glBlitFramebuffer(0, 0, width_, height_, where.x, where.y, where.x + where.width, where.y + where.height,
                    GL_COLOR_BUFFER_BIT, shrinking ? GL_LINEAR : GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace pdflab::ui
