// pdflab: the viewer (default) and the headless commands. See README.md.
#include "app/assets.h"
#include "app/bench_command.h"
#include "app/reference_command.h"
#include "app/render_command.h"
#include "app/sweep_command.h"
#include "app/veach_command.h"
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
#include <functional>
#include <optional>

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

// Every command that reads or writes references takes the cache folder the same way.
void add_cache_dir_option(CLI::App* command, std::string& cache_dir) {
  command->add_option("--cache-dir", cache_dir,
                      "Reference cache folder (default: $PDFLAB_REFERENCE_CACHE, else $XDG_CACHE_HOME/pdflab/references)");
}

// --rr or --rr=D: Russian roulette in every strategy the command renders.
void add_roulette_option(CLI::App* command, int& depth) {
  command
      ->add_flag("--rr{" + std::to_string(pdflab::kDefaultRouletteDepth) + "}", depth,
                 "Russian roulette in every strategy, from path depth D on (--rr=D; default " +
                     std::to_string(pdflab::kDefaultRouletteDepth) + "): the same as +rr:D on each")
      ->check(CLI::Range(1, pdflab::kMaxRouletteDepth));
}

void add_threads_option(CLI::App* command, int& threads) {
  command->add_option("--threads", threads, "Worker threads (0: all cores)")->check(CLI::Range(0, 1024));
}

// The viewer: pdflab without a command. Its options stay apart from
// ViewerOptions so that a build without the viewer parses them too.
struct ViewerCommand {
  std::string scene, strategy = "mix:cosine=0.5,light=0.5", screenshot, reference, resume, mode;
  std::uint32_t spp = 0;
  float ui_scale = 1.0f;
  bool presentation = false, auto_weight = false;
  double make_reference_seconds = 0.0;
  std::string window, layout_json;
  CLI::Option* strategy_option = nullptr;
};

void add_viewer_options(CLI::App& app, ViewerCommand& v) {
  app.add_option("--scene", v.scene, "Scene file (default: the book's Cornell box)");
  v.strategy_option = app.add_option("--strategy", v.strategy, "Sampling strategy (below)");
  app.footer(pdflab::strategy_help());
  app.add_option("--spp", v.spp, "With --screenshot: samples per pixel to render before saving")
      ->check(CLI::Range(1u, 1u << 30));
  app.add_option("--screenshot", v.screenshot, "Render until --spp, save this PNG (plus PFM and JSON), exit");
  app.add_option("--resume", v.resume,
                 "Continue a film file (from render --film-out or the viewer's Ctrl+S) with its scene and settings");
  app.add_option("--ui-scale", v.ui_scale, "Scale of the panels and their text, e.g. 1.5 for a projector")
      ->check(CLI::Range(0.5f, 4.0f));
  app.add_flag("--presentation", v.presentation, "Start in presentation mode: full screen, no panel (F11 leaves)");
  app.add_flag("--auto-weight", v.auto_weight,
               "Start with auto weight: a two-technique mixture's w moves between passes to the predicted best");
  app.add_option("--view", v.mode,
                 "Start in a view mode: image, heatmap, difference, drops, best-weight, technique-share, "
                 "guiding-tree");
  app.add_option("--reference", v.reference,
                 "Reference (a .pfm, .exr or .film) for live error figures in the viewer (default: the cached one, "
                 "if any)");
  app.add_option("--reference-seconds", v.make_reference_seconds, "The time limit Make reference starts with (120)")
      ->check(positive_number(" of seconds"));
  app.add_option("--window", v.window, "Window size WxH, e.g. 1280x720 (default: as last time, else fit the image)")
      ->check(CLI::Validator(
          [](std::string& text) {
            int w = 0, h = 0;
            char x = 0, rest = 0;
            if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &rest) != 3 || (x != 'x' && x != 'X') || w < 200 ||
                h < 200 || w > 16384 || h > 16384)
              return "must be WIDTHxHEIGHT with each side in 200..16384, not '" + text + "'";
            return std::string();
          },
          "WxH"));
  app.add_option("--layout-json", v.layout_json, "Write the viewer's layout (panel, overlays, controls) to this JSON file");
}

