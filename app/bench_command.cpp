#include "app/bench_command.h"

#include "app/measured_run.h"

#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/metrics/metrics.h"
#include "renderer/metrics/svg_plot.h"
#include "renderer/metrics/weight_paths.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <thread>

namespace pdflab {

namespace {

struct Checkpoint {
  std::uint32_t spp;
  double seconds, rmse, relmse, relmse_raw;  // relmse: corrected for the reference's noise
};

struct Result {
  Strategy strategy;
  std::uint32_t spp = 0;
  double seconds = 0, rmse = 0, efficiency = 0, samples_per_second = 0;
  RelMseMeasure error;  // relmse: error.corrected
  double estimated_relmse = 0;  // the film's own prediction, for comparison with the measured relmse
  std::uint64_t dropped = 0;
  std::vector<Checkpoint> curve;
  double weight = -1.0;     // with --predict: A's share of the pair; -1 outside the family
  double predicted = -1.0;  // the efficiency predicted from the pilot's paths; -1: none
  double predicted_share = -1.0;  // the largest pilot path's share of that prediction's second moment; -1: none
  std::shared_ptr<const GuidingDistribution> guiding;  // what the run learned (a strategy with `guided`)
};

// Samples per pixel of the pilot's run replayed for the prediction (as sweep).
constexpr std::uint32_t kPredictionSpp = 256;

// --predict A,B: the family is the first strategy of the list that mixes both
// (its other techniques keep their weights); the pilot is the member nearest
// w = 0.5 inside the defensive floor. -1 when no member is inside the floor.
struct Prediction {
  TechniquePair pair;
  int pilot = -1;
  std::vector<double> weights;  // per strategy, -1 for a non-member
};

Prediction plan_prediction(const std::string& predict, const std::vector<Strategy>& strategies) {
  Prediction p;
  TechniquePair probe = parse_technique_pair(predict);
  bool found = false;
  for (const Strategy& s : strategies) {
    double a = 0.0, b = 0.0;
    Strategy terms_only = s;
    terms_only.roulette_depth = 0;
    for (const auto& [name, weight] : mixture_terms(terms_only)) {
      if (name == probe.a) a += weight;
      if (name == probe.b) b += weight;
    }
    if (!s.nee_mis && a > 0.0 && b > 0.0) {
      p.pair = parse_technique_pair(predict, s.to_string());
      found = true;
      break;
    }
  }
  if (!found) throw InputError("--predict '" + predict + "': no strategy in --strategies mixes " + probe.a + " and " + probe.b);
  for (std::size_t i = 0; i < strategies.size(); ++i) {
    const double w = p.pair.weight_of(strategies[i]);
    p.weights.push_back(w);
    if (w >= 0.0 && defended_weight(w) == w &&
        (p.pilot < 0 || std::fabs(w - 0.5) < std::fabs(p.weights[static_cast<std::size_t>(p.pilot)] - 0.5)))
      p.pilot = static_cast<int>(i);
  }
  if (p.pilot < 0) {
    char range[64];
    std::snprintf(range, sizeof range, "[%.2g, %.2g]", kDefensiveFloor, 1.0 - kDefensiveFloor);
    throw InputError("--predict '" + predict + "': no mixture of " + p.pair.a + " and " + p.pair.b +
                     " in --strategies gives " + p.pair.a + " a share inside " + range + " to predict from");
  }
  return p;
}

std::vector<Strategy> parse_strategy_list(const std::string& text, int roulette_depth) {
  std::vector<Strategy> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ';'))
    if (item.find_first_not_of(" \t") != std::string::npos) out.push_back(with_roulette(Strategy::parse(item), roulette_depth));
  if (out.empty()) throw InputError("--strategies lists no strategy (separate them with ';')");
  return out;
}

std::string csv_field(const std::string& s) { return "\"" + s + "\""; }

