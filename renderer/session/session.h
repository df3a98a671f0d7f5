#pragma once
// Background rendering: N worker threads render progressive passes over tiles.
// A pass adds `pass_spp` samples to every pixel; tiles come from an atomic
// counter. Changing settings bumps a generation number: workers abandon tiles
// of an old generation, the last one out clears the film and starts again.
// Nobody ever waits on a worker except wait_until_done().
#include "renderer/film/film.h"
#include "renderer/integrator/integrator.h"
#include "renderer/metrics/metrics.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace pdflab {

struct RenderSettings {
  std::shared_ptr<const Scene> scene;
  Strategy strategy = Strategy::single(Technique::Cosine);
  std::uint64_t seed = 1;
  std::uint32_t target_spp = 0;  // 0: render until stopped
  // Also stop at the first pass boundary after this much rendering time (0: no
  // time limit); whichever of the two comes first ends the render.
  double target_seconds = 0.0;
  // Sample index of the film's first sample: renders of disjoint index ranges
  // of one seed (on several machines) merge into one render of their union.
  std::uint32_t first_sample = 0;
  // Path guiding's distribution, given (a strategy with `guided`): drawn from
  // as it is, no training passes. Auto weight's passes of one film keep the
  // distribution its first pass learned, so every pass draws from one that
  // was fixed before it started. Null: `guided:PASSES` trains its own.
  std::shared_ptr<const GuidingDistribution> guiding;
};

// An accumulation to continue (a saved film): `spp` samples per pixel, indices
// first_sample .. first_sample + spp - 1, with its drop counts and the
// rendering time it took. With that time the session's clock and sample count
// go on from the film's, so time, samples per second and efficiency describe
// the whole film; without it (0) they start at 0 and describe this run alone.
struct FilmStart {
  Film film;
  std::uint32_t spp = 0;
  DropCounts dropped;
  double seconds = 0.0;
};

struct SessionStats {
  std::uint64_t generation = 0;
  std::uint32_t spp = 0;           // complete passes: every pixel has this many samples
  std::uint64_t samples = 0;       // pixel samples traced in this generation
  double seconds = 0.0;            // rendering time of this generation (pauses excluded)
  double samples_per_second = 0.0;
  double progress = 0.0;           // 0..1 of target_spp or target_seconds, the nearer (0 when unlimited)
  DropCounts dropped;
  // The film's own relMSE estimate (metrics.h) after the last full pass; 0 before one.
  double estimated_relmse = 0.0;
  bool done = false;               // target_spp or target_seconds reached
  bool paused = false;
  // Path guiding (a strategy with `guided`): the training passes ended and
  // asked for, the records they took, and the distribution rendered with.
  int guiding_pass = 0, guiding_passes = 0;
  std::uint64_t guiding_records = 0;
  GuidingDistribution::Stats guiding;
};

// What copy_image published: a complete pass, or a preview after a change.
struct ImageInfo {
  int width = 0, height = 0;     // of the image
  // Of the buffer: a preview is published at its own low resolution, one value
  // per preview_scale x preview_scale block (right and bottom blocks may be cut),
  // so publishing and uploading it costs next to nothing.
  int data_width = 0, data_height = 0;
  int preview_scale = 1;
  std::uint64_t generation = 0;  // the settings generation the image shows
  std::uint32_t spp = 0;         // samples per pixel in the image (0 for a preview)
  double seconds = 0.0;          // rendering time of the generation when published
  bool preview = false;          // low-resolution first look, not part of the film
  // The film's own noise figures at this pass (metrics.h; 0 for a preview):
  // they need no reference, so a viewer can show them from the first pass on.
  double mean_relative_standard_error = 0.0;
  double estimated_relmse = 0.0;
  // A path guiding training pass (1, 2, ...; 0: none): its spp samples were
  // rendered while the distribution was still learning and are then discarded.
  int training_pass = 0;
};

// A published pass with the per-pixel layers a viewer shows beside the mean.
// For a preview only `rgb` is filled (it has no film behind it).
struct PublishedImage {
  std::vector<float> rgb;                      // data_width x data_height mean RGB
  std::vector<float> relative_standard_error;  // width x height, metrics.h's map
  std::vector<std::uint8_t> drop_mask;         // width x height, Film::drop_mask bits
  ImageInfo info;
};