// `render`, with what was typed and what was left to its default.
struct RenderCommand {
  pdflab::RenderOptions options;
  CLI::App* app = nullptr;
  CLI::Option *scene = nullptr, *strategy = nullptr, *spp = nullptr, *out = nullptr, *seed = nullptr,
              *first_sample = nullptr;
};

void add_render_command(CLI::App& app, RenderCommand& r) {
  pdflab::RenderOptions& ro = r.options;
  CLI::App* render = r.app = app.add_subcommand("render", "Render headlessly to an image file");
  render->footer(pdflab::strategy_help());
  r.scene = render->add_option("--scene", ro.scene, "Scene file (JSON); with --resume, default: the film's");
  r.strategy = render->add_option(
      "--strategy", ro.strategy,
      "Sampling strategy, e.g. cosine, light, mix:cosine=0.5,light=0.5; with --resume, default: the film's");
  r.spp = render->add_option("--spp", ro.spp, "Samples per pixel (with --resume: in all, those in the film included)")
              ->check(CLI::Range(1u, 1u << 30));
  r.out = render->add_option("--out", ro.out,
                             "Output image: .png (tone-mapped), .pfm (linear), .hdr, .exr (linear, with variance "
                             "and count layers)");
  r.seed = render->add_option("--seed", ro.seed, "Random seed (same seed, same image, any thread count)")
               ->check(non_negative_integer());
  r.first_sample =
      render->add_option("--first-sample", ro.first_sample,
                         "Index of the first sample of each pixel (default 0): renders of disjoint ranges merge")
          ->check(CLI::Range(0u, 0xffffffffu));
  render->add_option("--film-out", ro.film_out, "Also save the accumulation as a film file (for --resume and merge)");
  render->add_option("--resume", ro.resume, "Continue this film file (saved to it again unless --film-out says otherwise)");
  render->add_option("--checkpoint-seconds", ro.checkpoint_seconds,
                     "With a film file: save it this often while rendering (default 60; 0: only at the end)")
      ->check(CLI::Range(0.0, 1e9));
  add_threads_option(render, ro.threads);
  render->add_option("--width", ro.width, "Image width (default: the scene's)")->check(CLI::Range(1, 16384));
  render->add_option("--height", ro.height, "Image height (default: the scene's)")->check(CLI::Range(1, 16384));
  render->add_option("--stats-json", ro.stats_json, "Also write the summary as JSON");
  render->add_option("--transfer", ro.transfer, "PNG transfer curve: gamma2 (the book's) or srgb")
      ->check(CLI::IsMember({"gamma2", "srgb"}));
  render->add_option("--reference", ro.reference,
                     "Reference to measure against: a .pfm, .exr or .film, or 'auto' for the cached one of this "
                     "scene, size and depth");
  add_cache_dir_option(render, ro.cache_dir);
  render->add_flag("--quiet", ro.quiet, "No progress bar or notes");
  add_roulette_option(render, ro.roulette_depth);
}

// What render needs to know about the command line beyond the values: which
// options were typed (with --resume the others default to the film's).
pdflab::RenderOptions typed_render_options(const RenderCommand& r) {
  pdflab::RenderOptions o = r.options;
  o.scene_given = r.scene->count() > 0;
  o.strategy_given = r.strategy->count() > 0;
  o.spp_given = r.spp->count() > 0;
  o.out_given = r.out->count() > 0;
  o.seed_given = r.seed->count() > 0;
  o.first_sample_given = r.first_sample->count() > 0;
  return o;
}

CLI::App* add_reference_command(CLI::App& app, pdflab::ReferenceOptions& fo) {
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
  add_threads_option(reference, fo.threads);
  reference->add_flag("--quiet", fo.quiet, "No progress bar or notes");
  add_roulette_option(reference, fo.roulette_depth);
  return reference;
}

