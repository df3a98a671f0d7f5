#pragma once
// Feeds the weight predictor (weight_prediction.h) with real paths: replays a
// render's pixel samples through the one-path tracer, which records each
// diffuse vertex's point, normal and drawn direction, and evaluates there the
// densities of the two varied techniques and of the fixed rest.
#include "renderer/film/film.h"
#include "renderer/metrics/weight_prediction.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace pdflab {

// The mixtures of a sweep: A's share w of the pair, the rest fixed.
struct MixtureFamily {
  Strategy a, b;       // each one technique alone
  Strategy rest;       // the fixed techniques' mixture (unused when share is 1)
  double share = 1.0;  // the pair's total weight; the rest has 1 - share
};

// Two techniques A and B whose shares of one mixture vary, the others held at
// their weights: the family a sweep, bench's prediction and the viewer's curve
// walk along. w is A's share of the pair, whose total weight is `share`.
struct TechniquePair {
  std::string a, b;                                   // canonical technique names
  double share = 1.0;                                 // the pair's total weight
  std::vector<std::pair<std::string, double>> rest;  // the others, normalised weights
  int roulette_depth = 0;                             // Strategy::roulette_depth of every member
  bool guided_roulette = false;                       // Strategy::guided_roulette of every member (+rr:guided)

  Strategy at(double w) const;           // the mixture at A's share w
  MixtureFamily mixture_family() const;  // the densities the predictor evaluates
  // A's share of the pair in `s` when s is a member of this family (the same
  // techniques, the others at the same weights); -1 otherwise.
  double weight_of(const Strategy& s) const;
};

// "A,B" (a comma between two technique names) with an optional base mixture
// whose other techniques keep their weights, and Russian roulette from
// `roulette_depth` on (0: the base's own, if any). InputError naming `vary` or `base`.
TechniquePair parse_technique_pair(const std::string& vary, const std::string& base = "", int roulette_depth = 0);

// A strategy's canonical text as (technique, weight) pairs: "cosine" or
// "mix:cosine=0.25,light=0.75", the weights normalised as the text gives them.
std::vector<std::pair<std::string, double>> mixture_terms(const Strategy& s);

struct WeightPathOptions {
  std::uint64_t seed = 2;
  std::uint32_t first_sample = 0, samples = 64;  // per pixel: sample indices first .. first + samples - 1
  int threads = 0;                               // <= 0: hardware threads
  Film* film = nullptr;  // when given (at the scene's size), the traced samples are added to it
  // When given: per pixel, kShareKinds sums of the luminance the traced paths
  // carried (see TechniqueShare), added to what is there.
  std::vector<double>* technique_share = nullptr;
  // The predictor's cells: block x block pixels each (the right and bottom
  // ones may be cut), row by row; 1: one cell per pixel.
  int block = 1;
  // When given (each pixel's mean, RGB): one cell for the whole image, each
  // path's estimate divided per channel by sqrt(mean^2 + relative_epsilon), so
  // that the cell's second moment is the image's mean relative one (see
  // predict_image_wide). A few hundred bytes however large the image: what
  // auto weight needs, without a per-pixel table to allocate every pass.
  const std::vector<float>* relative_to = nullptr;
  double relative_epsilon = 0.0;
  // `guided`'s distribution, frozen, for every member of the family: the one
  // the render being replayed learned (null: untrained, the uniform sphere).
  // The prediction then says what each weight would give with that
  // distribution; a render at another weight trains its own.
  const GuidingDistribution* guiding = nullptr;
};

// The image-wide prediction of a predictor recorded with `relative_to` =
// `mean` (the same image and epsilon): the relative variance is the mean over
// pixels and channels of (M - mu^2) / (mu^2 + epsilon), as predict() gives
// with one cell per pixel.
WeightPrediction predict_image_wide(const WeightPredictor& predictor, const std::vector<float>& mean,
                                    double seconds_per_sample, double epsilon);

// How many cells of `block` pixels a side cover a width x height image.
inline int block_cells(int width, int height, int block) {
  return ((width + block - 1) / block) * ((height + block - 1) / block);
}

// "Which technique found the light": a path's estimate is carried by the
// direction its last diffuse vertex drew (lights do not scatter, so that
// direction, through any specular bounces, reached the emitter). Its share
// per technique is that technique's part of the mixture density there,
// w_i p_i / p_w: the probability that it was the one drawing this direction
// (the expected split of "which one drew it", with less noise than the draw
// itself). Paths that see a light with no diffuse vertex are their own kind.
enum TechniqueShare : int { kShareA = 0, kShareB = 1, kShareRest = 2, kShareDirect = 3, kShareKinds = 4 };

