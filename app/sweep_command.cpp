#include "app/sweep_command.h"

#include "app/bench_command.h"
#include "app/measured_run.h"
#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/metrics/metrics.h"
#include "renderer/metrics/statistics.h"
#include "renderer/metrics/svg_plot.h"
#include "renderer/metrics/weight_paths.h"
#include "renderer/metrics/weight_prediction.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include <sys/resource.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace pdflab {

namespace {

constexpr int kMaxWeights = 201;

std::string trim(std::string s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.erase(s.begin());
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.pop_back();
  return s;
}

double parse_number(const std::string& text, const std::string& what) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(v))
    throw InputError("--weights: " + what + " '" + text + "' is not a number");
  return v;
}

// LO:HI:STEP, both ends inside [0, 1]; HI is included when the steps reach it.
std::vector<double> parse_weights(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ':')) parts.push_back(trim(part));
  if (parts.size() != 3 || text.back() == ':')
    throw InputError("--weights '" + text + "' is not LO:HI:STEP (for example 0:1:0.1)");
  const double lo = parse_number(parts[0], "LO"), hi = parse_number(parts[1], "HI"),
               step = parse_number(parts[2], "STEP");
  if (lo < 0.0 || hi > 1.0) throw InputError("--weights '" + text + "': the weights must lie in [0, 1]");
  if (!(lo < hi)) throw InputError("--weights '" + text + "': LO must be less than HI");
  if (!(step > 0.0)) throw InputError("--weights '" + text + "': STEP must be positive");
  const double steps = (hi - lo) / step;
  if (steps + 1.0 > kMaxWeights)
    throw InputError("--weights '" + text + "' gives more than " + std::to_string(kMaxWeights) + " weights");
  const int n = static_cast<int>(std::floor(steps + 1e-9)) + 1;
  if (n < 2) throw InputError("--weights '" + text + "': STEP is larger than HI - LO (a sweep needs two weights)");
  std::vector<double> out;
  for (int i = 0; i < n; ++i) out.push_back(std::min(hi, lo + step * i));
  return out;
}

