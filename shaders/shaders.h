#pragma once
// GLSL sources from this folder, embedded at build time (see embed.cmake).

namespace pdflab::shaders {

extern const char* const display_vert;
extern const char* const display_frag;

}  // namespace pdflab::shaders
