#pragma once
// The viewer's references: the cached one of the scene on screen loaded
// automatically, "Make reference" rendered in the background, and the seed
// kept apart from the reference's. The viewer calls these few hooks; the
// panel reads ui::MeasureState.
#include "renderer/session/reference_build.h"
#include "ui/measure.h"

#include <cstdint>
#include <future>
#include <memory>
#include <optional>
#include <string>

namespace pdflab {

class ViewerReferences {
 public:
  // cache_dir: empty for reference_cache_dir() (option, env, XDG).
  explicit ViewerReferences(std::string cache_dir = {});
  ~ViewerReferences();
  ViewerReferences(const ViewerReferences&) = delete;
  ViewerReferences& operator=(const ViewerReferences&) = delete;

  // The render's scene (size and depth applied) after every settings change:
  // when its key changed, looks in the cache. A match replaces a reference that
  // came from the cache (or none); one loaded by hand stays. Returns true when
  // the reference changed.
  bool follow_scene(const Scene& render_scene, ui::MeasureState& m);
  // Starts a build of `render_scene` at 1/divisor of its size, to the target
  // `s` names (a share of the figures now shown, or an spp) within its time
  // limit. Replaces nothing until it is done; a second start while one runs is
  // ignored.
  void start(const Scene& render_scene, const std::string& scene_file, const ui::MeasureSettings& s,
             ui::MeasureState& m);
  void cancel(ui::MeasureState& m);
  // Once a frame: progress into m.build; when done, stores the reference in the
  // cache (off the UI thread) and then loads it. Returns true when it loaded one.
  bool service(ui::MeasureState& m);
  bool running() const { return build_ != nullptr || storing_.valid(); }
  // Taking every thread: the main render rests meanwhile.
  bool wants_main_paused() const { return running() && all_threads_; }
  const std::string& cache_dir() const { return cache_dir_; }

 private:
  struct Stored {
    Reference reference;
    std::string path, error;
    bool capped = false;  // short of its target: not cached
  };
  std::string cache_dir_;
  std::string looked_up_;  // the key's stem last looked up
  std::unique_ptr<ReferenceBuild> build_;
  ReferenceKey build_key_;
  bool all_threads_ = false;
  std::future<Stored> storing_;
};

// A seed for the render that shares no random numbers with `reference`, or
// nothing when `seed` already does not; `note` says what changed and why.
std::optional<std::uint64_t> decorrelated_seed(const Reference& reference, std::uint64_t seed,
                                               const Strategy& strategy, std::string& note);

}  // namespace pdflab