// Two-sided 97.5 % quantiles of Student's t for 1..30 degrees of freedom.
double t_quantile(int dof) {
  static constexpr double kT[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                  2.201,  2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
                                  2.080,  2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
  if (dof < 1) return 0.0;
  return dof <= 30 ? kT[dof - 1] : 1.96;
}

// Mean and the half-width of its 95 % confidence interval over seeds.
// Every quantity here is positive, so the lower bound stops at 0.
struct Interval {
  double mean = 0.0, half = 0.0;
  double low = -1.0, high = -1.0;  // when set (>= 0): bounds that are not mean -+ half
  double lo() const { return low >= 0.0 ? low : std::max(0.0, mean - half); }
  double hi() const { return high >= 0.0 ? high : mean + half; }
};
Interval interval(const std::vector<double>& v) {
  Interval r;
  if (v.empty()) return r;
  for (double x : v) r.mean += x;
  r.mean /= static_cast<double>(v.size());
  if (v.size() < 2) return r;
  double ss = 0.0;
  for (double x : v) ss += (x - r.mean) * (x - r.mean);
  const double sd = std::sqrt(ss / static_cast<double>(v.size() - 1));
  r.half = t_quantile(static_cast<int>(v.size()) - 1) * sd / std::sqrt(static_cast<double>(v.size()));
  return r;
}

// Efficiency from several runs: 1 / (V T), with V the mean over the runs of
// relMSE x spp (the relative variance of one sample per pixel; each run's
// relMSE x spp estimates it without bias whatever its spp, so a run slowed by
// the machine's load counts alike) and T their mean seconds per sample. Not
// the mean of the runs' own efficiencies: 1 / relMSE is convex, so that mean
// sits above 1 / (mean relMSE), by much when relMSE is heavy-tailed (a mixture
// with a small cosine share: most runs miss the rare bright paths and look
// efficient, one in several meets them). The interval maps V's and T's
// Student-t intervals through 1 / (V T), their relative half-widths combined.
Interval pooled_efficiency(const std::vector<double>& relmse_spp, const std::vector<double>& seconds_per_sample) {
  Interval e;
  const Interval v = interval(relmse_spp), t = interval(seconds_per_sample);
  if (!(v.mean > 0.0 && t.mean > 0.0)) {
    e.mean = std::nan("");
    return e;
  }
  e.mean = 1.0 / (v.mean * t.mean);
  const double rel = std::hypot(v.half / v.mean, t.half / t.mean);
  e.low = e.mean / (1.0 + rel);
  e.high = rel < 1.0 ? e.mean / (1.0 - rel) : std::numeric_limits<double>::infinity();
  e.half = 0.5 * (e.high - e.low);
  return e;
}

// Every other value, from `first` (0 or 1): the two halves of a seed list.
std::vector<double> half_of(const std::vector<double>& v, std::size_t first) {
  std::vector<double> out;
  for (std::size_t k = first; k < v.size(); k += 2) out.push_back(v[k]);
  return out;
}

struct Run {
  std::uint32_t spp = 0;
  double seconds = 0.0, relmse = 0.0, efficiency = 0.0, samples_per_second = 0.0;
  double cost_seconds = 0.0;  // what the run is priced by: `seconds`, or its CPU time with --cpu-time
  std::shared_ptr<const GuidingDistribution> guiding;  // what it learned (a mixture with `guided`)
};

// The process's CPU time so far, user and system, over all its threads.
double process_cpu_seconds() {
  rusage usage{};
  if (::getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

Run render_once(const std::shared_ptr<const Scene>& scene, const Strategy& strategy, std::uint64_t seed,
                const SweepOptions& o, const Reference& reference, const std::string& label,
                bool show_progress, std::vector<float>* image = nullptr, std::uint32_t first_sample = 0,
                std::shared_ptr<const GuidingDistribution> guiding = nullptr) {
  const double cpu_start = process_cpu_seconds();
  const MeasuredRun run = render_measured(scene, strategy, seed, {o.seconds, o.spp, o.threads, first_sample, std::move(guiding)},
                                          label, show_progress);
  Run r;
  r.spp = run.stats.spp;
  r.seconds = run.stats.seconds;
  r.cost_seconds = o.cpu_time ? process_cpu_seconds() - cpu_start : r.seconds;
  // Corrected for the reference's own noise when it has a variance (as bench does).
  const std::vector<float> mean = run.film.mean_rgb();
  r.relmse = measure_relmse(mean, reference.rgb, reference.variance).corrected;
  if (image) *image = mean;
  r.efficiency = efficiency(r.relmse, r.cost_seconds);
  r.samples_per_second = run.stats.samples_per_second;
  r.guiding = run.guiding;
  return r;
}

// Auto weight (weight_paths.h): the run is split into AutoWeight's passes
// (1/32, 3/32, 1/8, 1/4, 1/2 of the time or spp); each pass renders at the
// weight the passes before it predicted best, starting at 0.5, and the image
// is their sample-weighted mean. After each pass but the last, until the
// weight has settled (AutoWeight::settled), the prediction
// traces the next few samples of the sequence with the pass's weight through
// the one-path tracer, which records their vertices; they are added to the
// image, and their time counts against the run.
struct AutoRun {
  Run run;
  std::vector<double> weights;  // per pass
  double replay_seconds = 0.0;  // of run.seconds, the time spent predicting
  CostModel cost;               // fitted to the passes' timing
};

AutoRun render_auto(const std::shared_ptr<const Scene>& scene, const TechniquePair& family, const MixtureFamily& mixtures,
                    std::uint64_t seed, const SweepOptions& o, const Reference& reference, const std::string& label,
                    bool show_progress) {
  AutoWeight chooser;
  const std::size_t values = reference.rgb.size();
  std::vector<double> sum(values, 0.0);
  AutoRun out;
  double seconds = 0.0, share = 0.0;
  const double cpu_start = process_cpu_seconds();
  std::uint32_t spp = 0;
  // A mixture with `guided`: the first pass trains (its time counts) and every
  // later one draws from that distribution, fixed before it starts.
  std::shared_ptr<const GuidingDistribution> guiding;
  for (int pass = 0; pass < AutoWeight::kPasses; ++pass) {
    const double w = chooser.weight();
    out.weights.push_back(w);
    // Each pass ends where its share of the run does, counting the samples
    // and time of the predictions before it: the run keeps its budget.
    share += AutoWeight::pass_share(pass);
    SweepOptions slice = o;
    slice.seconds = o.seconds > 0 ? std::max(0.02 * o.seconds, o.seconds * share - seconds) : 0.0;
    const auto target = static_cast<std::uint32_t>(std::lround(o.spp * share));
    slice.spp = o.spp > 0 ? (target > spp ? target - spp : 1) : 0;
    // One seed, each pass continuing the sample indices where the last one
    // stopped: together the passes draw the very pixel positions (one
    // (0,2)-sequence per pixel) and random streams of a fixed-weight run of
    // as many samples; only the weights differ.
    std::vector<float> image;
    const Run r = render_once(scene, family.at(w), seed, slice, reference, label, show_progress, &image, spp, guiding);
    if (!guiding) guiding = r.guiding;
    for (std::size_t i = 0; i < values; ++i) sum[i] += static_cast<double>(image[i]) * r.spp;
    spp += r.spp;
    seconds += r.seconds;
    // A settled weight (two predictions agree) is kept without predicting
    // again; the decision, like the weight, rests on earlier samples only.
    if (pass + 1 == AutoWeight::kPasses || r.spp == 0 || chooser.settled()) continue;
    // The prediction knows what a render knows: the passes so far (their mean
    // image), not the reference. Its paths must not be among the samples of
    // that mean: a path that is also in its pixel's mean raises the mean with
    // its own brightness, so its share of the relative second moment,
    // F^2 / (mu^2 + eps), is held down exactly when F is large, and the
    // prediction leans towards the weight it was drawn at (measured on the
    // glossy box: 0.55-0.65 instead of the 0.75 that independent paths give).
    // So the prediction traces the next samples of the sequence, which then
    // join the image: the run still draws one unbroken sequence of samples.
    const auto start = std::chrono::steady_clock::now();
    std::vector<float> so_far(values);
    for (std::size_t i = 0; i < values; ++i) so_far[i] = static_cast<float>(sum[i] / spp);
    Film traced(scene->camera.width, scene->camera.height);
    WeightPathOptions po;
    po.seed = seed;
    po.first_sample = spp;
    po.samples = AutoWeight::replay_samples(r.spp);
    po.threads = o.threads;
    po.film = &traced;
    po.relative_to = &so_far;  // one image-wide cell: nothing per pixel to allocate
    po.relative_epsilon = kRelMseEpsilon;
    po.guiding = guiding.get();
    const WeightPredictor predictor = record_weight_paths(*scene, mixtures, family.at(w), w, chooser.grid(), po);
    // The pass's own time per sample and its paths' rays feed the cost model.
    chooser.add_pass(predict_image_wide(predictor, so_far, r.cost_seconds / r.spp, kRelMseEpsilon),
                     r.cost_seconds / r.spp);
    const std::vector<float> traced_mean = traced.mean_rgb();
    for (std::size_t i = 0; i < values; ++i) sum[i] += static_cast<double>(traced_mean[i]) * po.samples;
    spp += po.samples;
    const double replay = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    seconds += replay;
    out.replay_seconds += replay;
  }
  std::vector<float> mean(values);
  for (std::size_t i = 0; i < values; ++i) mean[i] = spp > 0 ? static_cast<float>(sum[i] / spp) : 0.0f;
  out.cost = chooser.cost_model();
  out.run.spp = spp;
  out.run.seconds = seconds;
  out.run.cost_seconds = o.cpu_time ? process_cpu_seconds() - cpu_start : seconds;
  out.run.relmse = measure_relmse(mean, reference.rgb, reference.variance).corrected;
  out.run.efficiency = efficiency(out.run.relmse, out.run.cost_seconds);
  return out;
}

// The per-pixel best weight as a picture: each pixel's weight of least
// predicted second moment (relative to the reference, as relMSE weighs it), on
// a blue (0: all B) - white (0.5) - red (1: all A) scale, `scale` x enlarged,
// with the scale as a bar underneath; grey where no recorded path carried
// light or w does not matter. Pixels as linear values that the PNG writer's gamma-2 curve maps to
// the intended colours.
std::vector<std::uint8_t> best_weight_png(const WeightPredictor& predictor, const std::vector<float>& reference,
                                          int width, int height) {
  constexpr int kScale = 6, kBar = 16, kGap = 4;
  const std::vector<float> best = predictor.best_weight_map(reference, kRelMseEpsilon);
  const int w = width * kScale, h = height * kScale + kGap + kBar;
  std::vector<float> rgb(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3, 1.0f);
  auto colour = [](double t, float out[3]) {  // t in 0..1
    const float blue[3] = {0.17f, 0.32f, 0.80f}, white[3] = {0.93f, 0.93f, 0.93f}, red[3] = {0.78f, 0.12f, 0.15f};
    const float* a = t < 0.5 ? blue : white;
    const float* b = t < 0.5 ? white : red;
    const float f = static_cast<float>(t < 0.5 ? t * 2.0 : t * 2.0 - 1.0);
    for (int c = 0; c < 3; ++c) {
      const float v = a[c] + (b[c] - a[c]) * f;
      out[c] = v * v;  // the PNG's gamma 2 takes the square root
    }
  };
  auto put = [&](int x, int y, const float c[3]) {
    float* p = &rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 3];
    p[0] = c[0], p[1] = c[1], p[2] = c[2];
  };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int cell = y * width + x;
      float c[3] = {0.25f, 0.25f, 0.25f};
      // Grey also where w does not matter (a light seen directly), as the viewer's map.
      if (best[static_cast<std::size_t>(cell)] >= 0.0f) colour(best[static_cast<std::size_t>(cell)], c);
      for (int dy = 0; dy < kScale; ++dy)
        for (int dx = 0; dx < kScale; ++dx) put(x * kScale + dx, y * kScale + dy, c);
    }
  for (int x = 0; x < w; ++x) {
    float c[3];
    colour(static_cast<double>(x) / (w - 1), c);
    for (int y = height * kScale + kGap; y < h; ++y) put(x, y, c);
  }
  return encode_png(rgb, w, h, Transfer::Gamma2);
}

struct Row {
  double weight = 0.0;
  Strategy strategy;
  bool unbiased = true;
  std::uint32_t spp = 0;  // the first seed's
  Interval seconds, relmse, efficiency, samples_per_second;
  Interval relmse_spp;  // relMSE x spp: the relative variance of one sample per pixel
  Interval predicted;  // efficiency predicted from the pilot weight's runs
  Interval predicted_relmse_spp;  // the relative variance the pilot's paths predict
  double predicted_rays_only = 0.0;  // the same with a cost of rays alone (no fixed cost per sample)
  double predicted_share = std::nan("");  // the largest pilot path's share of the predicted second moment
  double largest_share = std::nan("");    // the largest seed's share of the row's summed relMSE x spp
};

// "The best fixed weight's efficiency" measured fairly. The best row's mean is
// the largest of several noisy means and so sits high, by up to its
// interval's width. Two estimates that do not pick and measure with the same
// noise: the maximum of a parabola fitted by least squares to the row means
// within 0.2 of the best row (the curve is smooth there, and the fit averages
// the noise of five rows), and the weight chosen on half the seeds, measured
// on the other half (both ways round, averaged).
struct BestFixed {
  double fitted = 0.0, fitted_weight = -1.0;
  double held_out = 0.0;  // 0 with a single seed
};

BestFixed fair_best_fixed(const std::vector<Row>& rows, const std::vector<std::vector<double>>& relmse_spp,
                          const std::vector<std::vector<double>>& per_sample, int best) {
  BestFixed out;
  if (best < 0) return out;
  const double centre = rows[static_cast<std::size_t>(best)].weight;
  out.fitted = rows[static_cast<std::size_t>(best)].efficiency.mean;
  out.fitted_weight = centre;
  // y = c0 + c1 x + c2 x^2 with x = w - centre, by least squares.
  std::vector<double> xs, ys;
  for (const Row& r : rows) {
    const double x = r.weight - centre;
    if (!r.unbiased || std::fabs(x) > 0.2 + 1e-9 || !std::isfinite(r.efficiency.mean)) continue;
    xs.push_back(x);
    ys.push_back(r.efficiency.mean);
  }
  if (const std::optional<std::vector<double>> c = stats::polynomial_fit(xs, ys, 2)) {
    auto at = [&](double x) { return (*c)[0] + (*c)[1] * x + (*c)[2] * x * x; };
    const auto [x_lo, x_hi] = std::minmax_element(xs.begin(), xs.end());
    double x_best = at(*x_lo) > at(*x_hi) ? *x_lo : *x_hi;
    if ((*c)[2] < 0.0) x_best = std::clamp(-(*c)[1] / (2.0 * (*c)[2]), *x_lo, *x_hi);
    if (at(x_best) > 0.0) out.fitted = at(x_best), out.fitted_weight = centre + x_best;
  }
  const std::size_t seeds = relmse_spp.empty() ? 0 : relmse_spp[0].size();
  if (seeds >= 2) {
    auto half_efficiency = [&](std::size_t row, std::size_t half) {
      const double e = pooled_efficiency(half_of(relmse_spp[row], half), half_of(per_sample[row], half)).mean;
      return std::isfinite(e) ? e : 0.0;
    };
    for (std::size_t half = 0; half < 2; ++half) {
      std::size_t chosen = static_cast<std::size_t>(best);
      for (std::size_t i = 0; i < rows.size(); ++i)
        if (rows[i].unbiased && half_efficiency(i, half) > half_efficiency(chosen, half)) chosen = i;
      out.held_out += 0.5 * half_efficiency(chosen, 1 - half);
    }
  }
  return out;
}

// Samples per pixel replayed for the prediction: the pilot run's first ones,
// up to 256 and about 2^19 paths in all (each path is reweighted at every
// weight of a fine grid, so the replay's time grows with paths x grid).
constexpr std::uint32_t kPredictionSpp = 256;
constexpr std::uint64_t kPredictionPaths = std::uint64_t{1} << 19;

// The machine's one-minute load average (-1 when unknown): the sweeps' figures
// are only as steady as the machine they ran on.
double load_average() {
  double load[1] = {-1.0};
  return ::getloadavg(load, 1) == 1 ? load[0] : -1.0;
}

std::string num(double v) {
  if (v == std::numeric_limits<double>::infinity()) return "inf";  // an interval's unbounded end
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// What the runs need, all checked before the first: the weights and their
// strategies (one row each), the scene (sized by the reference), the seeds,
// the reference, and the prediction's pilot row and weight grid.
struct SweepPlan {
  std::vector<double> weights;
  TechniquePair family;
  MixtureFamily mixture_family;
  std::shared_ptr<Scene> scene;
  std::vector<Row> rows;
  std::vector<std::uint64_t> seeds;
  Reference reference;
  // The prediction replays the paths of the runs at one weight, the pilot: the
  // row nearest 0.5 that lies inside the defensive floor (see
  // weight_prediction.h). It predicts on the rows' weights and a fine grid.
  int pilot = -1;
  std::vector<double> grid;
  std::size_t grid_index(double w) const {
    return static_cast<std::size_t>(std::lower_bound(grid.begin(), grid.end(), w) - grid.begin());
  }
};

SweepPlan plan_sweep(const SweepOptions& o) {
  SweepPlan plan;
  plan.weights = parse_weights(o.weights);
  plan.family = parse_technique_pair(o.vary, o.strategy, o.roulette_depth);
  plan.scene = std::make_shared<Scene>(load_scene_file(o.scene));
  // Every strategy of the sweep is checked against the scene before the first render.
  for (double w : plan.weights) {
    Row r;
    r.weight = w;
    r.strategy = plan.family.at(w);
    (void)SamplingPlan::make(r.strategy, *plan.scene);
    r.unbiased = r.strategy.is_unbiased();
    plan.rows.push_back(r);
  }
  for (int k = 0; k < o.seeds; ++k) plan.seeds.push_back(o.seed + static_cast<std::uint64_t>(k));
  std::vector<Strategy> strategies;
  for (const Row& r : plan.rows) strategies.push_back(r.strategy);
  plan.reference = comparison_reference(*plan.scene, reference_choice(o), strategies, plan.seeds, o.quiet);

  const std::vector<Row>& rows = plan.rows;
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (defended_weight(rows[i].weight) == rows[i].weight &&
        (plan.pilot < 0 ||
         std::fabs(rows[i].weight - 0.5) < std::fabs(rows[static_cast<std::size_t>(plan.pilot)].weight - 0.5)))
      plan.pilot = static_cast<int>(i);
  plan.grid = weight_grid(101);
  plan.grid.insert(plan.grid.end(), plan.weights.begin(), plan.weights.end());
  std::sort(plan.grid.begin(), plan.grid.end());
  plan.grid.erase(std::unique(plan.grid.begin(), plan.grid.end()), plan.grid.end());
  plan.mixture_family = plan.family.mixture_family();
  return plan;
}

// Every run's figures, per row (one value per seed), and auto weight's.
struct SweepRuns {
  std::vector<std::vector<double>> seconds, relmse, relmse_spp, samples_per_second, per_sample;
  std::vector<WeightPrediction> predictions;  // one per seed of the pilot
  std::vector<std::uint8_t> map_png;          // from the pilot's first seed
  std::vector<double> auto_relmse_spp, auto_per_sample, auto_relmse, auto_seconds, auto_offset;
  std::vector<std::vector<double>> auto_weights;
};

// The pilot's paths replayed for the prediction (and the map, from its first seed).
void predict_from_pilot(const SweepPlan& plan, const SweepOptions& o, const Row& row, std::uint64_t seed,
                        const Run& run, SweepRuns& runs) {
  WeightPathOptions po;
  po.seed = seed;
  const Scene& scene = *plan.scene;
  const std::uint64_t pixels = static_cast<std::uint64_t>(scene.camera.width) * static_cast<std::uint64_t>(scene.camera.height);
  po.samples = std::min({run.spp, kPredictionSpp,
                         static_cast<std::uint32_t>(std::max<std::uint64_t>(1, (kPredictionPaths + pixels - 1) / pixels))});
  po.threads = o.threads;
  po.guiding = run.guiding.get();  // the pilot's own, frozen: the prediction at every weight uses it
  const WeightPredictor predictor = record_weight_paths(scene, plan.mixture_family, row.strategy, row.weight, plan.grid, po);
  if (!o.map.empty() && runs.map_png.empty())
    runs.map_png = best_weight_png(predictor, plan.reference.rgb, scene.camera.width, scene.camera.height);
  runs.predictions.push_back(predictor.predict(plan.reference.rgb, run.cost_seconds / run.spp, kRelMseEpsilon));
}

// Seed by seed, every weight (and auto weight) in turn: on a machine whose
// speed drifts, each weight's runs are spread over the whole sweep, so the
// drift falls on all weights alike instead of on a few.
SweepRuns run_sweep_runs(SweepPlan& plan, const SweepOptions& o) {
  const bool tty = ::isatty(STDERR_FILENO) != 0;
  const bool show_progress = !o.quiet && tty;
  std::vector<Row>& rows = plan.rows;
  const std::size_t total = rows.size() * static_cast<std::size_t>(o.seeds);
  std::size_t done_runs = 0;
  SweepRuns runs;
  for (auto* v : {&runs.seconds, &runs.relmse, &runs.relmse_spp, &runs.samples_per_second, &runs.per_sample})
    v->resize(rows.size());
  for (int k = 0; k < o.seeds; ++k) {
    const std::uint64_t seed = plan.seeds[static_cast<std::size_t>(k)];
    for (std::size_t i = 0; i < rows.size(); ++i) {
      Row& r = rows[i];
      char label[96];
      std::snprintf(label, sizeof label, "[%zu/%zu] %s=%.3g seed %d/%d", ++done_runs, total, plan.family.a.c_str(),
                    r.weight, k + 1, o.seeds);
      const Run run = render_once(plan.scene, r.strategy, seed, o, plan.reference, label, show_progress);
      if (k == 0) r.spp = run.spp;
      if (static_cast<int>(i) == plan.pilot && run.spp > 0) predict_from_pilot(plan, o, r, seed, run, runs);
      runs.seconds[i].push_back(run.seconds);
      runs.relmse[i].push_back(run.relmse);
      runs.samples_per_second[i].push_back(run.samples_per_second);
      if (run.spp > 0) {
        runs.relmse_spp[i].push_back(run.relmse * run.spp);
        runs.per_sample[i].push_back(run.cost_seconds / run.spp);
      }
      if (!o.quiet && !tty)
        std::fprintf(stderr, "%s: %u spp, %.2f s (priced %.2f s), relMSE %.4g, efficiency %.4g, load %.2f\n", label,
                     run.spp, run.seconds, run.cost_seconds, run.relmse, run.efficiency, load_average());
    }
    if (!o.auto_weight) continue;
    char label[64];
    std::snprintf(label, sizeof label, "[auto] seed %d/%d", k + 1, o.seeds);
    const AutoRun a = render_auto(plan.scene, plan.family, plan.mixture_family, seed, o, plan.reference, label,
                                  show_progress);
    if (a.run.spp > 0) {
      runs.auto_relmse_spp.push_back(a.run.relmse * a.run.spp);
      runs.auto_per_sample.push_back(a.run.cost_seconds / a.run.spp);
    }
    runs.auto_relmse.push_back(a.run.relmse);
    runs.auto_seconds.push_back(a.run.seconds);
    runs.auto_weights.push_back(a.weights);
    runs.auto_offset.push_back(a.cost.offset());
    if (!o.quiet && !tty)
      std::fprintf(stderr, "%s: %u spp, %.2f s (%.3f s predicting; priced %.2f s), relMSE %.4g, efficiency %.4g, load %.2f\n",
                   label, a.run.spp, a.run.seconds, a.replay_seconds, a.run.cost_seconds, a.run.relmse, a.run.efficiency,
                   load_average());
  }
  if (show_progress) std::fputc('\n', stderr);
  return runs;
}

void summarise_rows(std::vector<Row>& rows, const SweepRuns& runs) {
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].seconds = interval(runs.seconds[i]);
    rows[i].relmse = interval(runs.relmse[i]);
    rows[i].relmse_spp = interval(runs.relmse_spp[i]);
    rows[i].efficiency = pooled_efficiency(runs.relmse_spp[i], runs.per_sample[i]);
    rows[i].samples_per_second = interval(runs.samples_per_second[i]);
  }
}