// A figure that may be absent (negative): empty in the CSV.
std::string optional_number(double v) {
  if (!(v >= 0.0) || !std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

void write_text(const std::string& path, const std::string& text) {
  write_file_atomic(path, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
}

Result run_one(const std::shared_ptr<const Scene>& scene, const Strategy& strategy, const BenchOptions& o,
               const Reference& reference, const std::string& progress_prefix, bool show_progress) {
  Result r;
  r.strategy = strategy;
  std::vector<float> image;
  std::uint64_t version = 0;
  char label[128];
  std::snprintf(label, sizeof label, "%s %-32s", progress_prefix.c_str(), strategy.to_string().c_str());
  const MeasuredRun run = render_measured(scene, strategy, o.seed, {o.seconds, o.spp, o.threads}, label, show_progress,
                                          [&](RenderSession& session) {
    ImageInfo info;
    // The info describes the very image copied (its pass's spp and time); previews are not estimates,
    // and path guiding's training passes are discarded.
    if (session.copy_image(image, info, version) && !info.preview && info.training_pass == 0 && info.spp > 0) {
      const RelMseMeasure m = measure_relmse(image, reference.rgb, reference.variance);
      r.curve.push_back({info.spp, info.seconds, rmse(image, reference.rgb), m.corrected, m.raw});
    }
  });
  const SessionStats& st = run.stats;
  const std::vector<float> final_image = run.film.mean_rgb();
  r.spp = st.spp;
  r.seconds = st.seconds;
  r.rmse = rmse(final_image, reference.rgb);
  r.error = measure_relmse(final_image, reference.rgb, reference.variance);
  r.efficiency = efficiency(r.error.corrected, r.seconds);
  r.estimated_relmse = estimated_relmse(run.film);
  r.samples_per_second = st.samples_per_second;
  r.guiding = run.guiding;
  r.dropped = st.dropped.total();
  if (r.curve.empty() || r.curve.back().spp != r.spp)
    r.curve.push_back({r.spp, r.seconds, r.rmse, r.error.corrected, r.error.raw});
  return r;
}


// What the runs need, all checked before the first: the scene (sized by the
// reference), the strategies, the --predict family and the reference.
struct BenchPlan {
  std::shared_ptr<Scene> scene;
  std::vector<Strategy> strategies;
  Prediction prediction;
  Reference reference;
};

BenchPlan plan_bench(const BenchOptions& o) {
  BenchPlan plan;
  plan.scene = std::make_shared<Scene>(load_scene_file(o.scene));
  plan.strategies = parse_strategy_list(o.strategies, o.roulette_depth);
  for (Strategy& s : plan.strategies) s = for_scene(s, *plan.scene);
  for (const Strategy& s : plan.strategies) (void)SamplingPlan::make(s, *plan.scene);
  plan.prediction = o.predict.empty() ? Prediction{} : plan_prediction(o.predict, plan.strategies);
  plan.reference = comparison_reference(*plan.scene, reference_choice(o), plan.strategies, {o.seed}, o.quiet);
  return plan;
}

void note_biased_strategies(const std::vector<Strategy>& strategies, bool quiet) {
  if (quiet) return;
  for (const Strategy& s : strategies)
    if (!s.is_unbiased())
      std::fprintf(stderr,
                   "note: strategy '%s' is biased (%s): its error against the reference stops falling with time\n",
                   s.to_string().c_str(), s.bias_reason().c_str());
}

std::vector<Result> run_strategies(const BenchPlan& plan, const BenchOptions& o) {
  const bool show_progress = !o.quiet && ::isatty(STDERR_FILENO);
  std::vector<Result> results;
  for (std::size_t i = 0; i < plan.strategies.size(); ++i) {
    char prefix[48];
    std::snprintf(prefix, sizeof prefix, "[%zu/%zu]", i + 1, plan.strategies.size());
    results.push_back(run_one(plan.scene, plan.strategies[i], o, plan.reference, prefix, show_progress));
  }
  if (show_progress) std::fputc('\n', stderr);
  return results;
}

// --predict: each member's predicted efficiency into its result; returns the
// predicted best weight (-1 without a prediction).
double predict_members(const BenchPlan& plan, const BenchOptions& o, std::vector<Result>& results) {
  const Prediction& prediction = plan.prediction;
  if (prediction.pilot < 0 || results[static_cast<std::size_t>(prediction.pilot)].spp == 0) return -1.0;
  // Replays the pilot's first samples (same seed and indices: the very paths
  // it drew) and predicts on a grid of 0.01 and on every member's weight.
  const Result& pilot = results[static_cast<std::size_t>(prediction.pilot)];
  const double w = prediction.weights[static_cast<std::size_t>(prediction.pilot)];
  std::vector<double> grid = weight_grid(101);
  for (double m : prediction.weights)
    if (m >= 0.0) grid.push_back(m);
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  WeightPathOptions po;
  po.seed = o.seed;
  po.samples = std::min(pilot.spp, kPredictionSpp);
  po.threads = o.threads;
  po.guiding = pilot.guiding.get();  // the pilot's own, frozen: the prediction at every weight uses it
  const WeightPredictor predictor =
      record_weight_paths(*plan.scene, prediction.pair.mixture_family(), pilot.strategy, w, grid, po);
  const double seconds_per_sample = pilot.seconds / pilot.spp;
  WeightPrediction p = predictor.predict(plan.reference.rgb, seconds_per_sample, kRelMseEpsilon);
  // The cost model (weight_prediction.h): the members' measured seconds per
  // sample against the rays per sample predicted at their weights give the
  // fixed cost's share; the time stays anchored at the pilot's own, so that a
  // few short, noisy runs cannot move the prediction at the pilot's weight.
  CostFit cost_fit;
  for (std::size_t i = 0; i < results.size(); ++i)
    if (prediction.weights[i] >= 0.0 && results[i].spp > 0) {
      const auto g = std::lower_bound(grid.begin(), grid.end(), prediction.weights[i]) - grid.begin();
      cost_fit.add(p.cost[static_cast<std::size_t>(g)], results[i].seconds / results[i].spp);
    }
  const double offset = std::clamp(cost_fit.fit(AutoWeight::kPriorOffset).offset(), 0.0, 10.0);
  // Re-priced, not predicted again: the pilot's time per sample split with
  // that fixed cost.
  const CostModel model = anchored_cost_model(p.sampling_cost, seconds_per_sample, offset);
  if (model.per_ray > 0.0) apply_cost_model(p, model);
  for (std::size_t i = 0; i < results.size(); ++i)
    if (prediction.weights[i] >= 0.0) {
      results[i].weight = prediction.weights[i];
      const auto g = std::lower_bound(grid.begin(), grid.end(), prediction.weights[i]) - grid.begin();
      results[i].predicted = p.efficiency[static_cast<std::size_t>(g)];
      if (static_cast<std::size_t>(g) < p.largest_share.size() && std::isfinite(p.largest_share[static_cast<std::size_t>(g)]))
        results[i].predicted_share = p.largest_share[static_cast<std::size_t>(g)];
    }
  return p.best_weight();
}

// est_relmse: what the film predicts without a reference; unbiased: 0 for a
// strategy whose pdf misses directions the integrand needs.
// relmse is corrected for the reference's own noise, relmse_raw is not;
// relmse_ci: 95% half width of relmse; ref_share: the reference's part of relmse_raw;
// roulette_depth: where Russian roulette starts (0: off).
std::string results_csv(const std::vector<Result>& results) {
  std::string csv =
      "strategy,spp,seconds,rmse,relmse,efficiency,samples_per_second,dropped,est_relmse,unbiased,relmse_raw,"
      "relmse_ci,ref_share,roulette_depth,weight,predicted_efficiency,predicted_largest_share\n";
  char line[512];
  for (const Result& r : results) {
    std::snprintf(line, sizeof line, ",%u,%.6g,%.6g,%.6g,%.6g,%.6g,%llu,%.6g,%d,%.6g,%.6g,%.6g,%d,", r.spp, r.seconds,
                  r.rmse, r.error.corrected, r.efficiency, r.samples_per_second,
                  static_cast<unsigned long long>(r.dropped), r.estimated_relmse, r.strategy.is_unbiased() ? 1 : 0,
                  r.error.raw, r.error.interval, r.error.reference_share(), r.strategy.roulette_depth);
    csv += csv_field(r.strategy.to_string()) + line + optional_number(r.weight) + "," + optional_number(r.predicted) + "," +
           optional_number(r.predicted_share) + "\n";
  }
  return csv;
}

std::string curves_csv(const std::vector<Result>& results) {
  std::string curves = "strategy,spp,seconds,rmse,relmse,relmse_raw\n";
  char line[512];
  for (const Result& r : results)
    for (const Checkpoint& k : r.curve) {
      std::snprintf(line, sizeof line, ",%u,%.6g,%.6g,%.6g,%.6g\n", k.spp, k.seconds, k.rmse, k.relmse, k.relmse_raw);
      curves += csv_field(r.strategy.to_string()) + line;
    }
  return curves;
}

std::string rmse_plot(const std::vector<Result>& results, const std::string& scene_name) {
  std::vector<PlotSeries> series;
  for (const Result& r : results) {
    PlotSeries s;
    s.label = r.strategy.to_string() + (r.strategy.is_unbiased() ? "" : " (biased)");
    for (const Checkpoint& k : r.curve) {
      s.x.push_back(k.seconds);
      s.y.push_back(k.rmse);
    }
    series.push_back(std::move(s));
  }
  PlotOptions po;
  po.title = "RMSE against time: " + scene_name;
  po.x_label = "seconds";
  po.y_label = "RMSE vs reference";
  po.guide_slope = -0.5;
  po.guide_label = "1/sqrt(N)";
  po.width = 900;
  po.height = 520;
  return loglog_svg(series, po);
}

// Every text is built before the first is written, so only an I/O failure
// can leave one file without the others.
void write_bench_files(const BenchOptions& o, const std::vector<Result>& results, const std::string& scene_name) {
  const std::string csv = results_csv(results);
  const std::string curves = o.curves.empty() ? std::string() : curves_csv(results);
  const std::string plot = o.plot.empty() ? std::string() : rmse_plot(results, scene_name);
  write_text(o.csv, csv);
  if (!o.curves.empty()) write_text(o.curves, curves);
  if (!o.plot.empty()) write_text(o.plot, plot);
}

// The table: efficiency relative to the first strategy says which PDF wins.
void print_bench_table(const BenchPlan& plan, const std::vector<Result>& results, double predicted_best) {
  const Prediction& prediction = plan.prediction;
  const bool predicted = prediction.pilot >= 0;
  std::printf("%-36s %7s %8s %10s %10s %9s %10s %7s %10s %11s %8s %9s %8s%s\n", "strategy", "spp", "seconds", "rmse",
              "relmse", "+-", "raw", "ref %", "est relmse", "efficiency", "vs first", "Msamp/s", "dropped",
              predicted ? "   predicted" : "");
  for (const Result& r : results) {
    const double ratio = results[0].efficiency > 0 ? r.efficiency / results[0].efficiency : 0.0;
    char guess[32] = "";
    if (predicted && r.predicted >= 0.0)
      std::snprintf(guess, sizeof guess, " %10.4g%s", r.predicted, r.predicted_share > kDominantShare ? "*" : " ");
    else if (predicted) std::snprintf(guess, sizeof guess, " %11s", "-");
    std::printf("%-36s %7u %8.2f %10.4g %10.4g %9.2g %10.4g %6.1f%% %10.4g %11.4g %7.2fx %9.3f %8llu%s%s\n",
                r.strategy.to_string().c_str(), r.spp, r.seconds, r.rmse, r.error.corrected, r.error.interval,
                r.error.raw, 100.0 * r.error.reference_share(), r.estimated_relmse, r.efficiency, ratio,
                r.samples_per_second * 1e-6, static_cast<unsigned long long>(r.dropped), guess,
                r.strategy.is_unbiased() ? "" : "  (biased)");
  }
  std::printf("relMSE = mean (x - ref)^2 / (ref^2 + %.0e) %s, +- its 95%% interval; raw: uncorrected; ref %%: the "
              "reference's own noise as a share of raw; efficiency = 1 / (relMSE * seconds); est relmse: the film's "
              "own prediction, no reference\n",
              kRelMseEpsilon,
              plan.reference.has_variance() ? "minus the reference's own noise"
                                            : "(the reference has no variance: uncorrected)");
  if (predicted)
    std::printf("predicted: efficiency of each mixture of %s and %s from the paths of %s (%s's share %.3g); predicted "
                "best share of %s: %.3g\n",
                prediction.pair.a.c_str(), prediction.pair.b.c_str(),
                plan.strategies[static_cast<std::size_t>(prediction.pilot)].to_string().c_str(),
                prediction.pair.a.c_str(), prediction.weights[static_cast<std::size_t>(prediction.pilot)],
                prediction.pair.a.c_str(), predicted_best);
  bool dominated = false;
  for (const Result& r : results) dominated = dominated || r.predicted_share > kDominantShare;
  if (dominated)
    std::printf("*: one path carries more than %.0f%% of that prediction's second moment: there the moment is infinite or "
                "carried by paths too rare for the replay, and the predicted efficiency is likely too high\n",
                100.0 * kDominantShare);
}

}  // namespace

int run_bench(const BenchOptions& o) {
  check_comparison_options(o, {o.curves});
  const BenchPlan plan = plan_bench(o);
  note_biased_strategies(plan.strategies, o.quiet);
  std::vector<Result> results = run_strategies(plan, o);
  const double predicted_best = predict_members(plan, o, results);
  write_bench_files(o, results, plan.scene->name);
  print_bench_table(plan, results, predicted_best);
  return 0;
}

}  // namespace pdflab
