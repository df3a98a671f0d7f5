#include "renderer/metrics/weight_paths.h"

#include "renderer/integrator/integrator.h"

#include "renderer/error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <thread>

namespace pdflab {

std::vector<std::pair<std::string, double>> mixture_terms(const Strategy& s) {
  // The text, not the strategy's fields: nothing here depends on how a
  // strategy stores its weights.
  const std::string text = s.to_string();
  if (text.rfind("mix:", 0) != 0) return {{text, 1.0}};
  std::vector<std::pair<std::string, double>> terms;
  std::stringstream ss(text.substr(4));
  std::string term;
  while (std::getline(ss, term, ',')) {
    const std::size_t eq = term.find('=');
    terms.emplace_back(term.substr(0, eq), std::stod(term.substr(eq + 1)));
  }
  return terms;
}

namespace {

std::string trimmed(std::string s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.erase(s.begin());
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.pop_back();
  return s;
}

}  // namespace

Strategy TechniquePair::at(double w) const {
  char buf[64];
  std::string text = "mix:";
  std::snprintf(buf, sizeof buf, "%s=%.9g,%s=%.9g", a.c_str(), share * w, b.c_str(), share * (1.0 - w));
  text += buf;
  for (const auto& [name, weight] : rest) {
    std::snprintf(buf, sizeof buf, ",%s=%.9g", name.c_str(), weight);
    text += buf;
  }
  Strategy s = with_roulette(Strategy::parse(text), roulette_depth);
  s.guided_roulette = guided_roulette_holds(s, guided_roulette);
  return s;
}

MixtureFamily TechniquePair::mixture_family() const {
  MixtureFamily m;
  m.a = Strategy::parse(a);
  m.b = Strategy::parse(b);
  m.share = rest.empty() ? 1.0 : share;
  if (!rest.empty()) {
    std::string text = "mix:";
    for (const auto& [name, weight] : rest) text += (text.size() > 4 ? "," : "") + name + "=" + std::to_string(weight);
    m.rest = Strategy::parse(text);
  }
  return m;
}

double TechniquePair::weight_of(const Strategy& strategy) const {
  if (strategy.nee_mis || strategy.roulette_depth != roulette_depth ||
      strategy.guided_roulette != guided_roulette_holds(strategy, guided_roulette))
    return -1.0;
  Strategy s = strategy;
  s.roulette_depth = 0;  // the mixture's terms alone
  double wa = 0.0, wb = 0.0;
  std::vector<std::pair<std::string, double>> others;
  for (const auto& [name, weight] : mixture_terms(s))
    if (name == a) wa += weight;
    else if (name == b) wb += weight;
    else others.emplace_back(name, weight);
  if (!(wa + wb > 0.0) || std::fabs(wa + wb - share) > 1e-6 || others.size() != rest.size()) return -1.0;
  for (const auto& term : others) {
    const auto it = std::find_if(rest.begin(), rest.end(), [&](const auto& r) { return r.first == term.first; });
    if (it == rest.end() || std::fabs(it->second - term.second) > 1e-6) return -1.0;
  }
  return wa / (wa + wb);
}

TechniquePair parse_technique_pair(const std::string& vary, const std::string& base, int roulette_depth) {
  const std::size_t comma = vary.find(',');
  if (comma == std::string::npos || vary.find(',', comma + 1) != std::string::npos)
    throw InputError("--vary '" + vary + "' is not two techniques A,B (for example cosine,light)");
  TechniquePair f;
  f.roulette_depth = roulette_depth;
  for (std::string* name : {&f.a, &f.b}) {
    *name = trimmed(name == &f.a ? vary.substr(0, comma) : vary.substr(comma + 1));
    Strategy s;
    try {
      s = Strategy::parse(*name);
    } catch (const InputError& e) {  // an unknown name: the message lists the known ones
      throw InputError("--vary '" + vary + "': " + e.what());
    }
    if (s.nee_mis || s.to_string().rfind("mix:", 0) == 0)
      throw InputError("--vary '" + vary + "': '" + *name + "' is not a mixture technique");
    *name = s.to_string();  // canonical, as the base mixture's terms are written
  }
  if (f.a == f.b) throw InputError("--vary '" + vary + "' names the same technique twice");
  if (base.empty()) return f;
  Strategy s = Strategy::parse(base);
  if (s.roulette_depth > 0 && roulette_depth == 0) f.roulette_depth = s.roulette_depth;
  f.guided_roulette = s.guided_roulette;
  s.roulette_depth = 0;  // the mixture's terms alone
  if (s.nee_mis) throw InputError("--strategy '" + base + "': nee-mis is not a mixture; sweep varies mixture weights");
  double pair = 0.0;
  for (const auto& [name, weight] : mixture_terms(s))
    if (name == f.a || name == f.b)
      pair += weight;
    else
      f.rest.emplace_back(name, weight);
  if (!(pair > 0.0))
    throw InputError("--strategy '" + base + "' gives " + f.a + " and " + f.b +
                     " no weight: the sweep would hold them at zero");
  f.share = pair;
  return f;
}

WeightPredictor record_weight_paths(const Scene& scene, const MixtureFamily& family, const Strategy& mixture,
                                    double w, const std::vector<double>& grid, const WeightPathOptions& o) {
  const auto make = [&](const Strategy& s) {
    SamplingPlan p = SamplingPlan::make(s, scene);
    p.guiding = o.guiding;
    return p;
  };
  const SamplingPlan plan = make(mixture);
  const SamplingPlan plan_a = make(family.a);
  const SamplingPlan plan_b = make(family.b);
  const bool has_rest = family.share < 1.0;
  const SamplingPlan plan_rest = has_rest ? make(family.rest) : SamplingPlan{};
  const float rest_weight = static_cast<float>(1.0 - family.share);
  const int width = scene.camera.width, height = scene.camera.height;
  const WeightFamily weights{family.share, plan.roulette_depth > 0};
  if (o.technique_share) o.technique_share->resize(static_cast<std::size_t>(width * height) * kShareKinds, 0.0);

  int threads = o.threads > 0 ? o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::min(threads, height);
  const int block = std::max(1, o.block), blocks_x = (width + block - 1) / block;
  const std::vector<float>* relative = o.relative_to;
  if (relative && relative->size() != static_cast<std::size_t>(width * height) * 3)
    throw InputError("weight paths: the mean image does not have the scene's size");
  std::vector<WeightPredictor> parts(
      static_cast<std::size_t>(threads), WeightPredictor(relative ? 1 : block_cells(width, height, block), grid, w, weights));
  const SampleSeed seed(o.seed);
  auto work = [&](int part) {
    WeightPredictor& predictor = parts[static_cast<std::size_t>(part)];
    PathRecord record;
    std::vector<MixtureVertex> vertices;
    DropCounts drops;
    for (int y = part; y < height; y += threads)
      for (int x = 0; x < width; ++x)
        for (std::uint32_t i = 0; i < o.samples; ++i) {
          PixelSampleStart start = begin_pixel_sample(scene, seed, x, y, o.first_sample + i);
          const Vec3 radiance = trace_path(scene, plan, start.ray, start.rng, drops, &record);
          vertices.clear();
          for (const PathRecord::Vertex& v : record.vertices) {
            MixtureVertex m;
            m.a = plan_a.pdf(v.point, v.normal, v.direction);
            m.b = plan_b.pdf(v.point, v.normal, v.direction);
            m.rest = has_rest ? rest_weight * plan_rest.pdf(v.point, v.normal, v.direction) : 0.0f;
            m.roulette = v.roulette;
            m.segments = v.segments;
            vertices.push_back(m);
          }
          if (o.film) o.film->add(static_cast<std::size_t>(y * width + x), radiance);  // pixels of disjoint rows
          if (o.technique_share) {
            const double carried = luminance(radiance.x, radiance.y, radiance.z);
            double* share = &(*o.technique_share)[static_cast<std::size_t>(y * width + x) * kShareKinds];
            if (carried > 0.0 && std::isfinite(carried)) {
              if (vertices.empty()) {
                share[kShareDirect] += carried;
              } else {
                const MixtureVertex& last = vertices.back();
                const double p = weights.pdf(last, w);
                if (p > 0.0) {
                  share[kShareA] += carried * family.share * w * static_cast<double>(last.a) / p;
                  share[kShareB] += carried * family.share * (1.0 - w) * static_cast<double>(last.b) / p;
                  share[kShareRest] += carried * static_cast<double>(last.rest) / p;
                }
              }
            }
          }
          float rgb[3] = {radiance.x, radiance.y, radiance.z};
          if (relative) {
            const float* mu = &(*relative)[static_cast<std::size_t>(y * width + x) * 3];
            for (int c = 0; c < 3; ++c)
              rgb[c] = static_cast<float>(static_cast<double>(rgb[c]) /
                                          std::sqrt(static_cast<double>(mu[c]) * mu[c] + o.relative_epsilon));
          }
          const int cell = relative ? 0 : (y / block) * blocks_x + x / block;
          predictor.add_path(cell, rgb, vertices, static_cast<double>(record.segments));
        }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (std::thread& t : pool) t.join();
  for (std::size_t t = 1; t < parts.size(); ++t) parts[0].merge(parts[t]);
  return std::move(parts[0]);
}

WeightPrediction predict_image_wide(const WeightPredictor& predictor, const std::vector<float>& mean,
                                    double seconds_per_sample, double epsilon) {
  // The cell's moment is the mean of F^2 R / (mu^2 + eps) over all paths (each
  // pixel has as many); subtracting the mean of mu^2 / (mu^2 + eps) with a
  // unit denominator leaves the mean relative variance.
  std::vector<float> unit = {1.0f, 1.0f, 1.0f}, square(3, 0.0f);
  double sums[3] = {0.0, 0.0, 0.0};
  const std::size_t pixels = mean.size() / 3;
  for (std::size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < 3; ++c) {
      const double mu = static_cast<double>(mean[i * 3 + static_cast<std::size_t>(c)]);
      sums[c] += mu * mu / (mu * mu + epsilon);
    }
  for (int c = 0; c < 3; ++c) square[static_cast<std::size_t>(c)] = static_cast<float>(sums[c] / static_cast<double>(std::max<std::size_t>(1, pixels)));
  return predictor.predict(unit, seconds_per_sample, 0.0, 0.0, &square);
}

std::uint64_t forecast_seed(std::uint64_t render_seed) {
  // SampleSeed hashes the seed into its keys: any other seed gives other
  // random streams and other per-pixel scrambles.
  return render_seed ^ 0x9e3779b97f4a7c15ULL;
}

CostModel AutoWeight::pricing_model(const WeightPrediction& p, double seconds_per_sample) const {
  if (model_.per_ray > 0.0 || !(seconds_per_sample > 0.0)) return model_;
  return anchored_cost_model(p.sampling_cost, seconds_per_sample, prior_offset_);
}

WeightPrediction AutoWeight::priced(WeightPrediction p, double seconds_per_sample, CostModel* used) const {
  const CostModel model = pricing_model(p, seconds_per_sample);
  if (model.per_ray > 0.0) apply_cost_model(p, model);
  if (used) *used = model;
  return p;
}

double AutoWeight::pass_share(int pass) {
  static constexpr double kShare[kPasses] = {1.0 / 32, 3.0 / 32, 1.0 / 8, 1.0 / 4, 1.0 / 2};
  return pass >= 0 && pass < kPasses ? kShare[pass] : 0.0;
}

std::uint32_t AutoWeight::replay_samples(std::uint32_t pass_spp) {
  return std::min(pass_spp, std::clamp<std::uint32_t>(pass_spp / 32, 1, 8));
}

AutoWeight::AutoWeight(double first, int grid_points, double prior_offset)
    : grid_(weight_grid(grid_points)), prior_offset_(prior_offset), history_{defended_weight(first)}, chosen_{false} {}

bool AutoWeight::settled() const {
  // history_: the first guess, then one weight per prediction; chosen_: which
  // of those a prediction chose (a pass without paths, or whose pooled
  // prediction has no best, keeps the weight without choosing it).
  const std::size_t n = history_.size();
  return n >= 3 && chosen_[n - 1] && chosen_[n - 2] && history_[n - 1] == history_[n - 2];
}

void AutoWeight::add_pass(const WeightPrediction& prediction, double seconds_per_sample) {
  if (prediction.efficiency.size() != grid_.size()) return;
  passes_.push_back(prediction);
  if (seconds_per_sample > 0.0) {
    fit_.add(prediction.sampling_cost, seconds_per_sample);
    model_ = fit_.fit(prior_offset_, kFitSpread);
  }
  // The passes' predictions pooled (pooled_prediction), priced by the model
  // fitted so far or, without timing, by rays alone.
  const WeightPrediction pooled =
      pooled_prediction(passes_, model_.per_ray > 0.0 ? model_ : kRaysAlone);
  const bool chose = pooled.best >= 0 && prediction.paths > 0;
  history_.push_back(pooled.best >= 0 ? defended_weight(pooled.best_weight()) : history_.back());
  chosen_.push_back(chose);
}

}  // namespace pdflab