// The cost model (weight_prediction.h): every row's measured seconds per
// sample against the rays per sample that the pilot's paths predict at its
// weight. The rows' weights spread the rays, so their times tell the fixed
// cost per sample from the cost per ray. The pilot's seeds are pooled once
// (pooled_prediction, each counted by its paths): the pool's rays at each
// weight go into the cost fit, and the pool priced by the fitted model is the
// predicted curve (predict_rows).
struct CostFitted {
  std::vector<double> row_rays, row_seconds_per_sample;
  WeightPrediction pooled;
  CostModel model;
};

CostFitted fit_cost(const SweepPlan& plan, SweepRuns& runs) {
  const std::vector<Row>& rows = plan.rows;
  CostFitted c;
  c.row_rays.assign(rows.size(), std::nan(""));
  c.row_seconds_per_sample.assign(rows.size(), std::nan(""));
  c.pooled = pooled_prediction(runs.predictions, kRaysAlone);
  const std::vector<double>& pooled_rays = c.pooled.cost;
  CostFit cost_fit;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    c.row_seconds_per_sample[i] = interval(runs.per_sample[i]).mean;
    if (pooled_rays.empty() || runs.per_sample[i].empty()) continue;
    c.row_rays[i] = pooled_rays[plan.grid_index(rows[i].weight)];
    cost_fit.add(c.row_rays[i], c.row_seconds_per_sample[i]);
  }
  c.model = cost_fit.fit(AutoWeight::kPriorOffset);
  if (c.model.per_ray > 0.0)
    for (WeightPrediction& p : runs.predictions) apply_cost_model(p, c.model);
  return c;
}

