#pragma once
// An OpenGL program from a vertex and a fragment shader: compiled, linked and
// its error log read in one place, for every program the viewer draws with.
// Needs a current OpenGL 3.3 core context with glad loaded.
#include <cstdint>
#include <string>

namespace pdflab::ui {

class GlProgram {
 public:
  GlProgram() = default;
  ~GlProgram();
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;

  // Compiles both shaders and links them; false with the driver's log in
  // `error` (naming the stage that failed), and nothing left behind.
  bool build(const char* vertex_source, const char* fragment_source, std::string& error);
  std::uint32_t id() const { return program_; }
  // The location of a uniform (-1 when the program has none of that name).
  int uniform(const char* name) const;

 private:
  std::uint32_t program_ = 0;
};

}  // namespace pdflab::ui
