#include "app/reference_command.h"

#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/reference_build.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <thread>

#ifndef PDFLAB_VERSION
#define PDFLAB_VERSION "unknown"
#endif

namespace pdflab {

namespace {

std::string make_command(const Scene& scene, const std::string& scene_file) {
  return "pdflab reference --scene " + scene_file + " --width " + std::to_string(scene.camera.width) + " --height " +
         std::to_string(scene.camera.height) + " --max-depth " + std::to_string(scene.max_depth) + " --seconds 60";
}

void draw_progress(const ReferenceProgress& p, const SessionStats& st) {
  constexpr int kWidth = 32;
  std::string bar(static_cast<std::size_t>(p.fraction * kWidth), '#');
  bar.resize(kWidth, '.');
  std::fprintf(stderr, "\rreference [%s] %3d%%  %u spp  %.1f s  ~%.0f s left ", bar.c_str(),
               static_cast<int>(p.fraction * 100.0), st.spp, st.seconds, p.seconds_left);
  std::fflush(stderr);
}

}  // namespace

void note_unknown_seed(const Reference& reference, const std::vector<std::uint64_t>& seeds) {
  if (!reference.loaded() || reference.info.seed_known) return;
  std::string list;
  for (std::uint64_t seed : seeds) {
    if (!list.empty()) list += ", ";
    list += std::to_string(seed);
  }
  std::fprintf(stderr,
               "note: reference '%s' does not record its seed (a PFM without its sidecar '%s'): were it rendered with "
               "seed %s, it would share random numbers with this render and the error would look too small\n",
               printable(reference.path).c_str(), printable(reference_paths(reference.path).sidecar).c_str(),
               list.c_str());
}

void check_cache_dir(const std::string& cache_dir) {
  namespace fs = std::filesystem;
  const auto refuse = [&](const std::string& why) {
    throw InputError("reference cache folder '" + cache_dir + "' " + why + " (--cache-dir, $PDFLAB_REFERENCE_CACHE)");
  };
  // The folder itself, or the nearest part of its path that exists.
  fs::path at = fs::path(cache_dir).lexically_normal();
  for (;;) {
    std::error_code ec;
    const fs::file_status st = fs::status(at, ec);
    if (ec && ec != std::errc::no_such_file_or_directory)
      refuse("cannot be used: '" + at.string() + "': " + ec.message());  // a symlink loop, a file on the way
    if (fs::exists(st)) {
      if (!fs::is_directory(st))
        refuse(at == fs::path(cache_dir).lexically_normal() ? "is a file, not a folder"
                                                           : "cannot be made: '" + at.string() + "' is a file");
      if (::access(at.c_str(), W_OK) != 0)
        refuse("is not writable ('" + at.string() + "' does not let this user write)");
      return;
    }
    if (!at.has_relative_path() || at.parent_path() == at) return;  // nothing of it exists: made relative to '.'
    at = at.parent_path();
    if (at.empty()) at = ".";
  }
}

int run_reference(const ReferenceOptions& o) {
  if ((o.spp > 0) + (o.seconds > 0.0) + (o.target_relmse > 0.0) != 1)
    throw InputError("give exactly one of --spp, --seconds and --target-relmse");
  if (o.seconds < 0.0 || !std::isfinite(o.seconds)) throw InputError("--seconds must be a positive number");
  if (o.target_relmse < 0.0 || !std::isfinite(o.target_relmse))
    throw InputError("--target-relmse must be a positive number");
  if (!o.out.empty()) {
    if (image_format_for(o.out) != ImageFormat::Pfm)
      throw InputError("--out '" + o.out + "' must name a .pfm file (the variance and the sidecar go beside it)");
    check_output_path(o.out);
  }
  auto scene = std::make_shared<Scene>(load_scene_file(o.scene));
  if (o.width != 0) scene->camera.width = o.width;
  if (o.height != 0) scene->camera.height = o.height;
  if (o.max_depth != 0) scene->max_depth = o.max_depth;
  check_image_size(scene->camera.width, scene->camera.height, "--width/--height");
  scene->prepare();
  const Strategy strategy = reference_strategy(o.strategy, o.roulette_depth, *scene);
  const std::string cache_dir = reference_cache_dir(o.cache_dir);
  check_cache_dir(cache_dir);  // before the render, not after it
  const ReferenceKey key = reference_key(*scene);
  const CacheLookup before = find_cached_reference(cache_dir, key);
  if (before.status == CacheLookup::Damaged && !o.quiet)
    std::fprintf(stderr, "note: %s; it is rebuilt now\n", before.message.c_str());

  ReferenceJob job;
  job.scene = scene;
  job.scene_file = o.scene;
  job.strategy = strategy;
  job.seed_stream = o.seed_stream;
  job.goal = {o.spp, o.seconds, o.target_relmse};
  job.threads = o.threads;
  job.version = PDFLAB_VERSION;
  ReferenceBuild build(job);  // InputError: biased strategy, strategy/scene mismatch

  const bool show_progress = !o.quiet && ::isatty(STDERR_FILENO);
  for (;;) {
    const ReferenceProgress p = build.poll();
    if (show_progress) draw_progress(p, build.stats());
    if (p.reached) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(show_progress ? 200 : 50));
  }
  if (show_progress) std::fputc('\n', stderr);
  const Reference ref = build.finish();
  // --out first: should the cache fail after all (a full disk), the render is kept there.
  if (!o.out.empty()) save_reference(o.out, ref);
  const std::string cached = store_cached_reference(cache_dir, key, ref);
  std::printf("reference: %s, %dx%d, depth %d, %s, seed stream %u, %u spp, %.2f s, est. relMSE %.4g -> %s%s%s\n",
              printable(scene->name).c_str(), ref.width, ref.height, scene->max_depth, ref.info.strategy.c_str(),
              ref.info.seed_stream, ref.info.spp, ref.info.seconds, ref.info.estimated_relmse, printable(cached).c_str(),
              o.out.empty() ? "" : " and ", printable(o.out).c_str());
  return 0;
}

Reference resolve_reference(const std::string& option, const Scene& scene, const std::string& scene_file,
                            const std::string& cache_dir, bool required, bool quiet, std::string* missing) {
  if (option.empty()) return {};
  if (option != "auto") return load_reference(option);
  const CacheLookup found = find_cached_reference(reference_cache_dir(cache_dir), reference_key(scene));
  if (found.status == CacheLookup::Found) {
    if (!quiet) std::fprintf(stderr, "note: using the cached reference %s\n", printable(found.path).c_str());
    return found.reference;
  }
  std::string why = found.status == CacheLookup::Damaged
                        ? found.message
                        : "no cached reference for this scene at " + std::to_string(scene.camera.width) + "x" +
                              std::to_string(scene.camera.height) + ", depth " + std::to_string(scene.max_depth) +
                              " in '" + reference_cache_dir(cache_dir) + "'";
  why += "; make one with: " + make_command(scene, scene_file);
  if (required) throw InputError(why);
  if (missing) *missing = why;
  std::fprintf(stderr, "warning: --reference auto: %s; going on without a reference\n", printable(why).c_str());
  return {};
}

}  // namespace pdflab