// The best weight among the unbiased ones (a biased mixture's error stops
// falling with time, so its efficiency says nothing about longer runs), and
// the weights whose efficiency cannot be told from the best's at 95 %: the
// contiguous run around it whose upper bound reaches the best's lower bound.
struct BestRow {
  int best = -1, band_lo = -1, band_hi = -1;
  double efficiency = 0.0;
};

BestRow best_row(const std::vector<Row>& rows) {
  BestRow b;
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (rows[i].unbiased && std::isfinite(rows[i].efficiency.mean) &&
        (b.best < 0 || rows[i].efficiency.mean > rows[static_cast<std::size_t>(b.best)].efficiency.mean))
      b.best = static_cast<int>(i);
  b.band_lo = b.band_hi = b.best;
  if (b.best >= 0) {
    const double floor_value = rows[static_cast<std::size_t>(b.best)].efficiency.lo();
    while (b.band_lo > 0 && rows[static_cast<std::size_t>(b.band_lo - 1)].unbiased &&
           rows[static_cast<std::size_t>(b.band_lo - 1)].efficiency.hi() >= floor_value)
      --b.band_lo;
    while (b.band_hi + 1 < static_cast<int>(rows.size()) && rows[static_cast<std::size_t>(b.band_hi + 1)].unbiased &&
           rows[static_cast<std::size_t>(b.band_hi + 1)].efficiency.hi() >= floor_value)
      ++b.band_hi;
  }
  b.efficiency = b.best >= 0 ? rows[static_cast<std::size_t>(b.best)].efficiency.mean : 0.0;
  return b;
}

