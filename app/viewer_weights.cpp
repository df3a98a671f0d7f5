#include "app/viewer_weights.h"

#include "renderer/metrics/metrics.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace pdflab {

WeightLab::Result WeightLab::run_round(Round& r) {
  const Scene& scene = *r.scene;
  const int width = scene.camera.width, height = scene.camera.height, block = r.options.block;
  r.options.technique_share = &r.share;
  WeightPredictor part = record_weight_paths(scene, r.family, r.strategy, r.w, r.grid, r.options);
  if (r.predictor) r.predictor->merge(part);
  else r.predictor = std::make_unique<WeightPredictor>(std::move(part));
  // Each cell's mean and mean of mu^2 over its pixels (relMSE weighs pixels).
  const int blocks_x = (width + block - 1) / block, cells = block_cells(width, height, block);
  std::vector<float> mean(static_cast<std::size_t>(cells) * 3, 0.0f), square(mean.size(), 0.0f);
  std::vector<int> count(static_cast<std::size_t>(cells), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t cell = static_cast<std::size_t>((y / block) * blocks_x + x / block);
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      for (int c = 0; c < 3; ++c) {
        const float v = r.mean[p * 3 + static_cast<std::size_t>(c)];
        mean[cell * 3 + static_cast<std::size_t>(c)] += v;
        square[cell * 3 + static_cast<std::size_t>(c)] += v * v;
      }
      ++count[cell];
    }
  for (std::size_t cell = 0; cell < count.size(); ++cell)
    for (int c = 0; c < 3; ++c) {
      const float n = static_cast<float>(std::max(1, count[cell]));
      mean[cell * 3 + static_cast<std::size_t>(c)] /= n;
      square[cell * 3 + static_cast<std::size_t>(c)] /= n;
    }
  Result out;
  out.prediction = r.predictor->predict(mean, r.seconds_per_pass, kRelMseEpsilon, 0.0, &square);
  out.best_weight = r.predictor->best_weight_map(mean, kRelMseEpsilon);  // -1 where w does not matter
  // The technique shares per cell too: a pixel's few paths are mostly noise.
  std::vector<double> found(static_cast<std::size_t>(cells), 0.0), by_a(found.size(), 0.0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t cell = static_cast<std::size_t>((y / block) * blocks_x + x / block);
      const double* s = &r.share[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * kShareKinds];
      found[cell] += s[kShareA] + s[kShareB] + s[kShareRest];
      by_a[cell] += s[kShareA];
    }
  out.share_a.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), -1.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t cell = static_cast<std::size_t>((y / block) * blocks_x + x / block);
      if (found[cell] > 0.0)
        out.share_a[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)] =
            static_cast<float>(by_a[cell] / found[cell]);
    }
  out.predictor = std::move(r.predictor);
  out.share = std::move(r.share);
  out.seconds_per_sample = r.seconds_per_pass;
  out.width = width;
  out.height = height;
  out.block = block;
  return out;
}

WeightLab::WeightLab() = default;

WeightLab::~WeightLab() {
  if (job_.valid()) job_.wait();
}

void WeightLab::reset(std::uint64_t generation) {
  generation_ = generation;
  traced_ = 0;
  predictor_.reset();
  share_.clear();
  prediction_.reset();
  seconds_per_sample_ = 0.0;
  curve_ = {};
  curve_.why = "waiting for the first samples";
  maps_ = {};
  maps_.why = "waiting for the prediction";
}

void WeightLab::take(Result r, const AutoWeight& pricing) {
  predictor_ = std::move(r.predictor);
  share_ = std::move(r.share);
  CostModel model;
  const WeightPrediction p = pricing.priced(r.prediction, r.seconds_per_sample, &model);
  curve_.fixed_cost_rays = model.per_ray > 0.0 ? model.offset() : -1.0;
  curve_.cost_fitted = model.fitted;
  curve_.active = p.best >= 0;
  curve_.why = curve_.active ? "" : "no path has found light yet";
  curve_.weight.assign(p.weight.begin(), p.weight.end());
  curve_.relative_efficiency.clear();
  curve_.largest_share.assign(p.largest_share.begin(), p.largest_share.end());
  curve_.dominant_share = static_cast<float>(kDominantShare);
  const double top = p.best >= 0 ? p.efficiency[static_cast<std::size_t>(p.best)] : 0.0;
  for (double e : p.efficiency) curve_.relative_efficiency.push_back(top > 0.0 ? static_cast<float>(e / top) : 0.0f);
  // The best inside the floor: at w = 0 or 1 a technique may be biased alone
  // (light sampling misses indirect light), which no path's ratio can show.
  double best_efficiency = 0.0;
  curve_.best = -1.0;
  for (std::size_t g = 0; g < p.weight.size(); ++g)
    if (defended_weight(p.weight[g]) == p.weight[g] && p.efficiency[g] > best_efficiency)
      best_efficiency = p.efficiency[g], curve_.best = p.weight[g];
  curve_.sampling = w_;
  curve_.paths = p.paths;
  maps_.width = r.width;
  maps_.height = r.height;
  maps_.block = r.block;
  maps_.best_weight = std::move(r.best_weight);
  maps_.share_a = std::move(r.share_a);
  maps_.paths = p.paths;
  maps_.why.clear();
  prediction_ = std::move(r.prediction);
  seconds_per_sample_ = r.seconds_per_sample;
}

