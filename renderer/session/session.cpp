#include "renderer/session/session.h"

#include "renderer/integrator/packet.h"
#include "renderer/error.h"
#include "renderer/metrics/metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <sys/resource.h>
#include <unistd.h>

namespace pdflab {

using Clock = std::chrono::steady_clock;

namespace {
// Without published images, a sweep waits for the film to grow by 1/kSweepGrowth.
constexpr std::uint32_t kSweepGrowth = 4;
// The seed of path guiding's training passes: not the render's, so that no
// sample of the render reuses the random numbers of one that trained it.
std::uint64_t training_seed(std::uint64_t seed) { return seed ^ 0x9e3779b97f4a7c15ull; }
}  // namespace

RenderSession::RenderSession(int threads) { start_workers(threads); }

RenderSession::RenderSession(const SessionOptions& options) : options_(options) { start_workers(options.threads); }

void RenderSession::start_workers(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  workers_.reserve(static_cast<std::size_t>(threads));
  for (int i = 0; i < threads; ++i) workers_.emplace_back([this] { worker_main(); });
}

RenderSession::~RenderSession() {
  {
    std::lock_guard lk(mutex_);
    quit_ = true;
    generation_.fetch_add(1);  // workers inside a pass stop at their next tile
  }
  work_cv_.notify_all();
  for (auto& t : workers_) t.join();
}

void RenderSession::set_settings(RenderSettings settings) { change_settings(std::move(settings), std::nullopt); }

void RenderSession::resume(RenderSettings settings, FilmStart start) {
  if (settings.scene && (start.film.width() != settings.scene->camera.width ||
                         start.film.height() != settings.scene->camera.height))
    throw InputError("the film to continue is " + std::to_string(start.film.width()) + "x" +
                     std::to_string(start.film.height()) + ", the camera " +
                     std::to_string(settings.scene->camera.width) + "x" + std::to_string(settings.scene->camera.height));
  change_settings(std::move(settings), std::move(start));
}

void RenderSession::change_settings(RenderSettings settings, std::optional<FilmStart> start) {
  if (!settings.scene) throw std::invalid_argument("RenderSession: settings without a scene");
  const SamplingPlan plan = SamplingPlan::make(settings.strategy, *settings.scene);  // may throw InputError
  // The film is resized by whichever thread applies the settings, possibly a
  // worker: refuse an oversized image here, where the caller can catch it.
  check_image_size(settings.scene->camera.width, settings.scene->camera.height, "camera");
  {
    std::lock_guard lk(mutex_);
    generation_.fetch_add(1);
    if (pass_open_) {
      // Workers drop their tiles; the last one out applies these settings.
      pending_ = true;
      pending_settings_ = std::move(settings);
      pending_plan_ = plan;
      pending_start_ = std::move(start);
    } else {
      apply_settings_locked(std::move(settings), plan, std::move(start));
      if (!paused_) start_pass_locked();
    }
  }
  done_cv_.notify_all();
}

RenderSettings RenderSession::settings() const {
  std::lock_guard lk(mutex_);
  return pending_ ? pending_settings_ : settings_;
}

void RenderSession::apply_settings_locked(RenderSettings settings, const SamplingPlan& plan,
                                          std::optional<FilmStart> start) {
  settings_ = std::move(settings);
  plan_ = plan;
  plan_.scene = settings_.scene.get();
  const Camera& cam = settings_.scene->camera;
  spp_done_ = 0;
  drops_ = DropCounts{};
  samples_done_ = 0;
  seconds_before_ = 0.0;
  if (start) {
    film_ = std::move(start->film);
    spp_done_ = start->spp;
    drops_ = start->dropped;
    if (start->seconds > 0.0) {
      samples_done_ = static_cast<std::uint64_t>(start->spp) * film_.pixel_count();
      seconds_before_ = start->seconds;
    }
  } else if (film_.width() != cam.width || film_.height() != cam.height) {
    film_.reset(cam.width, cam.height);
  } else {
    film_.clear();
  }
  noise_ = NoiseSummary{};
  next_sweep_spp_ = 0;
  // guided:PASSES trains anew for each generation (a resumed film too: the
  // training depends on the scene, the strategy and the seed alone, so it
  // learns the distribution the film was rendered with), unless the settings
  // give the distribution (auto weight's later passes).
  const int guided = static_cast<int>(Technique::Guided);
  training_passes_ = plan_.weight[guided] > 0.0f ? static_cast<int>(std::lround(plan_.parameter[guided])) : 0;
  training_done_ = 0;
  trainer_.reset();
  guide_.reset();
  if (training_passes_ > 0 && settings_.guiding) {
    training_passes_ = 0;  // given: drawn from as it is
    guide_ = settings_.guiding;
  } else if (training_passes_ > 0) {
    trainer_ = std::make_unique<GuidingTrainer>(*settings_.scene);
    guide_ = trainer_->distribution();
  }
  plan_.guiding = guide_.get();
  running_clock_ = false;
  next_pass_spp_ = 1;
  preview_due_ = options_.preview;
  pass_.generation = generation_.load();
  // A film continued at or past its spp target renders no pass, so no pass
  // would publish it: publish it now as this generation's image, or a viewer
  // waiting for the new generation's image (a screenshot at --spp N) waits forever.
  if (start && spp_done_ > 0 && settings_.target_spp != 0 && spp_done_ >= settings_.target_spp) publish_film_locked();
}

void RenderSession::publish_film_locked() {
  if (!options_.publish_images) return;
  spare_rse_.resize(film_.pixel_count());
  spare_rgb_.resize(3 * film_.pixel_count());
  noise_ = sweep_noise_rect(film_, 0, 0, film_.width(), film_.height(), kRelMseEpsilon, spare_rse_.data(),
                            spare_rgb_.data())
               .summary();
  spare_drops_ = film_.drop_masks();
  Pass whole;
  whole.generation = generation_.load();
  whole.preview = false;
  publish_locked(spare_rgb_, whole);
}

int RenderSession::preview_scale_locked() const {
  const Camera& cam = settings_.scene->camera;
  const double pixels = static_cast<double>(cam.width) * cam.height;
  // Nothing measured yet: guess a modest half a million samples a second per
  // worker (deep paths in the book's scene); the first full pass corrects it.
  const double rate = full_samples_per_second_ > 0.0 ? full_samples_per_second_ : 5e5 * static_cast<double>(workers_.size());
  const double budget_samples = rate * options_.preview_budget_ms * 1e-3;
  const double scale = std::ceil(std::sqrt(pixels / std::max(1.0, budget_samples)));
  return static_cast<int>(std::clamp(scale, 1.0, 16.0));
}

void RenderSession::start_pass_locked() {
  if (!settings_.scene) return;
  const std::uint32_t target = settings_.target_spp;
  if (target_reached_locked(elapsed_locked())) return;
  std::uint32_t spp = next_pass_spp_;
  if (target != 0) spp = std::min(spp, target - spp_done_);
  const Camera& cam = settings_.scene->camera;
  pass_.id += 1;
  pass_.generation = generation_.load();
  const int scale = preview_due_ ? preview_scale_locked() : 1;
  preview_due_ = false;
  pass_.preview = scale > 1;
  pass_.preview_scale = scale;
  pass_.width = (cam.width + scale - 1) / scale;
  pass_.height = (cam.height + scale - 1) / scale;
  pass_.training = !pass_.preview && training_done_ < training_passes_;
  pass_.seed = pass_.training ? training_seed(settings_.seed) : settings_.seed;
  if (pass_.preview) {
    pass_.first_sample = 0;
    pass_.spp = 1;
    preview_.assign(3 * static_cast<std::size_t>(pass_.width) * static_cast<std::size_t>(pass_.height), 0.0f);
  } else if (pass_.training) {
    pass_.first_sample = 0;
    pass_.spp = 1u << training_done_;
  } else {
    pass_.first_sample = settings_.first_sample + spp_done_;
    pass_.spp = spp;
  }
  pass_.tiles_x = (pass_.width + kTile - 1) / kTile;
  pass_.tiles = pass_.tiles_x * ((pass_.height + kTile - 1) / kTile);
  pass_.sweep = !pass_.preview && (options_.publish_images || (!pass_.training && spp_done_ + pass_.spp >= next_sweep_spp_));
  if (pass_.sweep) {
    tile_noise_.assign(static_cast<std::size_t>(pass_.tiles), NoiseSums{});
    if (options_.publish_images) {  // every pixel is written by its tile's sweep
      spare_rse_.resize(film_.pixel_count());
      spare_rgb_.resize(3 * film_.pixel_count());
    }
  }
  next_tile_.store(0);
  tiles_finished_.store(0);
  pass_open_ = true;
  pass_started_ = Clock::now();
  if (!running_clock_) {
    running_clock_ = true;
    resumed_at_ = pass_started_;
  }
  work_cv_.notify_all();
}

void RenderSession::finish_pass_locked() {
  pass_open_ = false;
  const auto now = Clock::now();
  if (pending_) {
    pending_ = false;
    apply_settings_locked(std::move(pending_settings_), pending_plan_, std::move(pending_start_));
    pending_start_.reset();
    if (!paused_) start_pass_locked();
    done_cv_.notify_all();
    return;
  }
  const double pass_ms = std::chrono::duration<double, std::milli>(now - pass_started_).count();
  if (pass_.preview) {
    spare_rgb_.assign(preview_.begin(), preview_.end());
    publish_locked(spare_rgb_, pass_);
    if (paused_) stop_clock_locked(now);
    else start_pass_locked();
    done_cv_.notify_all();
    return;
  }
  if (pass_.training) {
    finish_training_locked(now);
    done_cv_.notify_all();
    return;
  }
  spp_done_ += pass_.spp;
  const std::uint64_t pass_samples = static_cast<std::uint64_t>(pass_.spp) * film_.pixel_count();
  samples_done_ += pass_samples;
  if (pass_ms > 1.0) full_samples_per_second_ = static_cast<double>(pass_samples) / (pass_ms * 1e-3);

  // The image and its noise, swept tile by tile as the pass rendered them
  // (render_tile), so a viewer shows noise without ever touching the film.
  // Swept here at the end, the last worker out took a few ms at 600x600
  // against passes of 30-120 ms while every other worker waited (the book
  // mixture on two threads: 3.5% more samples a second without that wait;
  // the more threads, the more they waited).
  publish_pass_locked();
  if (pass_.sweep) next_sweep_spp_ = spp_done_ + std::max<std::uint32_t>(1, spp_done_ / kSweepGrowth);

  // Aim for passes of 30-120 ms: short enough to react, long enough to amortise.
  if (pass_ms < 30.0 && next_pass_spp_ < 256) next_pass_spp_ *= 2;
  if (pass_ms > 120.0 && next_pass_spp_ > 1) next_pass_spp_ /= 2;

  const bool done = target_reached_locked(seconds_before_ + std::chrono::duration<double>(now - resumed_at_).count());
  if (done || paused_) stop_clock_locked(now);
  else start_pass_locked();
  done_cv_.notify_all();
}

void RenderSession::publish_pass_locked() {
  if (pass_.sweep) {
    NoiseSums sums;
    for (const NoiseSums& tile : tile_noise_) sums.add(tile);
    noise_ = sums.summary();
  }
  if (options_.publish_images) {
    spare_drops_ = film_.drop_masks();
    publish_locked(spare_rgb_, pass_);
  }
}

void RenderSession::stop_clock_locked(std::chrono::steady_clock::time_point now) {
  seconds_before_ += std::chrono::duration<double>(now - resumed_at_).count();
  running_clock_ = false;
}

void RenderSession::finish_training_locked(std::chrono::steady_clock::time_point now) {
  // What the pass recorded becomes the next distribution, which the next
  // pass (or the render) samples with; the pass's image is shown, then cleared.
  trainer_->finish_pass();
  guide_ = trainer_->distribution();
  plan_.guiding = guide_.get();
  ++training_done_;
  publish_pass_locked();
  film_.clear();
  drops_ = DropCounts{};
  noise_ = NoiseSummary{};
  if (paused_) stop_clock_locked(now);
  else start_pass_locked();
}

void RenderSession::publish_locked(std::vector<float>& rgb, const Pass& pass) {
  ImageInfo info;
  info.width = settings_.scene->camera.width;
  info.height = settings_.scene->camera.height;
  info.generation = pass.generation;
  info.spp = pass.preview ? 0 : pass.training ? pass.spp : spp_done_;
  info.training_pass = pass.training ? training_done_ : 0;
  info.seconds = elapsed_locked();
  info.preview = pass.preview;
  info.preview_scale = pass.preview ? pass.preview_scale : 1;
  info.data_width = pass.preview ? pass.width : info.width;
  info.data_height = pass.preview ? pass.height : info.height;
  if (!pass.preview) {
    info.mean_relative_standard_error = noise_.mean_relative_standard_error;
    info.estimated_relmse = noise_.estimated_relmse;
  }
  // The UI thread only ever takes image_mutex_, never mutex_.
  {
    std::lock_guard ik(image_mutex_);
    image_.swap(rgb);
    if (pass.preview) {
      image_rse_.clear();
      image_drops_.clear();
    } else {
      image_rse_.swap(spare_rse_);
      image_drops_.swap(spare_drops_);
    }
    image_width_ = info.width;
    image_height_ = info.height;
    image_info_ = info;
    ++image_version_;
  }
  if (options_.on_image) options_.on_image();
}

void RenderSession::worker_main() {
  if (options_.background_priority) {
    // Per-thread on Linux; raising one's own nice value needs no privilege.
    // Failure only costs UI smoothness, so it is ignored.
    (void)::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
  }
  std::uint64_t seen_pass = 0;
  std::unique_lock lk(mutex_);
  for (;;) {
    work_cv_.wait(lk, [&] { return quit_ || (pass_open_ && pass_.id != seen_pass); });
    if (quit_) return;
    const Pass pass = pass_;
    seen_pass = pass.id;
    ++inside_;
    lk.unlock();

    DropCounts local;
    for (;;) {
      int count = 1;
      const int tile = pass.preview ? next_tile_.fetch_add(1, std::memory_order_relaxed) : claim_tiles(pass, count);
      if (tile >= pass.tiles) break;
      if (generation_.load(std::memory_order_relaxed) != pass.generation) break;
      if (pass.preview) render_preview_tile(pass, tile, local);
      else render_tiles(pass, tile, count, local);
      tiles_finished_.fetch_add(static_cast<std::uint64_t>(count), std::memory_order_relaxed);
    }

    lk.lock();
    // Preview samples are not part of the estimate, so their drops are not counted either.
    if (pass.generation == generation_.load() && !pass.preview) drops_ += local;
    if (--inside_ == 0 && pass_open_ && pass_.id == pass.id) finish_pass_locked();
  }
}

int RenderSession::claim_tiles(const Pass& pass, int& count) {
  const int workers = std::max(1, static_cast<int>(workers_.size()));
  int first = next_tile_.load(std::memory_order_relaxed);
  for (;;) {
    if (first >= pass.tiles) return first;
    const int row_end = (first / pass.tiles_x + 1) * pass.tiles_x;
    count = std::clamp((pass.tiles - first) / (2 * workers), 1, std::min(kMaxRun, row_end - first));
    if (next_tile_.compare_exchange_weak(first, first + count, std::memory_order_relaxed)) return first;
  }
}

void RenderSession::render_tiles(const Pass& pass, int first, int count, DropCounts& drops) {
  const Scene& scene = *settings_.scene;
  const int x0 = (first % pass.tiles_x) * kTile;
  const int y0 = (first / pass.tiles_x) * kTile;
  const int x1 = std::min(x0 + count * kTile, scene.camera.width);
  const int y1 = std::min(y0 + kTile, scene.camera.height);
  // Several paths at a time (packet.h), a few thousand samples per call into
  // a buffer on the stack (no heap in the render loop). The samples come back
  // in order and each pixel adds them in sample order, so the sums are the
  // same bits for any thread count.
  constexpr std::size_t kChunk = 4096;
  std::array<SampleResult, kChunk> results;
  const auto add = [&](const SampleBlock& block) {
    trace_block(scene, plan_, pass.seed, block, results.data(), pass.training ? trainer_.get() : nullptr);
    const SampleResult* r = results.data();
    for (int y = block.y0; y < block.y1; ++y) {
      for (int x = block.x0; x < block.x1; ++x) {
        const std::size_t pixel = static_cast<std::size_t>(y) * static_cast<std::size_t>(scene.camera.width) +
                                  static_cast<std::size_t>(x);
        std::uint8_t dropped = 0;
        for (std::uint32_t s = 0; s < block.spp; ++s, ++r) {
          film_.add(pixel, r->radiance);
          dropped |= r->drops;
          if (r->drops)
            for (int reason = 0; reason < kDropReasonCount; ++reason)
              if (r->drops & (1u << reason)) drops.add(static_cast<DropReason>(reason));
        }
        if (dropped) film_.mark_drops(pixel, dropped);
      }
    }
  };
  const std::size_t row_samples = static_cast<std::size_t>(x1 - x0) * pass.spp;
  if (row_samples <= kChunk) {  // whole rows at a time
    const int rows = static_cast<int>(kChunk / row_samples);
    for (int y = y0; y < y1; y += rows) add(SampleBlock{x0, y, x1, std::min(y + rows, y1), pass.first_sample, pass.spp});
  } else {
    for (int y = y0; y < y1; ++y)  // a pixel's samples in runs, in order
      for (int x = x0; x < x1; ++x)
        for (std::uint32_t done = 0; done < pass.spp;) {
          const auto n = static_cast<std::uint32_t>(std::min<std::size_t>(kChunk, pass.spp - done));
          add(SampleBlock{x, y, x + 1, y + 1, pass.first_sample + done, n});
          done += n;
        }
  }
  // The tiles' pixels are final for this pass: sweep them, tile by tile, for
  // the noise figures and, for a viewer, the published image and noise map.
  if (!pass.sweep) return;
  float* map = options_.publish_images ? spare_rse_.data() : nullptr;
  float* rgb = options_.publish_images ? spare_rgb_.data() : nullptr;
  for (int t = 0; t < count; ++t) {
    const int tx0 = x0 + t * kTile, tx1 = std::min(tx0 + kTile, x1);
    tile_noise_[static_cast<std::size_t>(first + t)] = sweep_noise_rect(film_, tx0, y0, tx1, y1, kRelMseEpsilon, map, rgb);
  }
}

void RenderSession::render_preview_tile(const Pass& pass, int tile, DropCounts& drops) {
  const Scene& scene = *settings_.scene;
  const int s = pass.preview_scale;
  const int x0 = (tile % pass.tiles_x) * kTile;
  const int y0 = (tile / pass.tiles_x) * kTile;
  const int x1 = std::min(x0 + kTile, pass.width);
  const int y1 = std::min(y0 + kTile, pass.height);
  for (int py = y0; py < y1; ++py) {
    for (int px = x0; px < x1; ++px) {
      // The block's centre pixel, so the preview is not shifted against the image.
      const int x = std::min(px * s + s / 2, scene.camera.width - 1);
      const int y = std::min(py * s + s / 2, scene.camera.height - 1);
      const Vec3 c = render_pixel_sample(scene, plan_, settings_.seed, x, y, 0, drops);
      float* dst = &preview_[3 * (static_cast<std::size_t>(py) * pass.width + px)];
      dst[0] = c.x;
      dst[1] = c.y;
      dst[2] = c.z;
    }
  }
}

void RenderSession::set_target_spp(std::uint32_t target_spp) {
  {
    std::lock_guard lk(mutex_);
    if (pending_) pending_settings_.target_spp = target_spp;
    settings_.target_spp = target_spp;
    if (!paused_ && !pass_open_ && !pending_) start_pass_locked();
  }
  done_cv_.notify_all();
}

void RenderSession::set_target_seconds(double target_seconds) {
  {
    std::lock_guard lk(mutex_);
    const double t = std::isfinite(target_seconds) ? std::max(0.0, target_seconds) : 0.0;
    if (pending_) pending_settings_.target_seconds = t;
    settings_.target_seconds = t;
    if (!paused_ && !pass_open_ && !pending_) start_pass_locked();
  }
  done_cv_.notify_all();
}

void RenderSession::set_paused(bool paused) {
  {
    std::lock_guard lk(mutex_);
    if (paused_ == paused) return;
    paused_ = paused;
    if (!paused_ && !pass_open_) start_pass_locked();
  }
  done_cv_.notify_all();
}

bool RenderSession::target_reached_locked(double elapsed) const {
  const std::uint32_t spp = settings_.target_spp;
  const double seconds = settings_.target_seconds;
  return (spp != 0 && spp_done_ >= spp) || (seconds > 0.0 && spp_done_ > 0 && elapsed >= seconds);
}

double RenderSession::elapsed_locked() const {
  double s = seconds_before_;
  if (running_clock_) s += std::chrono::duration<double>(Clock::now() - resumed_at_).count();
  return s;
}

std::shared_ptr<const GuidingDistribution> RenderSession::guiding() const {
  std::lock_guard lk(mutex_);
  return pending_ ? nullptr : guide_;
}

SessionStats RenderSession::stats() const {
  std::lock_guard lk(mutex_);
  SessionStats st;
  st.generation = generation_.load();
  st.paused = paused_;
  // New settings wait for the workers to leave the old pass; until then the
  // counters below still describe the old render. The new one has nothing yet.
  if (pending_) return st;
  st.spp = spp_done_;
  st.seconds = elapsed_locked();
  std::uint64_t partial = 0;
  double pass_fraction = 0.0;
  if (pass_open_ && !pass_.preview && pass_.tiles > 0 && pass_.generation == generation_.load()) {
    pass_fraction = static_cast<double>(tiles_finished_.load()) / pass_.tiles;
    partial = static_cast<std::uint64_t>(pass_fraction * pass_.spp * static_cast<double>(film_.pixel_count()));
  }
  st.samples = samples_done_ + partial;
  st.samples_per_second = st.seconds > 0.0 ? static_cast<double>(st.samples) / st.seconds : 0.0;
  const std::uint32_t target = settings_.target_spp;
  // A lowered spp target counts at once (the pass in flight still ends); the time limit once the pass has.
  st.done = (target != 0 && spp_done_ >= target) || (!pass_open_ && target_reached_locked(st.seconds));
  if (target != 0) st.progress = std::min(1.0, (spp_done_ + pass_fraction * pass_.spp) / target);
  if (settings_.target_seconds > 0.0) st.progress = std::max(st.progress, std::min(1.0, st.seconds / settings_.target_seconds));
  st.dropped = drops_;
  st.estimated_relmse = noise_.estimated_relmse;
  st.guiding_passes = training_passes_;
  st.guiding_pass = training_done_;
  if (trainer_) st.guiding_records = trainer_->records();
  if (guide_) st.guiding = guide_->stats();
  return st;
}

bool RenderSession::wait_until_done(std::chrono::milliseconds timeout) {
  std::unique_lock lk(mutex_);
  auto done = [&] {
    return !pending_ && !pass_open_ && target_reached_locked(elapsed_locked());
  };
  if (timeout == std::chrono::milliseconds::max()) {
    done_cv_.wait(lk, done);
    return true;
  }
  return done_cv_.wait_for(lk, timeout, done);
}

bool RenderSession::copy_image(std::vector<float>& out, int& width, int& height, std::uint64_t& version) const {
  std::lock_guard ik(image_mutex_);
  if (image_version_ == version || image_.empty()) return false;
  width = image_width_;
  height = image_height_;
  version = image_version_;
  const ImageInfo& info = image_info_;
  if (!info.preview) {
    out = image_;
    return true;
  }
  const int s = info.preview_scale;
  out.resize(3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float* src = &image_[3 * (static_cast<std::size_t>(y / s) * info.data_width + x / s)];
      float* dst = &out[3 * (static_cast<std::size_t>(y) * width + x)];
      dst[0] = src[0];
      dst[1] = src[1];
      dst[2] = src[2];
    }
  return true;
}

bool RenderSession::copy_image(std::vector<float>& out, ImageInfo& info, std::uint64_t& version) const {
  std::lock_guard ik(image_mutex_);
  if (image_version_ == version || image_.empty()) return false;
  out = image_;
  info = image_info_;
  version = image_version_;
  return true;
}

bool RenderSession::copy_published(PublishedImage& out, std::uint64_t& version) const {
  std::lock_guard ik(image_mutex_);
  if (image_version_ == version || image_.empty()) return false;
  out.rgb = image_;
  out.relative_standard_error = image_rse_;
  out.drop_mask = image_drops_;
  out.info = image_info_;
  version = image_version_;
  return true;
}

void RenderSession::wait_idle_locked(std::unique_lock<std::mutex>& lk, const char* caller) const {
  // The film is only consistent between passes: wait for the open one to end.
  const bool done = settings_.target_spp != 0 && spp_done_ >= settings_.target_spp;
  if (!paused_ && !done) throw std::logic_error(std::string("RenderSession::") + caller + " while rendering");
  done_cv_.wait(lk, [&] { return !pass_open_; });
}

Film RenderSession::copy_film() const {
  std::unique_lock lk(mutex_);
  wait_idle_locked(lk, "copy_film");
  return film_;
}

Film RenderSession::take_film() {
  std::unique_lock lk(mutex_);
  wait_idle_locked(lk, "take_film");
  Film taken = std::move(film_);
  film_ = Film();
  settings_.scene.reset();  // no pass starts without a scene; new settings bring one and size the film
  return taken;
}

void RenderSession::read_film(
    const std::function<void(const Film&, std::uint32_t spp, const DropCounts&)>& read) const {
  std::unique_lock lk(mutex_);
  wait_idle_locked(lk, "read_film");
  read(film_, spp_done_, drops_);
}

}  // namespace pdflab
