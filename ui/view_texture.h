#pragma once
// An RGBA8 texture for the false-colour views, drawn by ImGui over the image
// area (its alpha blending lets the drop overlay show the image beneath).
// Needs a current OpenGL 3.3 core context with glad loaded.
#include <cstdint>

namespace pdflab::ui {

class ViewTexture {
 public:
  ViewTexture() = default;
  ~ViewTexture();
  ViewTexture(const ViewTexture&) = delete;
  ViewTexture& operator=(const ViewTexture&) = delete;

  void upload(const std::uint8_t* rgba, int width, int height);
  std::uint32_t id() const { return texture_; }
  bool empty() const { return width_ == 0; }

 private:
  std::uint32_t texture_ = 0;
  int width_ = 0, height_ = 0;
};

}  // namespace pdflab::ui