// The predicted curve: pooled over the pilot's seeds (pooled_prediction) as
// the measured rows are, not the mean of each seed's efficiency; priced by the
// cost model, `rays_only` by the pilot's time per ray.
struct PredictedCurve {
  WeightPrediction pooled, rays_only;
  std::vector<double> per_seed_best;  // each seed's own predicted best weight
  int top = -1;                       // the pooled curve's best grid point, inside the defensive floor
  double peak = 0.0;                  // its maximum over the sweep's range, the measured peak's counterpart
  Interval optimum;                   // the best weight: the pooled curve's, +- the seeds' spread
};

PredictedCurve predict_rows(SweepPlan& plan, const SweepRuns& runs, CostFitted& cost) {
  std::vector<Row>& rows = plan.rows;
  const std::vector<double>& grid = plan.grid;
  const std::vector<WeightPrediction>& predictions = runs.predictions;
  PredictedCurve c;
  const double pilot_seconds =
      plan.pilot >= 0 ? cost.row_seconds_per_sample[static_cast<std::size_t>(plan.pilot)] : std::nan("");
  for (const WeightPrediction& p : predictions)
    if (p.best >= 0) c.per_seed_best.push_back(p.best_weight());
  WeightPrediction& pooled = cost.pooled;
  if (pooled.paths > 0) apply_cost_model(pooled, cost.model);  // as pooled_prediction prices a pool with paths
  c.rays_only = pooled;
  if (!predictions.empty()) apply_cost_model(c.rays_only, CostModel{0.0, pilot_seconds / pooled.sampling_cost, false});
  const std::vector<double>& predicted_rays = pooled.cost;
  const std::vector<double>& predicted_curve = pooled.efficiency;
  auto inverse = [](double d) { return std::isfinite(d) && d > 0.0 ? 1.0 / d : 0.0; };
  for (std::size_t g = 0; g < grid.size() && !predictions.empty(); ++g) {
    if (defended_weight(grid[g]) == grid[g] &&
        (c.top < 0 || predicted_curve[g] > predicted_curve[static_cast<std::size_t>(c.top)]))
      c.top = static_cast<int>(g);
    if (grid[g] >= plan.weights.front() - 1e-9 && grid[g] <= plan.weights.back() + 1e-9)
      c.peak = std::max(c.peak, predicted_curve[g]);
  }
  if (c.top >= 0 && !(predicted_curve[static_cast<std::size_t>(c.top)] > 0.0)) c.top = -1;
  for (Row& r : rows) {
    if (predictions.empty()) {
      r.predicted.mean = r.predicted_rays_only = r.predicted_relmse_spp.mean = std::nan("");
      continue;
    }
    const std::size_t g = plan.grid_index(r.weight);
    std::vector<double> values;
    for (const WeightPrediction& p : predictions) values.push_back(p.relative_variance[g]);
    r.predicted_relmse_spp = interval(values);
    const double seconds_here = cost.model.seconds(predicted_rays[g]);
    r.predicted.mean = predicted_curve[g];
    r.predicted.low = inverse(r.predicted_relmse_spp.hi() * seconds_here);
    r.predicted.high = r.predicted_relmse_spp.lo() > 0.0 ? inverse(r.predicted_relmse_spp.lo() * seconds_here)
                                                          : std::numeric_limits<double>::infinity();
    r.predicted_rays_only = c.rays_only.efficiency[g];
    if (!pooled.largest_share.empty()) r.predicted_share = pooled.largest_share[g];
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    double sum = 0.0, top = 0.0;
    for (double v : runs.relmse_spp[i]) sum += v, top = std::max(top, v);
    if (runs.relmse_spp[i].size() > 1 && sum > 0.0) rows[i].largest_share = top / sum;
  }
  c.optimum = interval(c.per_seed_best);
  c.optimum.mean = c.top >= 0 ? grid[static_cast<std::size_t>(c.top)] : std::nan("");
  c.pooled = pooled;
  return c;
}

