#pragma once
#include <string>

namespace pdflab {

// The folder holding scenes/ and the other shipped files: $PDFLAB_ASSETS, then
// ../share/pdflab/assets or ../assets beside the executable, then the source tree.
std::string asset_dir();
std::string default_scene_path();

}  // namespace pdflab
