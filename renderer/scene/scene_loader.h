#pragma once
// Scene files (JSON, docs/scene_format.md). Every problem is an InputError whose
// message names the file and the JSON path (`objects[3].radius`), or the line
// and column of a syntax error.
#include "renderer/scene/scene.h"

#include <string>

namespace pdflab {

Scene load_scene_file(const std::string& path);
// `origin` names the source in messages (a file name, "<string>"); `base` is
// the folder a relative environment map's path starts from (empty: the
// working directory).
Scene load_scene_text(const std::string& text, const std::string& origin, const std::string& base = "");

}  // namespace pdflab
