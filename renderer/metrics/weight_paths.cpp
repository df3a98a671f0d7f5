#include "renderer/metrics/weight_paths.h"

#include "renderer/integrator/integrator.h"

#include <algorithm>
#include <thread>

namespace pdflab {

WeightPredictor record_weight_paths(const Scene& scene, const MixtureFamily& family, const Strategy& mixture,
                                    double w, const std::vector<double>& grid, const WeightPathOptions& o) {
  const SamplingPlan plan = SamplingPlan::make(mixture, scene);
  const SamplingPlan plan_a = SamplingPlan::make(family.a, scene);
  const SamplingPlan plan_b = SamplingPlan::make(family.b, scene);
  const bool has_rest = family.share < 1.0;
  const SamplingPlan plan_rest = has_rest ? SamplingPlan::make(family.rest, scene) : SamplingPlan{};
  const float rest_weight = static_cast<float>(1.0 - family.share);
  const int width = scene.camera.width, height = scene.camera.height;
  const WeightFamily weights{family.share};

  int threads = o.threads > 0 ? o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::min(threads, height);
  std::vector<WeightPredictor> parts(static_cast<std::size_t>(threads), WeightPredictor(width * height, grid, w, weights));
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
            vertices.push_back(m);
          }
          if (o.film) o.film->add(static_cast<std::size_t>(y * width + x), radiance);  // pixels of disjoint rows
          const float rgb[3] = {radiance.x, radiance.y, radiance.z};
          predictor.add_path(y * width + x, rgb, vertices, static_cast<double>(record.segments));
        }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (std::thread& t : pool) t.join();
  for (std::size_t t = 1; t < parts.size(); ++t) parts[0].merge(parts[t]);
  return std::move(parts[0]);
}

AutoWeight::AutoWeight(double first, int grid_points)
    : grid_(weight_grid(grid_points)), sum_(grid_.size(), 0.0), history_{defended_weight(first)} {}

void AutoWeight::add_pass(const WeightPrediction& prediction) {
  if (prediction.efficiency.size() != grid_.size()) return;
  ++passes_;
  for (std::size_t g = 0; g < grid_.size(); ++g) sum_[g] += prediction.efficiency[g];
  std::size_t best = 0;
  for (std::size_t g = 1; g < grid_.size(); ++g)
    if (sum_[g] > sum_[best]) best = g;
  history_.push_back(sum_[best] > 0.0 ? defended_weight(grid_[best]) : history_.back());
}

}  // namespace pdflab
