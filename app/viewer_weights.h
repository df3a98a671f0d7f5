#pragma once
// The viewer's live answer to "where should the slider be?": while a mixture
// of two techniques renders, a background job traces paths at the render's
// weight under forecast_seed (weight_paths.h: independent of the render's own
// samples, so of the published mean they are predicted against), a little at
// a time, as many per pixel as the render has drawn, and turns them into the
// predicted efficiency curve beside the w slider, priced by auto weight's cost
// model (AutoWeight::priced), the best-weight map and the "which technique
// found the light" map. Auto weight steps the slider between passes from the
// same prediction and the pass's measured time, as sweep --auto does.
#include "renderer/metrics/weight_paths.h"
#include "renderer/metrics/weight_prediction.h"
#include "renderer/scene/scene.h"
#include "renderer/session/session.h"
#include "ui/measure.h"
#include "ui/settings.h"

#include <cstdint>
#include <future>
#include <memory>
#include <optional>
#include <vector>

namespace pdflab {

class WeightLab {
 public:
  // Samples per pixel traced per round, and in all for one generation.
  static constexpr std::uint32_t kRoundSpp = 1, kMaxSpp = 64;
  // At most this many predictor cells: larger images are predicted per block.
  static constexpr int kMaxCells = 16384;

  WeightLab();
  ~WeightLab();  // waits for a job in flight
  WeightLab(const WeightLab&) = delete;
  WeightLab& operator=(const WeightLab&) = delete;

  struct Input {
    std::shared_ptr<const Scene> scene;  // as rendered
    Strategy strategy;
    std::uint64_t seed = 0;
    std::uint32_t first_sample = 0;  // the first sample index drawn at this strategy
    std::uint32_t spp_before = 0;    // samples per pixel in the film from before it (auto weight's earlier passes)
    double seconds_before = 0.0;     // and the rendering time they took (the film's clock runs on)
    std::uint64_t generation = 0;
    int a = -1, b = -1;  // the w slider's techniques (indices); -1: no pair
    const PublishedImage* image = nullptr;  // the latest published pass
    // Prices the curve: auto weight's chooser while it runs (its cost model
    // fitted to its passes); null: a fresh one (the prior fixed cost).
    const AutoWeight* pricing = nullptr;
    // A strategy with `guided`: the render's distribution, and whether its
    // training passes are over (the prediction waits for the frozen one).
    std::shared_ptr<const GuidingDistribution> guiding;
    bool guiding_trained = false;
  };
  // Once a frame. Starts a round when one is due, takes a finished one.
  // Returns true when the curve or the maps changed.
  bool update(const Input& in);

  const ui::WeightCurveStatus& curve() const { return curve_; }
  const ui::WeightMaps& maps() const { return maps_; }
  // The latest prediction, of `generation`, on AutoWeight's grid; none before the first round.
  // Unpriced (AutoWeight::add_pass prices it), with the render's measured
  // seconds per sample at this weight.
  const std::optional<WeightPrediction>& prediction() const { return prediction_; }
  double seconds_per_sample() const { return seconds_per_sample_; }
  std::uint64_t generation() const { return generation_; }

  // One round of tracing, run off the UI thread, and what it gives back.
  struct Round {
    std::shared_ptr<const Scene> scene;
    MixtureFamily family;
    Strategy strategy;
    double w = 0.5;
    WeightPathOptions options;
    std::shared_ptr<const GuidingDistribution> guiding;  // what options.guiding points to, kept alive
    std::vector<double> grid;
    std::unique_ptr<WeightPredictor> predictor;  // what earlier rounds traced, or null
    std::vector<double> share;
    std::vector<float> mean;  // the published mean, width x height RGB
    double seconds_per_pass = 0.0;
  };
  struct Result {
    std::unique_ptr<WeightPredictor> predictor;
    std::vector<double> share;
    WeightPrediction prediction;
    std::vector<float> best_weight, share_a;
    int width = 0, height = 0, block = 1;
    double seconds_per_sample = 0.0;
  };
  static Result run_round(Round& round);

 private:
  void reset(std::uint64_t generation);
  void take(Result r, const AutoWeight& pricing);

  std::uint64_t generation_ = ~std::uint64_t{0};
  double w_ = -1.0;
  std::uint32_t traced_ = 0;
  std::unique_ptr<WeightPredictor> predictor_;  // the traced paths of this generation
  std::vector<double> share_;                   // per pixel, kShareKinds sums
  std::future<Result> job_;
  std::uint64_t job_generation_ = 0;
  std::optional<WeightPrediction> prediction_;
  double seconds_per_sample_ = 0.0;
  ui::WeightCurveStatus curve_;
  ui::WeightMaps maps_;
};

}  // namespace pdflab
