#include "app/assets.h"

#include <cstdlib>
#include <filesystem>

namespace pdflab {

namespace fs = std::filesystem;

std::string asset_dir() {
  if (const char* env = std::getenv("PDFLAB_ASSETS"); env && *env) return env;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (const fs::path& candidate : {exe.parent_path() / "../share/pdflab/assets", exe.parent_path() / "../assets"})
      if (fs::is_directory(candidate / "scenes", ec)) return fs::weakly_canonical(candidate, ec).string();
  }
  return PDFLAB_SOURCE_ASSETS;
}

std::string default_scene_path() { return (fs::path(asset_dir()) / "scenes" / "cornell_book.json").string(); }

}  // namespace pdflab