CLI::App* add_merge_command(CLI::App& app, pdflab::MergeOptions& mo) {
  CLI::App* merge = app.add_subcommand("merge", "Add films of one scene and settings with disjoint sample ranges");
  merge->add_option("films", mo.films, "Film files (from render --film-out)")->required();
  merge->add_option("--out", mo.out, "Image of the merged estimate: .exr, .pfm, .png or .hdr");
  merge->add_option("--film-out", mo.film_out, "The merged film");
  merge->add_option("--stats-json", mo.stats_json, "Also write the summary as JSON");
  merge->add_option("--expect-spp", mo.expect_spp,
                    "Refuse unless the films hold exactly samples [0, N) of one seed: a missing part or one that "
                    "stopped early is named, nothing written")
      ->check(CLI::Range(1u, 0xffffffffu));
  merge->add_option("--transfer", mo.transfer, "PNG transfer curve: gamma2 (the book's) or srgb")
      ->check(CLI::IsMember({"gamma2", "srgb"}));
  return merge;
}

// What bench and sweep share (ComparisonOptions), in three groups placed
// among each command's own options: how long each run is and what it is
// measured against; the CSV and the plot; the seed and the threads.
void add_comparison_inputs(CLI::App* command, pdflab::ComparisonOptions& c, const std::string& per_run) {
  // CLI::PositiveNumber would print DBL_MAX in its message and let "nan" through to the
  // "exactly one of" check; say plainly what is wrong instead.
  command->add_option("--seconds", c.seconds, "Render time per " + per_run + " (equal time)")
      ->check(positive_number(" of seconds"));
  command->add_option("--spp", c.spp, "Samples per pixel per " + per_run + " (equal samples)")
      ->check(CLI::Range(1u, 1u << 30));
  command
      ->add_option("--reference", c.reference,
                   "Reference: a .pfm, .exr or .film (its size sets the render size), or 'auto' for the cached one")
      ->required();
  command->add_option("--width", c.width, "With --reference auto: image width (default: the scene's)")
      ->check(CLI::Range(1, 16384));
  command->add_option("--height", c.height, "With --reference auto: image height (default: the scene's)")
      ->check(CLI::Range(1, 16384));
  add_cache_dir_option(command, c.cache_dir);
}

void add_comparison_outputs(CLI::App* command, pdflab::ComparisonOptions& c, const std::string& csv_help,
                            const std::string& plot_help) {
  command->add_option("--csv", c.csv, csv_help)->required();
  command->add_option("--plot", c.plot, plot_help);
}

void add_seed_and_threads(CLI::App* command, pdflab::ComparisonOptions& c, const std::string& seed_help) {
  command->add_option("--seed", c.seed, seed_help)->check(non_negative_integer());
  add_threads_option(command, c.threads);
}

CLI::App* add_bench_command(CLI::App& app, pdflab::BenchOptions& bo) {
  CLI::App* bench = app.add_subcommand("bench", "Compare strategies at equal time (or spp) against a reference");
  bench->add_option("--scene", bo.scene, "Scene file (JSON)")->required();
  bench->add_option("--strategies", bo.strategies, "Strategies separated by ';'")->required();
  add_comparison_inputs(bench, bo, "strategy");
  add_comparison_outputs(bench, bo, "Results table as CSV", "Log-log plot of RMSE against time (SVG)");
  bench->add_option("--curves", bo.curves, "Every checkpoint of every strategy as CSV");
  bench->add_option("--predict", bo.predict,
                    "A,B: predict each mixture of A and B's efficiency from the paths of the one nearest 0.5");
  add_seed_and_threads(bench, bo, "Random seed (default 2; use one the reference was not rendered with)");
  bench->add_flag("--quiet", bo.quiet, "No progress line");
  add_roulette_option(bench, bo.roulette_depth);
  return bench;
}