// The Must-show comparison: the predicted curve over its peak against the
// measured one over its fitted peak, at each row in [0.1, 0.9]; the largest
// gap |predicted / measured - 1|, over all those rows and over those where
// the measured curve is at least 0.3 of its peak (below that, a few rare
// paths decide the measured value); and at how many rows the prediction
// (scaled to the measured peak) lies inside the measured interval.
struct Gap {
  double value = -1.0, at = -1.0;
  void take(double v, double w) {
    if (v > value) value = v, at = w;
  }
};
struct PredictionGaps {
  Gap all, high, light;
  int inside = 0, rows = 0;
  std::string heavy;  // the rows whose prediction one path dominates
};

PredictionGaps prediction_gaps(const std::vector<Row>& rows, const BestFixed& fair, double predicted_peak) {
  PredictionGaps g;
  for (const Row& r : rows) {
    if (!r.unbiased || r.weight < 0.1 - 1e-9 || r.weight > 0.9 + 1e-9 || !(fair.fitted > 0.0) ||
        !(predicted_peak > 0.0) || !std::isfinite(r.predicted.mean) || !(r.efficiency.mean > 0.0))
      continue;
    const double measured = r.efficiency.mean / fair.fitted, predicted = r.predicted.mean / predicted_peak;
    const double gap = std::fabs(predicted / measured - 1.0);
    ++g.rows;
    if (predicted * fair.fitted >= r.efficiency.lo() && predicted * fair.fitted <= r.efficiency.hi()) ++g.inside;
    g.all.take(gap, r.weight);
    if (measured >= 0.3) g.high.take(gap, r.weight);
    if (r.predicted_share <= kDominantShare) g.light.take(gap, r.weight);
  }
  for (const Row& r : rows)
    if (r.predicted_share > kDominantShare) {
      char buf[48];
      std::snprintf(buf, sizeof buf, "%s%.3g (%.0f%%)", g.heavy.empty() ? "" : ", ", r.weight, 100.0 * r.predicted_share);
      g.heavy += buf;
    }
  return g;
}

// Auto weight's runs, pooled as a row's.
struct AutoSummary {
  Interval relmse_spp, efficiency, relmse, seconds;
};

AutoSummary summarise_auto(const SweepRuns& runs) {
  return {interval(runs.auto_relmse_spp), pooled_efficiency(runs.auto_relmse_spp, runs.auto_per_sample),
          interval(runs.auto_relmse), interval(runs.auto_seconds)};
}

// Everything the outputs are made from.
struct SweepResult {
  const SweepPlan& plan;
  const SweepRuns& runs;
  const CostFitted& cost;
  const BestRow& best;
  const BestFixed& fair;
  const PredictedCurve& predicted;
  const PredictionGaps& gaps;
  const AutoSummary& automatic;
};

