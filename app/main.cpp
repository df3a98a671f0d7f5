// pdflab: the viewer (default) and the headless commands. See README.md.
#include "app/assets.h"
#include "app/bench_command.h"
#include "app/reference_command.h"
#include "app/render_command.h"
#include "app/sweep_command.h"
#include "renderer/error.h"
#include "renderer/film/film_file.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>

#ifdef PDFLAB_HAVE_VIEWER
#include "app/viewer.h"
#endif

namespace {

constexpr int kBadInput = 2;
constexpr int kInternalFailure = 1;

int report_input_error(const std::string& what) {
  std::fprintf(stderr, "pdflab: error: %s\n", what.c_str());
  return kBadInput;
}

// CLI11 wraps "-1" around and saturates a too large number when it converts
// them to an unsigned option; both are typing mistakes, so check first.
// CLI::PositiveNumber would print DBL_MAX in its message and let "nan" through;
// say plainly what is wrong instead.
CLI::Validator positive_number(const std::string& what) {
  return CLI::Validator(
      [what](std::string& text) {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || v <= 0.0)
          return "must be a positive number" + what + ", not '" + text + "'";
        return std::string();
      },
      "NUMBER");
}

// Every command that reads or writes references takes the cache folder the same way.
void add_cache_dir_option(CLI::App* command, std::string& cache_dir) {
  command->add_option("--cache-dir", cache_dir,
                      "Reference cache folder (default: $PDFLAB_REFERENCE_CACHE, else $XDG_CACHE_HOME/pdflab/references)");
}

// A headless comparison's reference (bench, sweep): the file or the cache, and
// the size to look it up at.
void add_comparison_reference_options(CLI::App* command, std::string& reference, int& width, int& height,
                                      std::string& cache_dir) {
  command->add_option("--reference", reference,
                      "Reference: a .pfm (its size sets the render size), or 'auto' for the cached one")
      ->required();
  command->add_option("--width", width, "With --reference auto: image width (default: the scene's)")
      ->check(CLI::Range(1, 16384));
  command->add_option("--height", height, "With --reference auto: image height (default: the scene's)")
      ->check(CLI::Range(1, 16384));
  add_cache_dir_option(command, cache_dir);
}

CLI::Validator non_negative_integer() {
  return CLI::Validator(
      [](std::string& value) {
        std::uint64_t parsed = 0;
        const char* end = value.data() + value.size();
        const auto [ptr, ec] = std::from_chars(value.data(), end, parsed);
        if (value.empty() || ec != std::errc() || ptr != end)
          return "must be an integer in 0.." + std::to_string(UINT64_MAX) + ", not '" + value + "'";
        return std::string();
      },
      "UINT64");
}

