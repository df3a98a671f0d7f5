#pragma once
// Feeds the weight predictor (weight_prediction.h) with real paths: replays a
// render's pixel samples through the one-path tracer, which records each
// diffuse vertex's point, normal and drawn direction, and evaluates there the
// densities of the two varied techniques and of the fixed rest.
#include "renderer/metrics/weight_prediction.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pdflab {

// The mixtures of a sweep: A's share w of the pair, the rest fixed.
struct MixtureFamily {
  Strategy a, b;       // each one technique alone
  Strategy rest;       // the fixed techniques' mixture (unused when share is 1)
  double share = 1.0;  // the pair's total weight; the rest has 1 - share
};

struct WeightPathOptions {
  std::uint64_t seed = 2;
  std::uint32_t first_sample = 0, samples = 64;  // per pixel: sample indices first .. first + samples - 1
  int threads = 0;                               // <= 0: hardware threads
};

// Traces `samples` per pixel of `scene` (prepared, at its camera size) with
// `mixture`, the family's member at weight `w` — exactly the paths a render
// with that seed draws — into a predictor over `grid` with one cell per pixel.
WeightPredictor record_weight_paths(const Scene& scene, const MixtureFamily& family, const Strategy& mixture,
                                    double w, const std::vector<double>& grid, const WeightPathOptions& options);

}  // namespace pdflab