std::string sweep_csv(const SweepOptions& o, const SweepResult& s) {
  const std::vector<Row>& rows = s.plan.rows;
  const BestRow& b = s.best;
  const double peak = s.predicted.peak;
  std::string csv =
      "weight,strategy,unbiased,seeds,spp,seconds,relmse,relmse_lo,relmse_hi,efficiency,efficiency_lo,efficiency_hi,"
      "relative_efficiency,samples_per_second,samples_per_second_lo,samples_per_second_hi,predicted_efficiency,"
      "predicted_efficiency_lo,predicted_efficiency_hi,predicted_relative_efficiency,best,in_best_interval,rays_per_sample,seconds_per_sample,"
      "model_seconds_per_sample,predicted_efficiency_rays_only,relmse_per_sample,relmse_per_sample_lo,relmse_per_sample_hi,"
      "predicted_relmse_per_sample,predicted_largest_share,relmse_largest_share\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    const int idx = static_cast<int>(i);
    csv += num(r.weight) + ",\"" + r.strategy.to_string() + "\"," + (r.unbiased ? "1" : "0") + "," +
           std::to_string(o.seeds) + "," + std::to_string(r.spp) + "," + num(r.seconds.mean) + "," +
           num(r.relmse.mean) + "," + num(r.relmse.lo()) + "," + num(r.relmse.hi()) + "," + num(r.efficiency.mean) +
           "," + num(r.efficiency.lo()) + "," + num(r.efficiency.hi()) + "," +
           num(b.efficiency > 0 ? r.efficiency.mean / b.efficiency : std::nan("")) + "," +
           num(r.samples_per_second.mean) + "," + num(r.samples_per_second.lo()) + "," +
           num(r.samples_per_second.hi()) + "," + num(r.predicted.mean) + "," + num(r.predicted.lo()) + "," +
           num(r.predicted.hi()) + "," +
           num(peak > 0 && r.unbiased ? r.predicted.mean / peak : std::nan("")) + "," +
           (idx == b.best ? "1" : "0") + "," +
           (b.best >= 0 && idx >= b.band_lo && idx <= b.band_hi ? "1" : "0") + "," + num(s.cost.row_rays[i]) + "," +
           num(s.cost.row_seconds_per_sample[i]) + "," +
           num(std::isfinite(s.cost.row_rays[i]) ? s.cost.model.seconds(s.cost.row_rays[i]) : std::nan("")) + "," +
           num(r.predicted_rays_only) + "," + num(r.relmse_spp.mean) + "," + num(r.relmse_spp.lo()) + "," +
           num(r.relmse_spp.hi()) + "," + num(r.predicted_relmse_spp.mean) + "," + num(r.predicted_share) + "," +
           num(r.largest_share) + "\n";
  }
  if (o.auto_weight) {
    const AutoSummary& a = s.automatic;
    std::string history;
    for (double w : s.runs.auto_weights[0]) history += (history.empty() ? "" : ">") + num(w);
    csv += num(s.runs.auto_weights[0].back()) + ",\"auto:" + history + "\",1," + std::to_string(o.seeds) + ",," +
           num(a.seconds.mean) + "," + num(a.relmse.mean) + "," + num(a.relmse.lo()) + "," +
           num(a.relmse.hi()) + "," + num(a.efficiency.mean) + "," + num(a.efficiency.lo()) + "," +
           num(a.efficiency.hi()) + "," +
           num(b.efficiency > 0 ? a.efficiency.mean / b.efficiency : std::nan("")) + ",,,,,,,,0,0,,,,," +
           num(a.relmse_spp.mean) + "," + num(a.relmse_spp.lo()) + "," + num(a.relmse_spp.hi()) + ",,,\n";
  }
  return csv;
}

std::string sweep_plot(const SweepOptions& o, const SweepResult& s) {
  const SweepPlan& plan = s.plan;
  const std::vector<Row>& rows = plan.rows;
  const std::vector<double>& grid = plan.grid;
  const BestRow& b = s.best;
  const WeightPrediction& pooled = s.predicted.pooled;
  const std::vector<double>& predicted_curve = pooled.efficiency;
  PlotSeries measured;
  measured.label = "measured (95% interval over " + std::to_string(o.seeds) + " seeds)";
  for (const Row& r : rows) {
    if (!r.unbiased) continue;
    measured.x.push_back(r.weight);
    measured.y.push_back(r.efficiency.mean);
    measured.y_lo.push_back(r.efficiency.lo());
    measured.y_hi.push_back(r.efficiency.hi());
  }
  PlotOptions po;
  po.title = "Efficiency against the weight of " + plan.family.a + " (vs " + plan.family.b + "): " + plan.scene->name;
  po.x_label = "weight of " + plan.family.a + " (share of " + plan.family.a + " + " + plan.family.b + ")";
  po.y_label = o.cpu_time ? "efficiency = 1 / (relMSE * CPU seconds)" : "efficiency = 1 / (relMSE * seconds)";
  po.width = 900;
  po.height = 520;
  po.x_min = plan.weights.front();
  po.x_max = plan.weights.back();
  if (b.best >= 0) {
    po.marker_x = rows[static_cast<std::size_t>(b.best)].weight;
    po.marker_lo = rows[static_cast<std::size_t>(b.band_lo)].weight;
    po.marker_hi = rows[static_cast<std::size_t>(b.band_hi)].weight;
    char buf[96];
    std::snprintf(buf, sizeof buf, "best %.3g (band %.3g..%.3g)", po.marker_x, po.marker_lo, po.marker_hi);
    po.marker_label = buf;
  }
  std::vector<PlotSeries> series = {measured};
  if (!s.runs.predictions.empty()) {
    PlotSeries predicted;
    char buf[128];
    std::snprintf(buf, sizeof buf, "predicted from w = %.3g (best %.3g)", rows[static_cast<std::size_t>(plan.pilot)].weight,
                  s.predicted.optimum.mean);
    predicted.label = buf;
    predicted.dashed = true;
    // The weights whose prediction one path dominates drawn apart: there it
    // is likely too high (the sweep's stdout says why).
    PlotSeries tail;
    char tail_label[96];
    std::snprintf(tail_label, sizeof tail_label, "predicted, one path > %.0f%%: likely too high", 100.0 * kDominantShare);
    tail.label = tail_label;
    tail.dashed = true;
    const auto dominated = [&](std::size_t i) {
      return i < pooled.largest_share.size() && pooled.largest_share[i] > kDominantShare;
    };
    for (std::size_t g = 0; g < grid.size(); ++g) {
      if (!(grid[g] >= plan.weights.front() && grid[g] <= plan.weights.back() && predicted_curve[g] > 0.0)) continue;
      // A gap (NaN) in each line where the other runs; a trusted point next
      // to a dominated one is in both, so the curve stays whole.
      const bool here = dominated(g), beside = (g > 0 && dominated(g - 1)) || dominated(g + 1);
      predicted.x.push_back(grid[g]), predicted.y.push_back(here ? std::nan("") : predicted_curve[g]);
      tail.x.push_back(grid[g]), tail.y.push_back(here || beside ? predicted_curve[g] : std::nan(""));
    }
    series.push_back(predicted);
    if (std::any_of(tail.y.begin(), tail.y.end(), [](double v) { return std::isfinite(v); })) series.push_back(tail);
  }
  return linear_svg(series, po);
}

void write_sweep_files(const SweepOptions& o, const SweepResult& s) {
  const std::string csv = sweep_csv(o, s);
  const std::string plot = o.plot.empty() ? std::string() : sweep_plot(o, s);
  write_file_atomic(o.csv, {reinterpret_cast<const std::uint8_t*>(csv.data()), csv.size()});
  if (!o.map.empty() && !s.runs.map_png.empty()) write_file_atomic(o.map, s.runs.map_png);
  if (!o.plot.empty()) write_file_atomic(o.plot, {reinterpret_cast<const std::uint8_t*>(plot.data()), plot.size()});
}