bool WeightLab::update(const Input& in) {
  bool changed = false;
  if (job_.valid() && job_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    Result r = job_.get();
    if (job_generation_ == generation_) {
      const AutoWeight prior;
      take(std::move(r), in.pricing ? *in.pricing : prior);
      changed = true;
    }
  }
  const ImageInfo* info = in.image ? &in.image->info : nullptr;
  if (in.a < 0 || in.b < 0 || !in.scene) {
    if (curve_.active || !maps_.a.empty() || curve_.why.empty()) changed = true;
    curve_ = {};
    curve_.why = "render a mixture of two techniques";
    maps_ = {};
    maps_.why = curve_.why;
    generation_ = ~std::uint64_t{0};
    return changed;
  }
  if (in.generation != generation_) {
    reset(in.generation);
    changed = true;
  }
  if (in.strategy.uses(Technique::Guided) && (!in.guiding_trained || !in.guiding)) {
    // No curve rather than the untrained sphere's: the prediction replays
    // paths with the distribution the render draws from once it has learned.
    static constexpr const char* kWaiting = "waiting for path guiding's training passes";
    if (curve_.active || curve_.why != kWaiting) changed = true;
    curve_ = {};
    curve_.why = kWaiting;
    maps_ = {};
    maps_.why = curve_.why;
    return changed;
  }
  // The pair's names as the strategy writes its terms: a technique with a
  // parameter carries it (cosine-power:8, guided:5), and weight_of matches names.
  const auto term_name = [&](int t) {
    const std::string base(technique_name(static_cast<Technique>(t)));
    for (const auto& term : mixture_terms(in.strategy))
      if (term.first == base || term.first.rfind(base + ":", 0) == 0) return term.first;
    return base;
  };
  TechniquePair pair;
  pair.a = term_name(in.a);
  pair.b = term_name(in.b);
  pair.roulette_depth = in.strategy.roulette_depth;  // the paths' own (the prediction weighs its checks)
  pair.guided_roulette = in.strategy.guided_roulette;
  maps_.a = pair.a;
  maps_.b = pair.b;
  const double w = pair.weight_of(in.strategy);
  if (w < 0.0) return changed;
  w_ = w;
  if (defended_weight(w) != w) {
    char why[96];
    std::snprintf(why, sizeof why, "w is outside [%.2f, %.2f]; the prediction waits (why: below)", kDefensiveFloor,
                  1.0 - kDefensiveFloor);
    if (curve_.why != why) changed = true;
    curve_.active = false;
    curve_.why = why;
    maps_.why = why;
    return changed;
  }
  if (job_.valid() || !info || info->preview || info->training_pass > 0 || info->generation != in.generation ||
      info->spp == 0)
    return changed;
  const std::uint32_t drawn = info->spp > in.spp_before ? info->spp - in.spp_before : 0;
  const std::uint32_t wanted = std::min(drawn, kMaxSpp);
  if (traced_ + kRoundSpp > wanted) return changed;

  auto round = std::make_shared<Round>();
  round->scene = in.scene;
  round->family = pair.mixture_family();
  round->strategy = in.strategy;
  round->w = w;
  const int width = in.scene->camera.width, height = in.scene->camera.height;
  int block = 1;
  while (block_cells(width, height, block) > kMaxCells) ++block;
  // Paths of their own (forecast_seed), at the indices this generation's
  // samples have under the render's seed: a later generation (auto weight's
  // next pass) starts past them and traces other paths again.
  round->options.seed = forecast_seed(in.seed);
  round->options.first_sample = in.first_sample + traced_;
  round->options.samples = kRoundSpp;
  round->options.threads = 1;  // beside the render's threads
  round->options.block = block;
  round->guiding = in.guiding;  // frozen for the generation once trained
  round->options.guiding = round->guiding.get();
  round->grid = AutoWeight().grid();
  round->predictor = std::move(predictor_);
  round->share = std::move(share_);
  round->mean = in.image->rgb;
  // This weight's time over its own samples (auto weight's earlier passes
  // are in the film's spp and in its clock, which runs on across them).
  round->seconds_per_pass = std::max(0.0, info->seconds - in.seconds_before) / drawn;
  traced_ += kRoundSpp;
  job_generation_ = generation_;
  job_ = std::async(std::launch::async, [round] { return run_round(*round); });
  return changed;
}

}  // namespace pdflab