CLI::App* add_sweep_command(CLI::App& app, pdflab::SweepOptions& so) {
  CLI::App* sweep =
      app.add_subcommand("sweep", "Efficiency against the mixture weight of two techniques, at equal time, over seeds");
  sweep->add_option("--scene", so.scene, "Scene file (JSON)")->required();
  sweep->add_option("--vary", so.vary, "The two techniques A,B whose shares are swept (e.g. cosine,light)")->required();
  sweep->add_option("--weights", so.weights, "A's share of the pair as LO:HI:STEP (e.g. 0.1:0.9:0.1)")->required();
  sweep->add_option("--strategy", so.strategy, "Base mixture: the other techniques keep their weights");
  add_comparison_inputs(sweep, so, "run");
  sweep->add_option("--seeds", so.seeds, "Runs per weight, for the intervals (default 3)")->check(CLI::Range(1, 1000));
  add_comparison_outputs(sweep, so, "One row per weight (CSV)", "Efficiency against weight, best weight marked (SVG)");
  sweep->add_option("--map", so.map, "Each pixel's predicted best weight, blue (0) to red (1) (PNG)");
  add_seed_and_threads(sweep, so, "First seed (default 2; use one the reference was not rendered with)");
  sweep->add_flag("--quiet", so.quiet, "No progress");
  add_roulette_option(sweep, so.roulette_depth);
  sweep->add_flag("--auto", so.auto_weight,
                  "Also render with auto weight (chosen between passes from the prediction) and compare");
  sweep->add_flag("--cpu-time", so.cpu_time,
                  "Price each run by its CPU time rather than the wall clock (runs still stop by the wall clock); "
                  "for a machine shared with other work");
  return sweep;
}

CLI::App* add_veach_command(CLI::App& app, pdflab::VeachOptions& vo) {
  CLI::App* veach = app.add_subcommand(
      "veach", "Veach's MIS figure: bsdf, light-sa, nee-mis:balance+bsdf and nee-mis+bsdf at equal time as one 2x2 "
               "image, and the relMSE of each plate and plate-light pair (docs/veach.md)");
  veach->add_option("--scene", vo.scene, "Scene file (default: the shipped assets/scenes/veach_mis.json)");
  add_comparison_inputs(veach, vo, "estimator and seed");
  veach->add_option("--seeds", vo.seeds, "Seeds per estimator (default 4)")->check(CLI::Range(1, 1000));
  veach->add_option("--out", vo.out, "The four first-seed renders as one image (.png, .pfm, .exr, .hdr)")->required();
  veach->add_option("--table", vo.table, "Also write the table (Markdown) here");
  add_seed_and_threads(veach, vo, "First random seed (default 2; use one the reference was not rendered with)");
  veach->add_flag("--quiet", vo.quiet, "No progress line");
  add_roulette_option(veach, vo.roulette_depth);
  return veach;
}

// The whole command line: the viewer's options and each command's.
struct CommandLine {
  ViewerCommand viewer;
  RenderCommand render;
  pdflab::ReferenceOptions reference;
  pdflab::MergeOptions merge;
  pdflab::BenchOptions bench;
  pdflab::SweepOptions sweep;
  pdflab::VeachOptions veach;
  CLI::App *reference_app = nullptr, *merge_app = nullptr, *bench_app = nullptr, *sweep_app = nullptr,
           *veach_app = nullptr;
};

void define_command_line(CLI::App& app, CommandLine& c) {
  app.set_version_flag("--version", std::string(PDFLAB_VERSION));
  app.require_subcommand(0, 1);
  add_viewer_options(app, c.viewer);
  add_render_command(app, c.render);
  c.reference_app = add_reference_command(app, c.reference);
  c.merge_app = add_merge_command(app, c.merge);
  c.bench_app = add_bench_command(app, c.bench);
  c.sweep_app = add_sweep_command(app, c.sweep);
  c.veach_app = add_veach_command(app, c.veach);
}