void print_sweep_table(const SweepOptions& o, const SweepResult& s, double load_at_start) {
  const SweepPlan& plan = s.plan;
  const std::vector<Row>& rows = plan.rows;
  const BestRow& b = s.best;
  const BestFixed& fair = s.fair;
  const CostModel& cost_model = s.cost.model;
  const PredictionGaps& gaps = s.gaps;
  std::printf("%-8s %-40s %6s %10s %22s %10s %11s %9s\n", "weight", "strategy", "spp", "relmse", "efficiency (95%)",
              "vs best", "predicted", "Msamp/s");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    char eff_text[64];
    std::snprintf(eff_text, sizeof eff_text, "%.4g [%.3g, %.3g]", r.efficiency.mean, r.efficiency.lo(), r.efficiency.hi());
    std::printf("%-8.3g %-40s %6u %10.4g %22s %9.2fx %11.4g %9.3f%s%s\n", r.weight, r.strategy.to_string().c_str(),
                r.spp, r.relmse.mean, eff_text, b.efficiency > 0 ? r.efficiency.mean / b.efficiency : 0.0,
                r.predicted.mean, r.samples_per_second.mean * 1e-6, r.unbiased ? "" : "  (biased)",
                static_cast<int>(i) == b.best ? "  <- best" : "");
  }
  if (b.best >= 0)
    std::printf("best weight of %s: %.3g; indistinguishable at 95%%: %.3g..%.3g\n", plan.family.a.c_str(),
                rows[static_cast<std::size_t>(b.best)].weight, rows[static_cast<std::size_t>(b.band_lo)].weight,
                rows[static_cast<std::size_t>(b.band_hi)].weight);
  else
    std::printf("no weight of the sweep gives an unbiased mixture\n");
  if (b.best >= 0)
    std::printf("best fixed weight's efficiency, fairly: %.4g at %.3g (the parabola through the rows within 0.2), "
                "%.4g (chosen on half the seeds, measured on the others); the best row's mean %.4g\n",
                fair.fitted, fair.fitted_weight, fair.held_out, b.efficiency);
  if (cost_model.per_ray > 0.0)
    std::printf("cost model: seconds per sample = %.4g + %.4g x rays (a fixed cost of %.2f rays; %s)\n",
                cost_model.per_sample, cost_model.per_ray, cost_model.offset(),
                cost_model.fitted ? "fitted to the rows' timing" : "too little spread to fit: the prior");
  if (o.auto_weight) {
    const Interval& auto_efficiency = s.automatic.efficiency;
    std::printf("auto weight against the fair best fixed: %.0f%% (%.0f..%.0f%%) of the fitted, %.0f%% of the held-out;"
                " its fitted fixed costs, rays:",
                fair.fitted > 0 ? 100.0 * auto_efficiency.mean / fair.fitted : 0.0,
                fair.fitted > 0 ? 100.0 * auto_efficiency.lo() / fair.fitted : 0.0,
                fair.fitted > 0 ? 100.0 * auto_efficiency.hi() / fair.fitted : 0.0,
                fair.held_out > 0 ? 100.0 * auto_efficiency.mean / fair.held_out : 0.0);
    for (double v : s.runs.auto_offset) std::printf(" %.2f", v);
    std::printf("\n");
    std::printf("auto weight: efficiency %.4g [%.3g, %.3g], %.0f%% of the best fixed weight's; weights per pass:",
                auto_efficiency.mean, auto_efficiency.lo(), auto_efficiency.hi(),
                b.efficiency > 0 ? 100.0 * auto_efficiency.mean / b.efficiency : 0.0);
    for (const auto& h : s.runs.auto_weights) {
      std::printf(" ");
      for (std::size_t i = 0; i < h.size(); ++i) std::printf("%s%.3g", i ? ">" : "", h[i]);
    }
    std::printf("\n");
  }
  if (!s.runs.predictions.empty())
    std::printf("predicted best weight (from the paths at %.3g, %zu seeds pooled): %.3g; each seed's alone: %.3g +- %.2g\n",
                rows[static_cast<std::size_t>(plan.pilot)].weight, s.runs.predictions.size(), s.predicted.optimum.mean,
                interval(s.predicted.per_seed_best).mean, s.predicted.optimum.half);
  else
    std::printf("no prediction: no weight of the sweep lies inside [%.2g, %.2g]\n", kDefensiveFloor,
                1.0 - kDefensiveFloor);
  if (gaps.rows > 0)
    std::printf("predicted relative efficiency against measured, %d weights in [0.1, 0.9]: largest gap %.0f%% (at %.3g); "
                "%.0f%% (at %.3g) where measured is at least 0.3 of its peak; inside the measured 95%% interval at %d of %d\n",
                gaps.rows, 100.0 * gaps.all.value, gaps.all.at, 100.0 * std::max(0.0, gaps.high.value), gaps.high.at,
                gaps.inside, gaps.rows);
  if (gaps.light.value >= 0.0)
    std::printf("  where no single path carries more than %.0f%% of the predicted second moment: largest gap %.0f%% (at %.3g)\n",
                100.0 * kDominantShare, 100.0 * gaps.light.value, gaps.light.at);
  if (!gaps.heavy.empty())
    std::printf("one path carries more than %.0f%% of the predicted second moment at %s: there the moment is infinite or "
                "carried by paths too rare for the runs to hold, so the predicted and the measured efficiency are "
                "likely too high\n",
                100.0 * kDominantShare, gaps.heavy.c_str());
  std::printf("load average (1 min): %.2f at the start, %.2f at the end; runs priced by %s\n", load_at_start,
              load_average(), o.cpu_time ? "their CPU time (--cpu-time)" : "the wall clock");
}

}  // namespace

int run_sweep(const SweepOptions& o) {
  check_comparison_options(o, {o.map});
  if (o.seeds < 1 || o.seeds > 1000) throw InputError("--seeds must be in 1..1000");
  SweepPlan plan = plan_sweep(o);
  const double load_at_start = load_average();
  SweepRuns runs = run_sweep_runs(plan, o);
  summarise_rows(plan.rows, runs);
  CostFitted cost = fit_cost(plan, runs);
  const AutoSummary automatic = summarise_auto(runs);
  const BestRow best = best_row(plan.rows);
  const BestFixed fair = fair_best_fixed(plan.rows, runs.relmse_spp, runs.per_sample, best.best);
  const PredictedCurve predicted = predict_rows(plan, runs, cost);
  const PredictionGaps gaps = prediction_gaps(plan.rows, fair, predicted.peak);
  const SweepResult result{plan, runs, cost, best, fair, predicted, gaps, automatic};
  write_sweep_files(o, result);
  print_sweep_table(o, result, load_at_start);
  return 0;
}

}  // namespace pdflab
