#pragma once
// Background rendering: N worker threads render progressive passes over tiles.
// A pass adds `pass_spp` samples to every pixel; tiles come from an atomic
// counter. Changing settings bumps a generation number: workers abandon tiles
// of an old generation, the last one out clears the film and starts again.
// Nobody ever waits on a worker except wait_until_done().
#include "renderer/film/film.h"
#include "renderer/integrator/integrator.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace pdflab {

struct RenderSettings {
  std::shared_ptr<const Scene> scene;
  Strategy strategy = Strategy::single(Technique::Cosine);
  std::uint64_t seed = 1;
  std::uint32_t target_spp = 0;  // 0: render until stopped
};

struct SessionStats {
  std::uint64_t generation = 0;
  std::uint32_t spp = 0;           // complete passes: every pixel has this many samples
  std::uint64_t samples = 0;       // pixel samples traced in this generation
  double seconds = 0.0;            // rendering time of this generation (pauses excluded)
  double samples_per_second = 0.0;
  double progress = 0.0;           // 0..1 of target_spp (0 when unlimited)
  DropCounts dropped;
  bool done = false;               // target_spp reached
  bool paused = false;
};

class RenderSession {
 public:
  // threads <= 0: one per hardware thread.
  explicit RenderSession(int threads = 0);
  ~RenderSession();
  RenderSession(const RenderSession&) = delete;
  RenderSession& operator=(const RenderSession&) = delete;

  // Starts (or restarts) rendering with these settings. Throws InputError when
  // the strategy cannot be used on the scene or the image is too large
  // (check_image_size); the running render then goes on.
  void set_settings(RenderSettings settings);
  RenderSettings settings() const;
  void set_paused(bool paused);

  SessionStats stats() const;
  int thread_count() const { return static_cast<int>(workers_.size()); }

  // Blocks until target_spp is reached (true) or the timeout passes (false).
  bool wait_until_done(std::chrono::milliseconds timeout = std::chrono::milliseconds::max());

  // The latest completed pass as mean float RGB. Returns false (and leaves `out`
  // alone) when nothing newer than `version` exists; never waits for a pass.
  bool copy_image(std::vector<float>& out, int& width, int& height, std::uint64_t& version) const;
  // The full accumulation (sum, sum of squares, count). Only while paused or
  // done (waits for the pass in flight to end); throws std::logic_error otherwise.
  Film copy_film() const;

 private:
  struct Pass {
    std::uint64_t id = 0;
    std::uint64_t generation = 0;
    std::uint32_t first_sample = 0;
    std::uint32_t spp = 0;
    int tiles_x = 0, tiles = 0;
  };

  void worker_main();
  void render_tile(const Pass& pass, int tile, DropCounts& drops);
  void finish_pass_locked();
  void apply_settings_locked(RenderSettings settings, const SamplingPlan& plan);
  void start_pass_locked();
  double elapsed_locked() const;

  static constexpr int kTile = 16;

  mutable std::mutex mutex_;
  std::condition_variable work_cv_;
  mutable std::condition_variable done_cv_;
  std::vector<std::thread> workers_;

  // Guarded by mutex_.
  bool quit_ = false;
  bool paused_ = false;
  bool pass_open_ = false;
  bool pending_ = false;
  RenderSettings settings_, pending_settings_;
  SamplingPlan plan_, pending_plan_;
  Pass pass_;
  int inside_ = 0;  // workers working on the open pass
  std::uint32_t spp_done_ = 0;
  std::uint64_t samples_done_ = 0;
  DropCounts drops_;
  double seconds_before_ = 0.0;  // time accumulated before the last resume
  std::chrono::steady_clock::time_point resumed_at_;
  bool running_clock_ = false;
  std::uint32_t next_pass_spp_ = 1;
  std::chrono::steady_clock::time_point pass_started_;

  std::atomic<std::uint64_t> generation_{0};
  std::atomic<int> next_tile_{0};
  std::atomic<std::uint64_t> tiles_finished_{0};  // in the open pass, for progress

  Film film_;  // tiles written by workers without the lock (disjoint)

  mutable std::mutex image_mutex_;
  std::vector<float> image_;
  int image_width_ = 0, image_height_ = 0;
  std::uint64_t image_version_ = 0;
};

}  // namespace pdflab
