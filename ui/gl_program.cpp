#include "ui/gl_program.h"

#include <glad/gl.h>

namespace pdflab::ui {

namespace {

std::string shader_log(GLuint shader) {
  char log[2048] = {};
  glGetShaderInfoLog(shader, sizeof log, nullptr, log);
  return log;
}

std::string program_log(GLuint program) {
  char log[2048] = {};
  glGetProgramInfoLog(program, sizeof log, nullptr, log);
  return log;
}

// A compiled shader, or 0 with "vertex shader: LOG" in `error`.
GLuint compile(GLenum kind, const char* source, std::string& error) {
  const GLuint shader = glCreateShader(kind);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok) return shader;
  error = std::string(kind == GL_VERTEX_SHADER ? "vertex" : "fragment") + " shader: " + shader_log(shader);
  glDeleteShader(shader);
  return 0;
}

}  // namespace

GlProgram::~GlProgram() {
  // Only valid while the context lives; its owners go before it.
  if (program_) glDeleteProgram(program_);
}

bool GlProgram::build(const char* vertex_source, const char* fragment_source, std::string& error) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_source, error);
  if (!vs) return false;
  const GLuint fs = compile(GL_FRAGMENT_SHADER, fragment_source, error);
  if (!fs) {
    glDeleteShader(vs);
    return false;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  // Attached shaders are freed with the program.
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    error = "shader link: " + program_log(program);
    glDeleteProgram(program);
    return false;
  }
  if (program_) glDeleteProgram(program_);
  program_ = program;
  return true;
}

int GlProgram::uniform(const char* name) const { return program_ ? glGetUniformLocation(program_, name) : -1; }

}  // namespace pdflab::ui