// --rr or --rr=D: Russian roulette in every strategy the command renders.
void add_roulette_option(CLI::App* command, int& depth) {
  command
      ->add_flag("--rr{" + std::to_string(pdflab::kDefaultRouletteDepth) + "}", depth,
                 "Russian roulette in every strategy, from path depth D on (--rr=D; default " +
                     std::to_string(pdflab::kDefaultRouletteDepth) + "): the same as +rr:D on each")
      ->check(CLI::Range(1, pdflab::kMaxRouletteDepth));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pdflab: a laboratory for importance sampling in path tracing"};
  app.set_version_flag("--version", std::string(PDFLAB_VERSION));
  app.require_subcommand(0, 1);

  // The viewer's options (no subcommand).
  std::string view_scene, view_strategy = "mix:cosine=0.5,light=0.5", screenshot;
  std::uint32_t view_spp = 0;
  app.add_option("--scene", view_scene, "Scene file (default: the book's Cornell box)");
  CLI::Option* view_strategy_option = app.add_option("--strategy", view_strategy, "Sampling strategy (below)");
  app.footer(pdflab::strategy_help());
  app.add_option("--spp", view_spp, "With --screenshot: samples per pixel to render before saving")
      ->check(CLI::Range(1u, 1u << 30));
  app.add_option("--screenshot", screenshot, "Render until --spp, save this PNG (plus PFM and JSON), exit");
  std::string view_reference, view_resume;
  app.add_option("--resume", view_resume,
                 "Continue a film file (from render --film-out or the viewer's Ctrl+S) with its scene and settings");
  float view_ui_scale = 1.0f;
  bool view_presentation = false;
  bool view_auto_weight = false;
  std::string view_mode;
  app.add_option("--ui-scale", view_ui_scale, "Scale of the panels and their text, e.g. 1.5 for a projector")
      ->check(CLI::Range(0.5f, 4.0f));
  app.add_flag("--presentation", view_presentation, "Start in presentation mode: full screen, no panel (F11 leaves)");
  app.add_flag("--auto-weight", view_auto_weight,
               "Start with auto weight: a two-technique mixture's w moves between passes to the predicted best");
  app.add_option("--view", view_mode,
                 "Start in a view mode: image, heatmap, difference, drops, best-weight, technique-share");
  app.add_option("--reference", view_reference,
                 "Reference image (PFM) for live error figures in the viewer (default: the cached one, if any)");
  double view_make_seconds = 0.0;
  app.add_option("--reference-seconds", view_make_seconds, "The time limit Make reference starts with (120)")
      ->check(positive_number(" of seconds"));
  std::string view_window, view_layout_json;
  app.add_option("--window", view_window, "Window size WxH, e.g. 1280x720 (default: as last time, else fit the image)")
      ->check(CLI::Validator(
          [](std::string& v) {
            int w = 0, h = 0;
            char x = 0, rest = 0;
            if (std::sscanf(v.c_str(), "%d%c%d%c", &w, &x, &h, &rest) != 3 || (x != 'x' && x != 'X') || w < 200 ||
                h < 200 || w > 16384 || h > 16384)
              return "must be WIDTHxHEIGHT with each side in 200..16384, not '" + v + "'";
            return std::string();
          },
          "WxH"));
  app.add_option("--layout-json", view_layout_json, "Write the viewer's layout (panel, overlays, controls) to this JSON file");

  pdflab::RenderOptions ro;
  CLI::App* render = app.add_subcommand("render", "Render headlessly to an image file");
  render->footer(pdflab::strategy_help());
  CLI::Option* scene_option = render->add_option("--scene", ro.scene, "Scene file (JSON); with --resume, default: the film's");
  CLI::Option* strategy_option = render->add_option("--strategy", ro.strategy,
                     "Sampling strategy, e.g. cosine, light, mix:cosine=0.5,light=0.5; with --resume, default: the film's");
  CLI::Option* spp_option =
      render->add_option("--spp", ro.spp, "Samples per pixel (with --resume: in all, those in the film included)")
          ->check(CLI::Range(1u, 1u << 30));
  CLI::Option* out_option = render->add_option("--out", ro.out, "Output image: .png (tone-mapped), .pfm (linear), .hdr, .exr (linear, with variance and count layers)");
  CLI::Option* seed_option = render->add_option("--seed", ro.seed, "Random seed (same seed, same image, any thread count)")
      ->check(non_negative_integer());
  CLI::Option* first_option =
      render->add_option("--first-sample", ro.first_sample,
                         "Index of the first sample of each pixel (default 0): renders of disjoint ranges merge")
          ->check(CLI::Range(0u, 0xffffffffu));
  render->add_option("--film-out", ro.film_out, "Also save the accumulation as a film file (for --resume and merge)");
  render->add_option("--resume", ro.resume, "Continue this film file (saved to it again unless --film-out says otherwise)");
  render->add_option("--checkpoint-seconds", ro.checkpoint_seconds,
                     "With a film file: save it this often while rendering (default 60; 0: only at the end)")
      ->check(CLI::Range(0.0, 1e9));
  render->add_option("--threads", ro.threads, "Worker threads (0: all cores)")->check(CLI::Range(0, 1024));
  render->add_option("--width", ro.width, "Image width (default: the scene's)")->check(CLI::Range(1, 16384));
  render->add_option("--height", ro.height, "Image height (default: the scene's)")->check(CLI::Range(1, 16384));
  render->add_option("--stats-json", ro.stats_json, "Also write the summary as JSON");
  render->add_option("--transfer", ro.transfer, "PNG transfer curve: gamma2 (the book's) or srgb")
      ->check(CLI::IsMember({"gamma2", "srgb"}));
  render->add_option("--reference", ro.reference,
                     "Reference to measure against: a .pfm, or 'auto' for the cached one of this scene, size and depth");
  add_cache_dir_option(render, ro.cache_dir);
  render->add_flag("--quiet", ro.quiet, "No progress bar or notes");
  add_roulette_option(render, ro.roulette_depth);

  pdflab::ReferenceOptions fo;
  CLI::App* reference = app.add_subcommand(
      "reference", "Render a converged reference (unbiased, reserved seeds) into the cache, and --out if given");
  reference->add_option("--scene", fo.scene, "Scene file (JSON)")->required();
  reference->add_option("--width", fo.width, "Image width (default: the scene's)")->check(CLI::Range(1, 16384));
  reference->add_option("--height", fo.height, "Image height (default: the scene's)")->check(CLI::Range(1, 16384));
  reference->add_option("--max-depth", fo.max_depth, "Path depth (default: the scene's)")->check(CLI::Range(1, 10000));
  reference->add_option("--spp", fo.spp, "Stop at this many samples per pixel")->check(CLI::Range(1u, 1u << 30));
  reference->add_option("--seconds", fo.seconds, "Stop after this much rendering time")
      ->check(positive_number(" of seconds"));
  reference->add_option("--target-relmse", fo.target_relmse,
                        "Stop when the estimated relMSE of the reference itself is at most this")
      ->check(positive_number(""));
  reference->add_option("--strategy", fo.strategy,
                        "Unbiased strategy (default: mix:cosine=0.5,light=0.5, cosine for a scene without targets)");
  reference->add_option("--seed-stream", fo.seed_stream, "Which of the reference seeds (independent references)")
      ->check(CLI::Range(0u, 1u << 30));
  reference->add_option("--out", fo.out, "Also write the reference here (.pfm, with .var.pfm and .json beside it)");
  add_cache_dir_option(reference, fo.cache_dir);
  reference->add_option("--threads", fo.threads, "Worker threads (0: all cores)")->check(CLI::Range(0, 1024));
  reference->add_flag("--quiet", fo.quiet, "No progress bar or notes");
  add_roulette_option(reference, fo.roulette_depth);

  pdflab::MergeOptions mo;
  CLI::App* merge = app.add_subcommand("merge", "Add films of one scene and settings with disjoint sample ranges");
  merge->add_option("films", mo.films, "Film files (from render --film-out)")->required();
  merge->add_option("--out", mo.out, "Image of the merged estimate: .exr, .pfm, .png or .hdr");
  merge->add_option("--film-out", mo.film_out, "The merged film");
  merge->add_option("--stats-json", mo.stats_json, "Also write the summary as JSON");
  merge->add_option("--transfer", mo.transfer, "PNG transfer curve: gamma2 (the book's) or srgb")
      ->check(CLI::IsMember({"gamma2", "srgb"}));

  pdflab::BenchOptions bo;
  CLI::App* bench = app.add_subcommand("bench", "Compare strategies at equal time (or spp) against a reference");
  bench->add_option("--scene", bo.scene, "Scene file (JSON)")->required();
  bench->add_option("--strategies", bo.strategies, "Strategies separated by ';'")->required();
  // CLI::PositiveNumber would print DBL_MAX in its message and let "nan" through to the
  // "exactly one of" check; say plainly what is wrong instead.
  bench->add_option("--seconds", bo.seconds, "Render time per strategy (equal time)")
      ->check(positive_number(" of seconds"));
  bench->add_option("--spp", bo.spp, "Samples per pixel per strategy (equal samples)")->check(CLI::Range(1u, 1u << 30));
  add_comparison_reference_options(bench, bo.reference, bo.width, bo.height, bo.cache_dir);
  bench->add_option("--csv", bo.csv, "Results table as CSV")->required();
  bench->add_option("--plot", bo.plot, "Log-log plot of RMSE against time (SVG)");
  bench->add_option("--curves", bo.curves, "Every checkpoint of every strategy as CSV");
  bench->add_option("--predict", bo.predict,
                    "A,B: predict each mixture of A and B's efficiency from the paths of the one nearest 0.5");
  bench->add_option("--seed", bo.seed, "Random seed (default 2; use one the reference was not rendered with)")
      ->check(non_negative_integer());
  bench->add_option("--threads", bo.threads, "Worker threads (0: all cores)")->check(CLI::Range(0, 1024));
  bench->add_flag("--quiet", bo.quiet, "No progress line");
  add_roulette_option(bench, bo.roulette_depth);

  pdflab::SweepOptions so;
  CLI::App* sweep =
      app.add_subcommand("sweep", "Efficiency against the mixture weight of two techniques, at equal time, over seeds");
  sweep->add_option("--scene", so.scene, "Scene file (JSON)")->required();
  sweep->add_option("--vary", so.vary, "The two techniques A,B whose shares are swept (e.g. cosine,light)")->required();
  sweep->add_option("--weights", so.weights, "A's share of the pair as LO:HI:STEP (e.g. 0.1:0.9:0.1)")->required();
  sweep->add_option("--strategy", so.strategy, "Base mixture: the other techniques keep their weights");
  sweep->add_option("--seconds", so.seconds, "Render time per run (equal time)")->check(positive_number(" of seconds"));
  sweep->add_option("--spp", so.spp, "Samples per pixel per run (equal samples)")->check(CLI::Range(1u, 1u << 30));
  add_comparison_reference_options(sweep, so.reference, so.width, so.height, so.cache_dir);
  sweep->add_option("--seeds", so.seeds, "Runs per weight, for the intervals (default 3)")->check(CLI::Range(1, 1000));
  sweep->add_option("--seed", so.seed, "First seed (default 2; use one the reference was not rendered with)")
      ->check(non_negative_integer());
  sweep->add_option("--csv", so.csv, "One row per weight (CSV)")->required();
  sweep->add_option("--plot", so.plot, "Efficiency against weight, best weight marked (SVG)");
  sweep->add_option("--map", so.map, "Each pixel's predicted best weight, blue (0) to red (1) (PNG)");
  sweep->add_option("--threads", so.threads, "Worker threads (0: all cores)")->check(CLI::Range(0, 1024));
  sweep->add_flag("--quiet", so.quiet, "No progress");
  add_roulette_option(sweep, so.roulette_depth);
  sweep->add_flag("--auto", so.auto_weight,
                  "Also render with auto weight (chosen between passes from the prediction) and compare");
  sweep->add_flag("--cpu-time", so.cpu_time,
                  "Price each run by its CPU time rather than the wall clock (runs still stop by the wall clock); "
                  "for a machine shared with other work");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "pdflab: error: %s\nRun 'pdflab --help' or 'pdflab COMMAND --help' for usage.\n", e.what());
    return kBadInput;
  }

  try {
    if (render->parsed()) {
      ro.scene_given = scene_option->count() > 0;
      ro.strategy_given = strategy_option->count() > 0;
      ro.spp_given = spp_option->count() > 0;
      ro.out_given = out_option->count() > 0;
      ro.seed_given = seed_option->count() > 0;
      ro.first_sample_given = first_option->count() > 0;
      return pdflab::run_render(ro);
    }
    if (merge->parsed()) return pdflab::run_merge(mo);
    if (bench->parsed()) return pdflab::run_bench(bo);
    if (reference->parsed()) return pdflab::run_reference(fo);
    if (sweep->parsed()) return pdflab::run_sweep(so);
#ifdef PDFLAB_HAVE_VIEWER
    pdflab::ViewerOptions vo;
    vo.scene = view_scene.empty() ? pdflab::default_scene_path() : view_scene;
    vo.strategy = view_strategy;
    vo.spp = view_spp;
    vo.screenshot = screenshot;
    vo.reference = view_reference;
    vo.resume = view_resume;
    if (!view_resume.empty()) {
      // The film names its scene and strategy; given again, they must match it.
      const pdflab::FilmFile film = pdflab::read_film_file(view_resume);
      if (view_scene.empty()) vo.scene = film.info.scene_file;
      if (view_strategy_option->count() == 0) vo.strategy = film.info.strategy;
    }
    vo.ui_scale = view_ui_scale;
    vo.presentation = view_presentation;
    vo.auto_weight = view_auto_weight;
    vo.view = view_mode;
    vo.make_reference_seconds = view_make_seconds;
    char x = 0;
    if (!view_window.empty()) std::sscanf(view_window.c_str(), "%d%c%d", &vo.window_width, &x, &vo.window_height);
    vo.layout_json = view_layout_json;
    vo.remember = true;
    return pdflab::run_viewer(vo);
#else
    // Built without the viewer: render the default scene headlessly instead.
    (void)view_strategy_option;
    pdflab::RenderOptions fallback;
    fallback.scene = view_scene.empty() ? pdflab::default_scene_path() : view_scene;
    fallback.strategy = view_strategy;
    fallback.spp = view_spp ? view_spp : 64;
    fallback.out = screenshot.empty() ? "pdflab.png" : screenshot;
    const int status = pdflab::run_render(fallback);
    std::printf("pdflab was built without the viewer; the image is at %s\n",
                std::filesystem::absolute(fallback.out).c_str());
    return status;
#endif
  } catch (const pdflab::InputError& e) {
    return report_input_error(e.what());
  } catch (const pdflab::IoError& e) {
    std::fprintf(stderr, "pdflab: error: %s\n", e.what());
    return kInternalFailure;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pdflab: internal error: %s\n", e.what());
    return kInternalFailure;
  }
}