struct SessionOptions {
  int threads = 0;  // <= 0: one per hardware thread
  // Workers run at a lower scheduling priority so an interactive thread in the
  // same process keeps its frame rate while every core renders.
  bool background_priority = false;
  // After each change, render one cheap reduced-resolution pass first (never
  // summed into the film) so the first image of new settings appears quickly.
  bool preview = false;
  double preview_budget_ms = 10.0;  // aimed duration of the preview pass
  // Called by a worker right after each new image is published (a viewer wakes
  // its event loop with it). Must be cheap and safe to call from any thread.
  std::function<void()> on_image;
  // False for a headless render that reads the film at the end: no image,
  // noise map or drop mask is published after each pass, so the session holds
  // the film and nothing else of the image's size; and the noise figures
  // (SessionStats::estimated_relmse) are swept only on a pass that takes the
  // film to a quarter more samples than the last swept one, as
  // many as a history of the estimate against the samples needs.
  bool publish_images = true;
};

class RenderSession {
 public:
  // threads <= 0: one per hardware thread.
  explicit RenderSession(int threads = 0);
  explicit RenderSession(const SessionOptions& options);
  ~RenderSession();
  RenderSession(const RenderSession&) = delete;
  RenderSession& operator=(const RenderSession&) = delete;

  // Starts (or restarts) rendering with these settings. Throws InputError when
  // the strategy cannot be used on the scene or the image is too large
  // (check_image_size); the running render then goes on.
  void set_settings(RenderSettings settings);
  // Like set_settings, but continues `start` instead of an empty film: its
  // size must be the camera's (InputError otherwise). target_spp counts the
  // samples already in it.
  void resume(RenderSettings settings, FilmStart start);
  RenderSettings settings() const;
  void set_paused(bool paused);
  // Changes when rendering stops (0: never) without restarting the accumulation;
  // a target below the current spp stops after the pass in flight.
  void set_target_spp(std::uint32_t target_spp);
  // The same for the time limit (0: none).
  void set_target_seconds(double target_seconds);
  // Bumped by every set_settings; compare with ImageInfo::generation.
  std::uint64_t generation() const { return generation_.load(); }

  SessionStats stats() const;
  // Path guiding's distribution as learned so far (null: the strategy has no
  // `guided`): what the render draws from once its training passes are done.
  std::shared_ptr<const GuidingDistribution> guiding() const;
  int thread_count() const { return static_cast<int>(workers_.size()); }

  // Blocks until target_spp or target_seconds is reached (true) or the timeout passes (false).
  bool wait_until_done(std::chrono::milliseconds timeout = std::chrono::milliseconds::max());

  // The latest completed pass as mean float RGB. Returns false (and leaves `out`
  // alone) when nothing newer than `version` exists; never waits for a pass.
  // (This form always delivers width x height values: a preview is enlarged.)
  bool copy_image(std::vector<float>& out, int& width, int& height, std::uint64_t& version) const;
  // The buffer as published: info.data_width x info.data_height values.
  bool copy_image(std::vector<float>& out, ImageInfo& info, std::uint64_t& version) const;
  // The buffer as published with its noise map and drop mask, all of the same
  // pass. Same contract as copy_image: false when nothing newer than `version`.
  bool copy_published(PublishedImage& out, std::uint64_t& version) const;
  // The full accumulation (sum, sum of squares, count). Only while paused or
  // done (waits for the pass in flight to end); throws std::logic_error otherwise.
  Film copy_film() const;
  // Calls `read` with the film, its spp and drop counts, without copying the
  // film; same conditions as copy_film. Rendering waits while `read` runs.
  void read_film(const std::function<void(const Film&, std::uint32_t spp, const DropCounts&)>& read) const;
  // Moves the accumulation out, as copy_film without the copy (same
  // conditions). The session renders nothing more until the next set_settings
  // or resume: a caller that keeps the film after the session is gone (a
  // Python Film) needs no second copy of it.
  Film take_film();

 private:
  struct Pass {
    std::uint64_t id = 0;
    std::uint64_t generation = 0;
    std::uint32_t first_sample = 0;
    std::uint32_t spp = 0;
    int tiles_x = 0, tiles = 0;
    bool preview = false;
    int preview_scale = 1;  // preview pixel = preview_scale x preview_scale image pixels
    int width = 0, height = 0;  // of the grid the tiles cover
    bool sweep = false;  // a full pass whose tiles are swept for the noise figures
    bool training = false;  // a path guiding training pass: recorded, then discarded
    std::uint64_t seed = 0;  // of its samples
  };

