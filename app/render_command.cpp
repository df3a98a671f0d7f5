#include "app/render_command.h"

#include "app/reference_command.h"
#include "renderer/error.h"
#include "renderer/film/film.h"
#include "renderer/film/film_file.h"
#include "renderer/film/image_io.h"
#include "renderer/input_file.h"
#include "renderer/integrator/packet.h"
#include "renderer/metrics/metrics.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include <nlohmann/json.hpp>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <thread>

namespace pdflab {

namespace {

constexpr int kInterrupted = 130;  // the shell's status for a run stopped by Ctrl-C

volatile std::sig_atomic_t g_stop_signal = 0;

void on_stop_signal(int sig) { g_stop_signal = sig; }

// SIGINT and SIGTERM stop the render between passes (the film is saved when
// there is one to save); the previous handlers come back on destruction.
class StopSignals {
 public:
  StopSignals() {
    g_stop_signal = 0;
    struct sigaction sa{};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    ::sigaction(SIGINT, &sa, &old_int_);
    ::sigaction(SIGTERM, &sa, &old_term_);
  }
  ~StopSignals() {
    ::sigaction(SIGINT, &old_int_, nullptr);
    ::sigaction(SIGTERM, &old_term_, nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  bool stopped() const { return g_stop_signal != 0; }

 private:
  struct sigaction old_int_{}, old_term_{};
};

void draw_progress(const SessionStats& st, std::uint32_t target) {
  constexpr int kWidth = 32;
  const int filled = static_cast<int>(st.progress * kWidth);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '.');
  const double remaining = st.progress > 0.0 ? st.seconds * (1.0 - st.progress) / st.progress : 0.0;
  std::fprintf(stderr, "\r[%s] %3d%%  %u/%u spp  %.1f s  %.2f M samples/s  ~%.0f s left ", bar.c_str(),
               static_cast<int>(st.progress * 100.0), st.spp, target, st.seconds, st.samples_per_second * 1e-6,
               remaining);
  std::fflush(stderr);
}

Transfer parse_transfer(const std::string& text) {
  if (text == "gamma2") return Transfer::Gamma2;
  if (text == "srgb") return Transfer::Srgb;
  throw InputError("--transfer must be 'gamma2' or 'srgb', not '" + text + "'");
}

void write_text(const std::string& path, const std::string& text) {
  write_file_atomic(path, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
}

std::string hex_hash(std::uint64_t hash) {
  char text[24];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

// What an EXR's header says about the estimate in it.
std::vector<std::pair<std::string, std::string>> image_attributes(const FilmInfo& info) {
  return film_image_attributes(info, PDFLAB_VERSION);
}

// The same for a PFM, which has no room for it, in its sidecar (NAME.json
// beside NAME.pfm, where load_reference looks): a PFM kept as a reference
// still names its seeds.
nlohmann::json identity_json(const FilmInfo& info) {
  nlohmann::json j;
  j["format"] = "pdflab-render";
  j["scene_file"] = info.scene_file;
  j["scene_hash"] = hex_hash(info.scene_hash);
  j["strategy"] = info.strategy;
  j["width"] = info.width;
  j["height"] = info.height;
  j["max_depth"] = info.max_depth;
  const std::vector<std::uint64_t> seeds = info.seeds();
  if (!seeds.empty()) j["seed"] = seeds.front();
  j["seeds"] = seeds;
  j["sample_ranges"] = info.ranges_text();
  j["spp"] = info.spp();
  j["seconds"] = info.seconds;
  j["version"] = PDFLAB_VERSION;
  return j;
}

// The sidecar a PFM output gets (empty for other formats).
std::string sidecar_of(const std::string& image) {
  if (image.empty() || image_format_for(image) != ImageFormat::Pfm) return {};
  return reference_paths(image).sidecar;
}

bool same_file(const std::string& a, const std::string& b) {
  if (a.empty() || b.empty()) return false;
  std::error_code ec;
  if (std::filesystem::equivalent(a, b, ec)) return true;
  return std::filesystem::weakly_canonical(std::filesystem::absolute(a), ec) ==
         std::filesystem::weakly_canonical(std::filesystem::absolute(b), ec);
}

// A sidecar may replace an earlier one (pdflab's: it names a strategy), never
// another file that happens to share the image's name: the scene itself
// (cornell.json beside cornell.pfm) or anything else.
void check_sidecar(const std::string& sidecar, const std::string& image, const std::string& scene) {
  if (sidecar.empty()) return;
  check_output_path(sidecar);
  if (same_file(sidecar, scene))
    throw InputError("output '" + image + "': its sidecar '" + sidecar +
                     "' (what identifies the image) would replace the scene file; choose another name");
  std::error_code ec;
  if (!std::filesystem::exists(sidecar, ec)) return;
  bool ours = false;
  try {
    const nlohmann::json j = nlohmann::json::parse(read_input_file(sidecar, "sidecar", 1 << 20));
    ours = j.is_object() && j.contains("strategy");
  } catch (const std::exception&) {
    ours = false;
  }
  if (!ours)
    throw InputError("output '" + image + "': its sidecar '" + sidecar +
                     "' would replace a file that is not a pdflab sidecar; choose another name");
}

// The image with what identifies it: attributes in an EXR, a sidecar beside a
// PFM (unless the stats JSON is that very file, which then carries it).
void write_identified_image(const std::string& path, const Film& film, Transfer transfer, const FilmInfo& info,
                            const std::string& stats_json) {
  write_film_image(path, film, transfer, image_attributes(info));
  if (const std::string sidecar = sidecar_of(path); !sidecar.empty() && !same_file(sidecar, stats_json))
    write_text(sidecar, identity_json(info).dump(2) + "\n");
}

nlohmann::json drops_json(const DropCounts& dropped) {
  nlohmann::json j = {{"total", dropped.total()}};
  for (int r = 0; r < kDropReasonCount; ++r)
    j[std::string(drop_reason_name(static_cast<DropReason>(r)))] = dropped.by_reason[static_cast<std::size_t>(r)];
  return j;
}

std::string drops_text(const DropCounts& dropped) {
  const auto& d = dropped.by_reason;
  char text[160];
  std::snprintf(text, sizeof text, "%llu samples dropped (pdf_zero %llu, pdf_not_finite %llu, radiance_not_finite %llu)",
                static_cast<unsigned long long>(dropped.total()), static_cast<unsigned long long>(d[0]),
                static_cast<unsigned long long>(d[1]), static_cast<unsigned long long>(d[2]));
  return text;
}

// The film to continue, checked against what the command line asks for.
struct Resumed {
  FilmFile file;
  std::string scene, strategy;
};

Resumed open_resume(const RenderOptions& o) {
  Resumed r{read_film_file(o.resume), o.scene_given ? o.scene : "", o.strategy_given ? o.strategy : ""};
  const FilmInfo& info = r.file.info;
  const std::string film = "film '" + o.resume + "'";
  if (info.ranges.size() != 1)
    throw InputError("--resume: " + film + " is a merge of " + std::to_string(info.ranges.size()) +
                     " renders (" + info.ranges_text() + "); only one render's film can be continued");
  const SampleRange& range = info.ranges.front();
  if (!o.scene_given) r.scene = info.scene_file;
  if (!o.strategy_given) r.strategy = info.strategy;
  (void)Strategy::parse(r.strategy);  // bad input before anything is read further; compared with the scene below
  if (o.seed_given && o.seed != range.seed)
    throw InputError("--resume: " + film + " was rendered with seed " + std::to_string(range.seed) + ", not " +
                     std::to_string(o.seed));
  if (o.first_sample_given && o.first_sample != range.first)
    throw InputError("--resume: " + film + " starts at sample " + std::to_string(range.first) + ", not " +
                     std::to_string(o.first_sample));
  if (info.spp() > o.spp)
    throw InputError("--resume: " + film + " holds " + std::to_string(info.spp()) + " samples per pixel, more than --spp " +
                     std::to_string(o.spp) + " asks for in all");
  if ((o.width != 0 && o.width != info.width) || (o.height != 0 && o.height != info.height))
    throw InputError("--resume: " + film + " is " + std::to_string(info.width) + "x" + std::to_string(info.height) +
                     ", not the size asked for");
  return r;
}

// Everything the user typed is checked before any file is read.
void check_render_options(const RenderOptions& o) {
  if (o.resume.empty() && !o.scene_given) throw InputError("--scene is required (unless --resume names a film)");
  if (o.resume.empty() && !o.strategy_given) throw InputError("--strategy is required (unless --resume names a film)");
  if (!o.spp_given) throw InputError("--spp is required");
  if (o.spp == 0) throw InputError("--spp must be at least 1");
  if (!o.out_given && o.film_out.empty() && o.resume.empty())
    throw InputError("nothing to write: give --out IMAGE, --film-out FILM or both");
  if (o.out_given) {
    (void)image_format_for(o.out);
    check_output_path(o.out);
  }
  const std::string film_out = o.film_out.empty() ? o.resume : o.film_out;
  if (!film_out.empty()) check_output_path(film_out);
  if (!o.stats_json.empty()) check_output_path(o.stats_json);
  const std::string sidecar = o.out_given ? sidecar_of(o.out) : std::string();
  check_distinct_outputs({o.out, film_out, o.stats_json, same_file(sidecar, o.stats_json) ? "" : sidecar});
  (void)parse_transfer(o.transfer);
  if (o.threads < 0 || o.threads > 1024) throw InputError("--threads must be in 0..1024 (0: all cores)");
  if (!(o.checkpoint_seconds >= 0.0) || !std::isfinite(o.checkpoint_seconds))
    throw InputError("--checkpoint-seconds must be a number >= 0");
}

// What is rendered: the scene at its size, the strategy, the samples (seed and
// first index) and the film it continues, if any; and where the film goes.
struct RenderPlan {
  std::optional<Resumed> resumed;
  std::string scene_path;
  std::shared_ptr<Scene> scene;
  Strategy strategy;
  FilmInfo info;  // the film's description, without its ranges, drops and time
  std::uint64_t seed = 0;
  std::uint32_t first_sample = 0;
  std::string film_out;  // empty: no film is written
  Transfer transfer = Transfer::Gamma2;
  std::string reference_missing;  // --reference auto found nothing: why
};

RenderPlan plan_render(const RenderOptions& o) {
  RenderPlan plan;
  plan.transfer = parse_transfer(o.transfer);
  plan.film_out = o.film_out.empty() ? o.resume : o.film_out;
  if (!o.resume.empty()) plan.resumed = open_resume(o);
  const std::optional<Resumed>& resumed = plan.resumed;
  plan.scene_path = resumed ? resumed->scene : o.scene;
  const std::string strategy_text = resumed ? resumed->strategy : o.strategy;

  plan.scene = std::make_shared<Scene>(load_scene_file(plan.scene_path));
  Scene& scene = *plan.scene;
  const int width = resumed ? resumed->file.info.width : o.width;
  const int height = resumed ? resumed->file.info.height : o.height;
  if (width != 0) scene.camera.width = width;
  if (height != 0) scene.camera.height = height;
  if (width != 0 || height != 0) check_image_size(scene.camera.width, scene.camera.height, "--width/--height");
  scene.prepare();
  plan.strategy = for_scene(with_roulette(Strategy::parse(strategy_text), o.roulette_depth), scene);
  if (resumed && (o.strategy_given || o.roulette_depth > 0) &&
      plan.strategy.to_string() != resumed->file.info.strategy)
    throw InputError("--resume: film '" + o.resume + "' was rendered with strategy '" + resumed->file.info.strategy +
                     "', not '" + plan.strategy.to_string() + "'");
  (void)SamplingPlan::make(plan.strategy, scene);  // strategy/scene mismatch is bad input too

  FilmInfo& info = plan.info;
  info.scene_hash = film_scene_hash(scene);
  info.scene_file = plan.scene_path;
  info.width = scene.camera.width;
  info.height = scene.camera.height;
  info.max_depth = scene.max_depth;
  info.strategy = plan.strategy.to_string();
  plan.seed = resumed ? resumed->file.info.ranges.front().seed : o.seed;
  plan.first_sample = resumed ? resumed->file.info.ranges.front().first : o.first_sample;
  if (std::uint64_t{plan.first_sample} + o.spp > std::numeric_limits<std::uint32_t>::max())
    throw InputError("--first-sample " + std::to_string(plan.first_sample) + " plus --spp " + std::to_string(o.spp) +
                     " passes the last sample index (" + std::to_string(std::numeric_limits<std::uint32_t>::max()) + ")");
  if (resumed) {
    const FilmInfo& had = resumed->file.info;
    if (had.scene_hash != info.scene_hash || had.max_depth != info.max_depth)
      throw InputError("--resume: film '" + o.resume + "' was rendered from another scene than '" + plan.scene_path +
                       "' (its content or maximum depth differs)");
  }
  return plan;
}

// The reference is checked before any rendering: its size, and that the
// render would not repeat its random numbers.
Reference checked_reference(const RenderOptions& o, RenderPlan& plan) {
  const Scene& scene = *plan.scene;
  const Reference reference =
      resolve_reference(o.reference, scene, plan.scene_path, o.cache_dir, false, o.quiet, &plan.reference_missing);
  if (!reference.loaded()) return reference;
  if (reference.width != scene.camera.width || reference.height != scene.camera.height)
    throw InputError("reference '" + reference.path + "' is " + std::to_string(reference.width) + "x" +
                     std::to_string(reference.height) + " but the render is " + std::to_string(scene.camera.width) +
                     "x" + std::to_string(scene.camera.height) + " (use --width/--height)");
  if (const std::string shared = shared_random_numbers(reference.info, plan.seed, plan.strategy); !shared.empty())
    throw InputError("reference '" + reference.path + "': " + shared + "; choose another --seed");
  if (!o.quiet) note_unknown_seed(reference, {plan.seed});
  return reference;
}

void note_bias(const Strategy& strategy, bool quiet) {
  if (!strategy.is_unbiased() && !quiet)
    std::fprintf(stderr, "note: strategy '%s' is biased: %s, so its pdf is zero where light may arrive\n",
                 strategy.to_string().c_str(), strategy.bias_reason().c_str());
}

// The film's own estimate is noted at fixed sample counts, the powers of two
// on the way and the end, where the session stops for a moment (one short
// pass at most for each): the same samples give the same history, and so the
// same verdict on the estimate, however the passes fell in time. (Noted
// whenever a poll came by, the verdict of four identical renders differed.)
std::uint32_t next_estimate_spp(std::uint32_t spp, std::uint32_t target) {
  std::uint64_t n = 2;
  while (n <= spp && n < target) n *= 2;
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(n, target));
}

// A render session on the plan's film, saving it as a film file on request
// (checkpoints, an interruption, the end).
class FilmRender {
 public:
  // A resumed film is moved out of the plan into the session.
  FilmRender(const RenderOptions& o, RenderPlan& plan) : plan_(plan), session_(session_options(o)) {
    RenderSettings settings;
    settings.scene = plan.scene;
    settings.strategy = plan.strategy;
    settings.seed = plan.seed;
    settings.first_sample = plan.first_sample;
    const std::uint32_t had = plan.resumed ? static_cast<std::uint32_t>(plan.resumed->file.info.spp()) : 0;
    settings.target_spp = next_estimate_spp(had, o.spp);
    if (plan.resumed) {
      // The film's own seconds start the session's clock, so the summary's
      // time, speed and efficiency describe the whole film, as its spp and
      // error do (the time of this run alone overstated the efficiency).
      FilmFile& file = plan.resumed->file;
      const auto had_spp = static_cast<std::uint32_t>(file.info.spp());
      const DropCounts had_drops = file.info.dropped;
      session_.resume(settings, FilmStart{std::move(file.film), had_spp, had_drops, file.info.seconds});
    } else {
      session_.set_settings(settings);
    }
  }

  RenderSession& session() { return session_; }

  // The film as it stands between two passes, with what it holds.
  FilmInfo info_now(std::uint32_t spp, const DropCounts& dropped, double seconds) const {
    FilmInfo now = plan_.info;
    now.ranges = {SampleRange{plan_.seed, plan_.first_sample, plan_.first_sample + spp}};
    now.dropped = dropped;
    now.seconds = seconds;
    return now;
  }
  FilmInfo save_film(const Film& film, std::uint32_t spp, const DropCounts& dropped, double seconds) const {
    const FilmInfo now = info_now(spp, dropped, seconds);
    write_film_file(plan_.film_out, now, film);
    return now;
  }
  // Pauses and saves the film; returns the spp saved (0: nothing yet).
  std::uint32_t checkpoint() {
    session_.set_paused(true);
    const double seconds = session_.stats().seconds;
    std::uint32_t saved = 0;
    session_.read_film([&](const Film& film, std::uint32_t spp, const DropCounts& dropped) {
      if (spp > 0) save_film(film, spp, dropped, seconds);
      saved = spp;
    });
    return saved;
  }

 private:
  static SessionOptions session_options(const RenderOptions& o) {
    SessionOptions options;
    options.threads = o.threads;
    options.publish_images = false;  // the film is read once, at the end
    return options;
  }
  const RenderPlan& plan_;
  RenderSession session_;
};

// Waits for the session, drawing progress, saving checkpoints and stopping on
// SIGINT or SIGTERM. Returns kInterrupted when stopped, 0 when done; the
// history receives the film's own estimates along the way.
int wait_for_render(const RenderOptions& o, const RenderPlan& plan, FilmRender& render, EstimateHistory& history) {
  RenderSession& session = render.session();
  const StopSignals signals;
  const bool show_progress = !o.quiet && ::isatty(STDERR_FILENO);
  using Clock = std::chrono::steady_clock;
  auto last_checkpoint = Clock::now();
  const bool checkpoints = !plan.film_out.empty() && o.checkpoint_seconds > 0.0;
  std::uint32_t target = session.settings().target_spp;
  // The progress of the whole render, not of the stretch to the next estimate.
  const auto progress = [&] {
    SessionStats st = session.stats();
    st.progress = std::min(1.0, st.progress * target / o.spp);
    return st;
  };
  for (;;) {
    if (session.wait_until_done(std::chrono::milliseconds(show_progress ? 200 : 100))) {
      std::uint32_t spp = 0;
      double estimate = 0.0;
      session.read_film([&](const Film& film, std::uint32_t now, const DropCounts&) {
        spp = now;
        estimate = estimated_relmse(film);
      });
      history.add(spp, estimate);
      if (spp >= o.spp) break;
      target = next_estimate_spp(spp, o.spp);
      session.set_target_spp(target);
      continue;
    }
    if (signals.stopped()) {
      if (show_progress) std::fputc('\n', stderr);
      if (plan.film_out.empty()) {
        std::fprintf(stderr, "pdflab: interrupted; nothing written\n");
        return kInterrupted;
      }
      const std::uint32_t saved = render.checkpoint();
      std::fprintf(stderr, "pdflab: interrupted at %u of %u spp; the film '%s' holds them: continue with "
                   "'pdflab render --resume %s --spp %u'\n", saved, o.spp, printable(plan.film_out).c_str(),
                   printable(plan.film_out).c_str(), o.spp);
      return kInterrupted;
    }
    if (checkpoints &&
        std::chrono::duration<double>(Clock::now() - last_checkpoint).count() >= o.checkpoint_seconds) {
      render.checkpoint();
      session.set_paused(false);
      last_checkpoint = Clock::now();
    }
    if (show_progress) draw_progress(progress(), o.spp);
  }
  if (show_progress) {
    draw_progress(progress(), o.spp);
    std::fputc('\n', stderr);
  }
  return 0;
}

// What the finished render gives: the film's description as saved, its own
// estimate and the error against the reference.
struct RenderResult {
  SessionStats stats;
  FilmInfo info;
  double estimate = 0.0;
  RelMseMeasure error;
  int threads = 0;
};

RenderResult finish_render(const RenderOptions& o, const RenderPlan& plan, FilmRender& render,
                           const Reference& reference) {
  RenderResult r;
  r.stats = render.session().stats();
  r.threads = render.session().thread_count();
  r.info = plan.info;
  render.session().read_film([&](const Film& film, std::uint32_t spp, const DropCounts& dropped) {
    r.info = plan.film_out.empty() ? render.info_now(spp, dropped, r.stats.seconds)
                                   : render.save_film(film, spp, dropped, r.stats.seconds);
    if (o.out_given) write_identified_image(o.out, film, plan.transfer, r.info, o.stats_json);
    r.estimate = estimated_relmse(film);
    if (reference.loaded()) r.error = measure_relmse(film.mean_rgb(), reference.rgb, reference.variance);
  });
  return r;
}

void write_render_stats(const RenderOptions& o, const RenderPlan& plan, const RenderResult& r,
                        const Reference& reference, const EstimateHistory& history) {
  const bool unreliable = history.unreliable();
  const Strategy& strategy = plan.strategy;
  const SessionStats& st = r.stats;
  nlohmann::json j = identity_json(r.info);  // so that it can be an image's sidecar too
  j["scene"] = plan.scene->name;
  j["scene_file"] = plan.scene_path;
  j["strategy"] = strategy.to_string();
  j["unbiased"] = strategy.is_unbiased();
  j["russian_roulette_depth"] = strategy.roulette_depth;  // 0: off
  j["sampler"] = strategy.sobol ? "sobol" : "independent";  // +sobol
  if (strategy.fastest) j["expanded_from"] = "fastest";
  j["width"] = r.info.width;
  j["height"] = r.info.height;
  j["spp"] = r.info.spp();
  j["seed"] = plan.seed;
  j["first_sample"] = plan.first_sample;
  j["threads"] = r.threads;
  // What the speed figures came from (the images are the same bits with any).
  j["tracer"] = std::string(packet_isa_name(best_packet_isa()));
  j["tracer_lanes"] = packet_lanes(best_packet_isa());
  j["seconds"] = st.seconds;
  j["samples"] = st.samples;
  j["samples_per_second"] = st.samples_per_second;
  j["dropped"] = drops_json(r.info.dropped);
  if (st.guiding_passes > 0)
    j["guiding"] = {{"training_passes", st.guiding_passes}, {"records", st.guiding_records},
                    {"leaves", st.guiding.leaves}, {"nodes", st.guiding.nodes},
                    {"max_depth", st.guiding.max_depth}, {"bytes", st.guiding.bytes}};
  j["output"] = o.out;
  if (!plan.film_out.empty()) j["film"] = plan.film_out;
  // The film's own estimate is a lower bound: it cannot see what the samples never found.
  j["est_relmse"] = r.estimate;
  j["est_relmse_unreliable"] = unreliable;
  // The estimate at each power of two and at the end, which the verdict is
  // drawn from: the same for the same samples, whatever the timing.
  nlohmann::json points = nlohmann::json::array();
  for (const auto& [spp, relmse_spp] : history.points()) points.push_back({spp, relmse_spp / spp});
  j["est_relmse_history"] = points;
  if (strategy.is_unbiased()) j["est_efficiency"] = efficiency(r.estimate, st.seconds);
  if (!plan.reference_missing.empty()) j["reference_missing"] = plan.reference_missing;
  if (reference.loaded()) {
    j["reference"] = reference.path;
    j["relmse"] = r.error.corrected;
    j["relmse_interval"] = r.error.interval;
    j["relmse_raw"] = r.error.raw;
    j["reference_corrected"] = r.error.reference_corrected;
    j["reference_share"] = r.error.reference_share();
    j["efficiency"] = efficiency(r.error.corrected, st.seconds);
  }
  write_text(o.stats_json, j.dump(2) + "\n");
}

void print_render_summary(const RenderOptions& o, const RenderPlan& plan, const RenderResult& r,
                          const Reference& reference, bool unreliable) {
  const SessionStats& st = r.stats;
  const std::string target = o.out_given ? o.out : plan.film_out;
  std::printf("%llu spp, %dx%d, %.2f s, %.3f M samples/s, %d threads, %s -> %s\n",
              static_cast<unsigned long long>(r.info.spp()), r.info.width, r.info.height, st.seconds,
              st.samples_per_second * 1e-6, r.threads, drops_text(r.info.dropped).c_str(), printable(target).c_str());
  if (st.guiding_passes > 0)
    std::printf("path guiding: %d training passes of 1 to %u spp (discarded; their time is in the %.2f s), %llu "
                "records; the SD-tree: %d leaves, %zu quadtree nodes, %d levels deep, %.2f MiB\n",
                st.guiding_passes, 1u << (st.guiding_passes - 1), st.seconds,
                static_cast<unsigned long long>(st.guiding_records), st.guiding.leaves, st.guiding.nodes,
                st.guiding.max_depth, static_cast<double>(st.guiding.bytes) / (1024.0 * 1024.0));
  if (reference.loaded()) {
    std::printf("relMSE %.4g +- %.2g (95%%) against %s; raw %.4g, of which the reference's own noise is %.1f%%%s; "
                "efficiency %.4g\n",
                r.error.corrected, r.error.interval, printable(reference.path).c_str(), r.error.raw,
                100.0 * r.error.reference_share(),
                r.error.reference_corrected ? "" : " (unknown: it has no variance, nothing subtracted)",
                efficiency(r.error.corrected, st.seconds));
    return;
  }
  std::printf("est. relMSE %.4g: a lower bound from the film's own variance, blind to what its samples never "
              "found; ",
              r.estimate);
  if (plan.strategy.is_unbiased())
    std::printf("efficiency estimate %.4g\n", efficiency(r.estimate, st.seconds));
  else
    std::printf("no efficiency: '%s' is biased and no reference shows how much light it misses\n",
                plan.strategy.to_string().c_str());
  if (unreliable)
    std::printf("warning: the estimate is unreliable: relMSE * spp grew more than 2x over a doubling of samples "
                "(rare bright paths are still being found); measure against a reference (--reference auto)\n");
}

}  // namespace

int run_render(const RenderOptions& o) {
  check_render_options(o);
  RenderPlan plan = plan_render(o);
  if (o.out_given) check_sidecar(sidecar_of(o.out), o.out, plan.scene_path);
  const Reference reference = checked_reference(o, plan);
  note_bias(plan.strategy, o.quiet);

  FilmRender render(o, plan);
  EstimateHistory history;  // is the film's own estimate trustworthy?
  if (const int status = wait_for_render(o, plan, render, history); status != 0) return status;
  const RenderResult result = finish_render(o, plan, render, reference);

  if (!o.stats_json.empty()) write_render_stats(o, plan, result, reference, history);
  print_render_summary(o, plan, result, reference, history.unreliable());
  return 0;
}

namespace {

void check_merge_options(const MergeOptions& o) {
  if (o.films.empty()) throw InputError("merge: name at least one film");
  if (o.out.empty() && o.film_out.empty()) throw InputError("merge: nothing to write: give --out IMAGE, --film-out FILM or both");
  if (!o.out.empty()) {
    (void)image_format_for(o.out);
    check_output_path(o.out);
  }
  if (!o.film_out.empty()) check_output_path(o.film_out);
  if (!o.stats_json.empty()) check_output_path(o.stats_json);
  const std::string sidecar = sidecar_of(o.out);
  check_distinct_outputs({o.out, o.film_out, o.stats_json, same_file(sidecar, o.stats_json) ? "" : sidecar});
  (void)parse_transfer(o.transfer);
  for (std::size_t i = 0; i < o.films.size(); ++i)
    for (std::size_t k = 0; k < i; ++k) {
      std::error_code ec;
      if (std::filesystem::equivalent(o.films[i], o.films[k], ec))
        throw InputError("merge: film '" + o.films[i] + "' is named twice; its samples would be counted twice");
    }
}

// Each film is checked against every one before it, so a refusal names the
// two files that disagree; then it is added and dropped. `each` receives
// every film's own description, in the order given.
FilmFile merge_films(const std::vector<std::string>& films, std::vector<FilmInfo>& each) {
  FilmFile all = read_film_file(films.front());
  each = {all.info};
  for (std::size_t i = 1; i < films.size(); ++i) {
    FilmFile next = read_film_file(films[i]);
    for (std::size_t k = 0; k < i; ++k)
      if (const std::string problem = merge_problem(films[k], each[k], films[i], next.info); !problem.empty())
        throw InputError(problem);
    all.film.add_film(next.film);
    all.info = merged_info(all.info, next.info);
    each.push_back(std::move(next.info));
  }
  return all;
}

std::string range_text(std::uint64_t seed, std::uint64_t first, std::uint64_t end) {
  return "seed " + std::to_string(seed) + " samples [" + std::to_string(first) + ", " + std::to_string(end) + ")";
}

// --expect-spp N: the merge must be the whole of [0, N) of one seed, as a
// fan-out of one render is. A part that failed, or stopped early and saved
// what it had, leaves a gap; the refusal names each missing range and the
// film that ends where it starts (a part that stopped early).
void check_expected_samples(const MergeOptions& o, const FilmInfo& all, const std::vector<FilmInfo>& each) {
  const std::uint32_t n = o.expect_spp;
  const std::vector<std::uint64_t> seeds = all.seeds();
  if (seeds.size() != 1)
    throw InputError("merge: the films hold samples of " + std::to_string(seeds.size()) + " seeds (" +
                     all.ranges_text() + "); --expect-spp " + std::to_string(n) + " expects one seed's [0, " +
                     std::to_string(n) + ")");
  const std::uint64_t seed = seeds.front();
  std::string missing, beyond;
  std::uint64_t at = 0;
  const auto name_missing = [&](std::uint64_t first, std::uint64_t end) {
    std::string ender;
    for (std::size_t i = 0; i < each.size() && ender.empty(); ++i)
      for (const SampleRange& r : each[i].ranges)
        if (r.end == first) ender = " after '" + o.films[i] + "', which ends there";
    if (!missing.empty()) missing += "; ";
    missing += range_text(seed, first, end);
    missing += ender;
  };
  for (const SampleRange& r : all.ranges) {  // sorted, touching ones joined (merged_info)
    if (r.first > at && at < n) name_missing(at, std::min<std::uint64_t>(r.first, n));
    if (r.end > n) {
      if (!beyond.empty()) beyond += ", ";
      beyond += range_text(seed, std::max<std::uint64_t>(r.first, n), r.end);
    }
    at = std::max<std::uint64_t>(at, r.end);
  }
  if (at < n) name_missing(at, n);
  if (missing.empty() && beyond.empty()) return;
  std::string why = "merge: the films hold " + std::to_string(all.spp()) + " of the " + std::to_string(n) +
                    " samples per pixel expected (" + all.ranges_text() + ")";
  if (!missing.empty())
    why += "; missing " + missing + ": render the missing samples (or resume the film that stopped) and merge again";
  if (!beyond.empty()) why += "; beyond [0, " + std::to_string(n) + "): " + beyond;
  throw InputError(why);
}

}  // namespace

int run_merge(const MergeOptions& o) {
  check_merge_options(o);
  const Transfer transfer = parse_transfer(o.transfer);
  std::vector<FilmInfo> each;
  const FilmFile all = merge_films(o.films, each);
  if (o.expect_spp > 0) check_expected_samples(o, all.info, each);
  if (!o.out.empty()) check_sidecar(sidecar_of(o.out), o.out, all.info.scene_file);

  if (!o.film_out.empty()) write_film_file(o.film_out, all.info, all.film);
  if (!o.out.empty()) write_identified_image(o.out, all.film, transfer, all.info, o.stats_json);
  if (!o.stats_json.empty()) {
    nlohmann::json j = identity_json(all.info);
    j["films"] = o.films;
    j["samples"] = all.info.ranges_text();
    j["dropped"] = drops_json(all.info.dropped);
    write_text(o.stats_json, j.dump(2) + "\n");
  }
  std::printf("merged %zu films: %llu spp (%s), %dx%d, %.2f s of rendering, %s -> %s\n", o.films.size(),
              static_cast<unsigned long long>(all.info.spp()), all.info.ranges_text().c_str(), all.info.width,
              all.info.height, all.info.seconds, drops_text(all.info.dropped).c_str(),
              printable(!o.out.empty() ? o.out : o.film_out).c_str());
  return 0;
}

}  // namespace pdflab