// Traces `samples` per pixel of `scene` (prepared, at its camera size) with
// `mixture`, the family's member at weight `w` — exactly the paths a render
// with that seed draws — into a predictor over `grid` with one cell per pixel
// (or per block, options.block).
WeightPredictor record_weight_paths(const Scene& scene, const MixtureFamily& family, const Strategy& mixture,
                                    double w, const std::vector<double>& grid, const WeightPathOptions& options);

// The seed of the paths a prediction traces beside a render whose film it
// cannot add them to (the viewer, whose session owns the film). A prediction
// must not use the very samples of the mean it is compared with (a bright path
// would raise its own pixel's mean and hold its own share of the second moment
// down, leaning the prediction towards the weight it was drawn at), nor random
// numbers a later pass will reuse: under this seed its paths share neither
// random streams nor pixel positions with the render of `render_seed`.
std::uint64_t forecast_seed(std::uint64_t render_seed);

// Auto weight: each pass renders with one fixed weight chosen from the
// predictions of the passes before it, never from its own samples. Every
// pass is then an unbiased estimate of the image whatever its weight, and so
// is their sample-weighted sum. (A weight chosen from a pass's own samples
// would correlate the weight with those samples' noise, and the sum would no
// longer be unbiased.)
//
// The schedule: a run of kPasses passes taking 1/32, 3/32, 1/8, 1/4 and 1/2 of
// its time (or samples), the first at `first`. The first pass is short because
// its weight is a guess (at 1/16 it cost up to 3 % of the run on the
// aluminium box, whose 0.5 has half the best weight's efficiency); after each
// pass but the last a few more samples per pixel are traced for the
// prediction (replay_samples: about 1/32 of the pass, 1 to 8: predicting
// costs several per cent of a short run, less of a long one), and the next
// weight is the best of the passes' predictions so far, pooled (each counted
// by its number of paths; see add_pass). Once two predictions in a row choose
// the same weight (settled()), `sweep --auto`'s later passes keep it and trace
// no more forecast paths (the viewer keeps predicting for its live curve):
// the forecast runs on the one-path tracer, several times dearer a sample
// than the packet tracer, and on the shipped scenes a settled weight moved by
// at most one grid step afterwards (docs/measuring.md).
//
// The time a weight costs comes from a CostModel (weight_prediction.h) fitted
// to the passes' own timing: each pass gives its seconds per sample and its
// paths' mean rays. Until the passes' rays spread enough to tell the fixed
// cost per sample from the cost per ray, the fixed cost is `prior_offset` rays.
class AutoWeight {
 public:
  static constexpr int kPasses = 5;
  // The fixed cost per sample, in rays, assumed until the passes measure it
  // (sweeps of the shipped scenes fit 0 to 2.5, docs/measuring.md).
  static constexpr double kPriorOffset = 0.5;
  // The passes' rays must spread by this share of their mean before their
  // times are fitted: a few passes of noisy times at nearby weights cannot
  // tell a fixed cost from a cost per ray.
  static constexpr double kFitSpread = 0.25;
  static double pass_share(int pass);  // of the run, for pass 0 .. kPasses - 1
  static std::uint32_t replay_samples(std::uint32_t pass_spp);

  explicit AutoWeight(double first = 0.5, int grid_points = 21, double prior_offset = kPriorOffset);
  double weight() const { return history_.back(); }  // for the next pass
  // Whether the latest prediction kept the weight the one before it chose (the
  // first pass's weight is a guess, not a choice, and so is a weight kept by a
  // pass without paths or without a best): then predicting may stop.
  bool settled() const;
  // A finished pass's prediction (on grid()) and its measured seconds per
  // sample (one sample in every cell; 0: unknown, rays alone price it): the
  // next weight is the best of the passes' pooled prediction (relative
  // variance and rays, each pass counted by its paths) under the cost model
  // fitted so far, kept inside the defensive floor.
  void add_pass(const WeightPrediction& prediction, double seconds_per_sample = 0.0);
  // `prediction` priced as add_pass prices the passes: by the cost model
  // fitted to the passes so far or, before a fit, by its own seconds per
  // sample split with the prior fixed cost (the same model add_pass makes of
  // a first pass). What the viewer's curve shows; `used`, if given, receives
  // that model.
  WeightPrediction priced(WeightPrediction prediction, double seconds_per_sample, CostModel* used = nullptr) const;
  const std::vector<double>& grid() const { return grid_; }
  const std::vector<double>& history() const { return history_; }  // the first guess, then one weight per add_pass
  const CostModel& cost_model() const { return model_; }           // the latest fit (zero before a timed pass)

 private:
  std::vector<double> grid_;
  double prior_offset_;
  std::vector<WeightPrediction> passes_;
  CostFit fit_;
  CostModel model_;
  std::vector<double> history_;
  std::vector<bool> chosen_;  // per history_ entry: chosen by a prediction
  // The model priced() uses for a prediction with this time per sample.
  CostModel pricing_model(const WeightPrediction& prediction, double seconds_per_sample) const;
};

}  // namespace pdflab