  void start_workers(int threads);
  void worker_main();
  // The next run of neighbouring tiles in one tile row (its first tile; `count`
  // of them), or a first tile past the pass's when none is left. A run is
  // longer while much of the pass is left (at most kMaxRun tiles, and at most
  // the tiles left over twice the workers) so that the workers still end a
  // pass together.
  int claim_tiles(const Pass& pass, int& count);
  // A run's samples, traced as blocks of its whole width; then each tile swept.
  void render_tiles(const Pass& pass, int first, int count, DropCounts& drops);
  void render_preview_tile(const Pass& pass, int tile, DropCounts& drops);
  void publish_locked(std::vector<float>& rgb, const Pass& pass);
  void publish_film_locked();  // the whole film as a complete pass of this generation
  int preview_scale_locked() const;
  void finish_pass_locked();
  // A training pass ends (finish_pass_locked, at `now`).
  void finish_training_locked(std::chrono::steady_clock::time_point now);
  // The ended pass's noise figures (its tiles' sweeps, where it has them)
  // and, for a viewer, its image.
  void publish_pass_locked();
  // The clock stops at `now` (paused, or the render done).
  void stop_clock_locked(std::chrono::steady_clock::time_point now);
  void change_settings(RenderSettings settings, std::optional<FilmStart> start);
  void apply_settings_locked(RenderSettings settings, const SamplingPlan& plan, std::optional<FilmStart> start);
  void wait_idle_locked(std::unique_lock<std::mutex>& lk, const char* caller) const;
  void start_pass_locked();
  double elapsed_locked() const;
  // The spp or the time limit reached, the time as of `elapsed` seconds.
  bool target_reached_locked(double elapsed) const;

  // Tiles are the unit of scheduling and of the noise sweep; runs of them the
  // unit of tracing. The packet tracer's lanes drain at the end of each block it
  // is given (the last paths run on with the other lanes idle): the book's box at
  // 600x600 passes 2 samples per pixel, so a 16x16 tile is a block of 512
  // samples, and tracing runs of 8 tiles (blocks of 4096) gave 7-9% more samples
  // a second on two threads, the same bits.
  static constexpr int kTile = 16;
  static constexpr int kMaxRun = 8;

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
  std::optional<FilmStart> pending_start_;
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
  SessionOptions options_;
  bool preview_due_ = false;          // the next pass of this generation is a preview
  double full_samples_per_second_ = 0.0;  // measured on full passes, sizes the preview
  std::vector<float> preview_;        // preview pixels, written by workers (disjoint)
  NoiseSummary noise_;                // of the last swept full pass
  std::uint32_t next_sweep_spp_ = 0;  // without published images: the film's spp that the next sweep waits for
  // Each tile's noise sums in the open full pass, written by the worker that
  // rendered the tile as soon as it has (disjoint slots), added in tile order
  // when the pass ends.
  std::vector<NoiseSums> tile_noise_;

  std::atomic<std::uint64_t> generation_{0};
  std::atomic<int> next_tile_{0};
  std::atomic<std::uint64_t> tiles_finished_{0};  // in the open pass, for progress

  Film film_;  // tiles written by workers without the lock (disjoint)

  // Path guiding (guiding.h), for a strategy with `guided`: the generation's
  // training passes (`guided:PASSES`), of 1, 2, 4, ... samples per pixel, each
  // rendered with the distribution learned so far and recorded into the
  // trainer, its image then cleared from the film: the render proper starts
  // with the distribution frozen. The passes draw from their own seed, so no
  // sample of the render shares its random numbers with one that trained it.
  // Its clock counts the training (a time limit applies from the first kept
  // pass on), and its samples count only the kept ones.
  std::unique_ptr<GuidingTrainer> trainer_;
  std::shared_ptr<const GuidingDistribution> guide_;
  int training_passes_ = 0, training_done_ = 0;

  mutable std::mutex image_mutex_;
  std::vector<float> image_;
  int image_width_ = 0, image_height_ = 0;
  std::uint64_t image_version_ = 0;
  ImageInfo image_info_;
  std::vector<float> image_rse_;            // published with image_, empty for a preview
  std::vector<std::uint8_t> image_drops_;
  // Filled during a pass (each tile's pixels by the worker that rendered it,
  // a preview's by the last worker out), then swapped with the published ones
  // under mutex_: the buffers of the pass before are reused, not allocated
  // (and faulted in) again.
  std::vector<float> spare_rgb_;
  std::vector<float> spare_rse_;
  std::vector<std::uint8_t> spare_drops_;
};

}  // namespace pdflab