// The exit status when parsing ends the run (help, version, a parse error);
// nothing when a command is to run.
std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // CLI11 quotes what was typed: control bytes in an argument are shown, not sent to the terminal.
    std::fprintf(stderr, "pdflab: error: %s\nRun 'pdflab --help' or 'pdflab COMMAND --help' for usage.\n",
                 pdflab::printable(e.what()).c_str());
    return kBadInput;
  }
  return std::nullopt;
}

#ifdef PDFLAB_HAVE_VIEWER
int run_viewer_command(const ViewerCommand& v) {
  pdflab::ViewerOptions vo;
  vo.scene = v.scene.empty() ? pdflab::default_scene_path() : v.scene;
  vo.strategy = v.strategy;
  vo.spp = v.spp;
  vo.screenshot = v.screenshot;
  vo.reference = v.reference;
  vo.resume = v.resume;
  if (!v.resume.empty()) {
    // The film names its scene and strategy; given again, they must match it.
    const pdflab::FilmFile film = pdflab::read_film_file(v.resume);
    if (v.scene.empty()) vo.scene = film.info.scene_file;
    if (v.strategy_option->count() == 0) vo.strategy = film.info.strategy;
  }
  vo.ui_scale = v.ui_scale;
  vo.presentation = v.presentation;
  vo.auto_weight = v.auto_weight;
  vo.view = v.mode;
  vo.make_reference_seconds = v.make_reference_seconds;
  char x = 0;
  if (!v.window.empty()) std::sscanf(v.window.c_str(), "%d%c%d", &vo.window_width, &x, &vo.window_height);
  vo.layout_json = v.layout_json;
  vo.remember = true;
  return pdflab::run_viewer(vo);
}
#else
// Built without the viewer: render the default scene headlessly instead.
int run_viewer_command(const ViewerCommand& v) {
  pdflab::RenderOptions fallback;
  fallback.scene = v.scene.empty() ? pdflab::default_scene_path() : v.scene;
  fallback.strategy = v.strategy;
  fallback.spp = v.spp ? v.spp : 64;
  fallback.out = v.screenshot.empty() ? "pdflab.png" : v.screenshot;
  const int status = pdflab::run_render(fallback);
  std::printf("pdflab was built without the viewer; the image is at %s\n",
              std::filesystem::absolute(fallback.out).c_str());
  return status;
}
#endif

int run_chosen_command(const CommandLine& c) {
  if (c.render.app->parsed()) return pdflab::run_render(typed_render_options(c.render));
  if (c.merge_app->parsed()) return pdflab::run_merge(c.merge);
  if (c.bench_app->parsed()) return pdflab::run_bench(c.bench);
  if (c.reference_app->parsed()) return pdflab::run_reference(c.reference);
  if (c.sweep_app->parsed()) return pdflab::run_sweep(c.sweep);
  if (c.veach_app->parsed()) {
    pdflab::VeachOptions vo = c.veach;
    if (vo.scene.empty()) vo.scene = pdflab::asset_dir() + "/scenes/veach_mis.json";
    return pdflab::run_veach(vo);
  }
  return run_viewer_command(c.viewer);
}

// Bad input is one message and status 2; a failure of the machine (a full
// disk) or of pdflab itself is status 1.
int with_errors_reported(const std::function<int()>& command) {
  try {
    return command();
  } catch (const pdflab::InputError& e) {
    return report_input_error(e.what());
  } catch (const pdflab::IoError& e) {
    std::fprintf(stderr, "pdflab: error: %s\n", e.what());
    return kInternalFailure;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pdflab: internal error: %s\n", pdflab::printable(e.what()).c_str());
    return kInternalFailure;
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pdflab: a laboratory for importance sampling in path tracing"};
  CommandLine command_line;
  define_command_line(app, command_line);
  if (const std::optional<int> status = parse_command_line(app, argc, argv)) return *status;
  return with_errors_reported([&] { return run_chosen_command(command_line); });
}
