#include "app/render_command.h"

#include "app/reference_command.h"
#include "renderer/metrics/metrics.h"

#include "renderer/error.h"
#include "renderer/film/film.h"
#include "renderer/film/image_io.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include <nlohmann/json.hpp>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <thread>

namespace pdflab {

namespace {

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

}  // namespace

int run_render(const RenderOptions& o) {
  // Everything the user typed is checked before any work starts.
  if (o.spp == 0) throw InputError("--spp must be at least 1");
  const ImageFormat format = image_format_for(o.out);
  (void)format;
  check_output_path(o.out);
  if (!o.stats_json.empty()) check_output_path(o.stats_json);
  check_distinct_outputs({o.out, o.stats_json});
  Transfer transfer;
  if (o.transfer == "gamma2") transfer = Transfer::Gamma2;
  else if (o.transfer == "srgb") transfer = Transfer::Srgb;
  else throw InputError("--transfer must be 'gamma2' or 'srgb', not '" + o.transfer + "'");
  if (o.threads < 0 || o.threads > 1024) throw InputError("--threads must be in 0..1024 (0: all cores)");

  auto scene = std::make_shared<Scene>(load_scene_file(o.scene));
  if (o.width != 0) scene->camera.width = o.width;
  if (o.height != 0) scene->camera.height = o.height;
  if (o.width != 0 || o.height != 0) check_image_size(scene->camera.width, scene->camera.height, "--width/--height");
  scene->prepare();
  const Strategy strategy = Strategy::parse(o.strategy);
  (void)SamplingPlan::make(strategy, *scene);  // strategy/scene mismatch is bad input too

  // The reference is checked before any rendering: its size, and that the
  // render would not repeat its random numbers.
  const Reference reference = resolve_reference(o.reference, *scene, o.scene, o.cache_dir, false, o.quiet);
  if (reference.loaded()) {
    if (reference.width != scene->camera.width || reference.height != scene->camera.height)
      throw InputError("reference '" + reference.path + "' is " + std::to_string(reference.width) + "x" +
                       std::to_string(reference.height) + " but the render is " +
                       std::to_string(scene->camera.width) + "x" + std::to_string(scene->camera.height) +
                       " (use --width/--height)");
    if (const std::string shared = shared_random_numbers(reference.info, o.seed, strategy); !shared.empty())
      throw InputError("reference '" + reference.path + "': " + shared + "; choose another --seed");
  }

  if (!strategy.is_unbiased() && !o.quiet)
    std::fprintf(stderr,
                 "note: strategy '%s' is biased: its pdf is zero for directions that miss the importance "
                 "targets, so it omits indirect light\n",
                 strategy.to_string().c_str());

  RenderSession session(o.threads);
  RenderSettings settings;
  settings.scene = scene;
  settings.strategy = strategy;
  settings.seed = o.seed;
  settings.target_spp = o.spp;
  session.set_settings(settings);

  const bool show_progress = !o.quiet && ::isatty(STDERR_FILENO);
  EstimateHistory history;  // is the film's own estimate trustworthy?
  std::vector<float> pass_image;
  std::uint64_t pass_version = 0;
  while (!session.wait_until_done(std::chrono::milliseconds(show_progress ? 200 : 100))) {
    if (show_progress) draw_progress(session.stats(), o.spp);
    ImageInfo info;
    if (session.copy_image(pass_image, info, pass_version) && !info.preview)
      history.add(info.spp, info.estimated_relmse);
  }
  const SessionStats st = session.stats();
  if (show_progress) {
    draw_progress(st, o.spp);
    std::fputc('\n', stderr);
  }

  const Film film = session.copy_film();
  const std::vector<float> mean = film.mean_rgb();
  const double estimate = estimated_relmse(film);
  history.add(st.spp, estimate);
  write_image(o.out, mean, film.width(), film.height(), transfer);
  RelMseMeasure error;
  if (reference.loaded()) error = measure_relmse(mean, reference.rgb, reference.variance);
  const double measured_efficiency = efficiency(error.corrected, st.seconds);

  const auto& d = st.dropped.by_reason;
  if (!o.stats_json.empty()) {
    nlohmann::json j;
    j["scene"] = scene->name;
    j["scene_file"] = o.scene;
    j["strategy"] = strategy.to_string();
    j["unbiased"] = strategy.is_unbiased();
    j["width"] = film.width();
    j["height"] = film.height();
    j["spp"] = st.spp;
    j["seed"] = o.seed;
    j["threads"] = session.thread_count();
    j["seconds"] = st.seconds;
    j["samples"] = st.samples;
    j["samples_per_second"] = st.samples_per_second;
    j["dropped"] = {{"total", st.dropped.total()}};
    for (int r = 0; r < kDropReasonCount; ++r)
      j["dropped"][std::string(drop_reason_name(static_cast<DropReason>(r)))] = d[r];
    j["output"] = o.out;
    // The film's own estimate is a lower bound: it cannot see what the samples never found.
    j["est_relmse"] = estimate;
    j["est_relmse_unreliable"] = history.unreliable();
    if (strategy.is_unbiased()) j["est_efficiency"] = efficiency(estimate, st.seconds);
    if (reference.loaded()) {
      j["reference"] = reference.path;
      j["relmse"] = error.corrected;
      j["relmse_interval"] = error.interval;
      j["relmse_raw"] = error.raw;
      j["reference_corrected"] = error.reference_corrected;
      j["reference_share"] = error.reference_share();
      j["efficiency"] = measured_efficiency;
    }
    const std::string text = j.dump(2) + "\n";
    write_file_atomic(o.stats_json, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
  }

  std::printf("%u spp, %dx%d, %.2f s, %.3f M samples/s, %d threads, %llu samples dropped "
              "(pdf_zero %llu, pdf_not_finite %llu, radiance_not_finite %llu) -> %s\n",
              st.spp, film.width(), film.height(), st.seconds, st.samples_per_second * 1e-6, session.thread_count(),
              static_cast<unsigned long long>(st.dropped.total()), static_cast<unsigned long long>(d[0]),
              static_cast<unsigned long long>(d[1]), static_cast<unsigned long long>(d[2]), o.out.c_str());
  if (reference.loaded()) {
    std::printf("relMSE %.4g +- %.2g (95%%) against %s; raw %.4g, of which the reference's own noise is %.1f%%%s; "
                "efficiency %.4g\n",
                error.corrected, error.interval, reference.path.c_str(), error.raw, 100.0 * error.reference_share(),
                error.reference_corrected ? "" : " (unknown: it has no variance, nothing subtracted)",
                measured_efficiency);
  } else {
    std::printf("est. relMSE %.4g: a lower bound from the film's own variance, blind to what its samples never "
                "found; ",
                estimate);
    if (strategy.is_unbiased())
      std::printf("efficiency estimate %.4g\n", efficiency(estimate, st.seconds));
    else
      std::printf("no efficiency: '%s' is biased and no reference shows how much light it misses\n",
                  strategy.to_string().c_str());
    if (history.unreliable())
      std::printf("warning: the estimate is unreliable: relMSE * spp grew more than 2x over a doubling of samples "
                  "(rare bright paths are still being found); measure against a reference (--reference auto)\n");
  }
  return 0;
}

}  // namespace pdflab
