#pragma once
// Where should the mixture weight be? A prediction of the second moment, the
// cost and the efficiency of a one-sample mixture at every weight of a grid,
// from paths drawn at one weight.
//
// The mixture varies the share of two techniques A and B; the others keep
// their weights. At a diffuse vertex whose drawn direction has density a under
// A, b under B and r = sum over the other techniques of w_i p_i, the mixture's
// density at weight w (A's share of the pair, which has total weight s) is
//
//     p_w = s (w a + (1 - w) b) + r.
//
// A path's pdf is the product of p_w over its diffuse vertices (specular
// bounces do not depend on w). For a path drawn at w with estimate F_w = f /
// prod p_w, the same path at w' would have estimated F_w' = F_w R with
// R = prod_k p_w(k) / p_w'(k), and
//
//     M(w') = E_w'[F_w'^2] = E_w[F_w'^2 prod_k p_w'(k) / p_w(k)] = E_w[F_w^2 R]
//     C(w') = E_w'[cost]   = E_w[cost / R]
//
// are both estimated without bias from the paths at w.
//
// With Russian roulette the path's pdf also holds each check's survival
// probability q = min(1, m), m the largest component of throughput * albedo
// there. The throughput before vertex k at w' is the one at w times R_<k, the
// ratio of everything before k, so q_w'(k) = min(1, m_k R_<k), and R gains a
// factor q_w(k) / q_w'(k) at each check the path survived (a path that did not
// survive carries no estimate, so M is as above). The cost is then summed
// segment by segment, C(w') = E_w[sum over segments of 1 / R of what decided
// that the segment is traced]: a path that at w' could end at a check where at
// w it always goes on (q_w = 1 > q_w') is, for its cost, the start of a path
// that went on, which the whole path's ratio would not count. With a pixel's mean mu
// (which does not depend on w), its variance at w' is M(w') - mu^2, and the
// image-wide relative variance is the mean over pixels and channels of
// variance / (mu^2 + epsilon), the relMSE of one sample per pixel. At equal
// time the relMSE scales with the time per sample, which scales with C(w'):
// efficiency(w') = 1 / (relative variance(w') * seconds per sample(w')).
//
// R is bounded only while w stays away from 0 and 1: p_w'/p_w <= max(w'/w,
// (1-w')/(1-w)) for the pair's share. A weight near 0 or 1 makes the estimate
// of M at the far end of the grid heavy-tailed, so the sampling weight is kept
// inside [floor, 1 - floor] while predicting (kDefensiveFloor).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pdflab {

inline constexpr double kDefensiveFloor = 0.05;
// Where the largest single path carries more than this share of a predicted
// relative second moment, the prediction there is not to be trusted
// (WeightPrediction::largest_share).
inline constexpr double kDominantShare = 0.1;

// Densities at one diffuse vertex for the direction it drew.
struct MixtureVertex {
  float a = 0.0f;     // technique A's pdf
  float b = 0.0f;     // technique B's pdf
  float rest = 0.0f;  // sum of w_i p_i over the techniques that are not varied
  // With Russian roulette (WeightFamily::roulette): the largest component of
  // throughput * albedo at the check taken before this direction was drawn
  // (0: no check here), and the segments traced up to this vertex.
  float roulette = 0.0f;
  int segments = 0;
};

// The family of mixtures: A's share w of the pair whose total weight is `share`.
struct WeightFamily {
  double share = 1.0;     // wA + wB of the normalised weights, in (0, 1]
  bool roulette = false;  // the paths had Russian roulette (Strategy::roulette_depth > 0)
  double pdf(const MixtureVertex& v, double w) const {
    return share * (w * static_cast<double>(v.a) + (1.0 - w) * static_cast<double>(v.b)) + static_cast<double>(v.rest);
  }
};

// WeightPrediction::largest_share from the per-channel sums and largest terms:
// per grid point the largest over channels of largest / sum (1 where either is
// infinite, NaN where no channel has a moment).
std::vector<double> largest_shares(const std::vector<double>& moment_rgb, const std::vector<double>& largest_term_rgb);

// The grid of weights w' the prediction covers: `points` evenly spaced on [0, 1].
std::vector<double> weight_grid(int points);

// Clamps a weight into [floor, 1 - floor].
double defended_weight(double w, double floor = kDefensiveFloor);

struct WeightPrediction {
  std::vector<double> weight;           // the grid
  std::vector<double> relative_variance;  // mean over pixels and channels of var / (mu^2 + eps), one sample each
  std::vector<double> cost;             // expected cost of a path (segments traced)
  std::vector<double> efficiency;       // 1 / (relative_variance * seconds per pass); 0 where infinite variance
  std::uint64_t paths = 0;
  double sampling_cost = 0.0;           // mean cost of the recorded paths, at the sampling weight
  // The max-to-sum ratio of the terms F^2 R / (mu^2 + eps) whose mean is the
  // relative second moment: the largest single path's share of it, per grid
  // weight. For nonnegative terms with a finite mean it falls towards 0 as
  // paths are added (O'Brien 1980); where it stays large the second moment is
  // infinite or carried by paths too rare for the sample, and the predicted
  // variance is too low. Above kDominantShare the prediction is unreliable.
  // Per channel the largest of its channel's terms over their sum: a path
  // that carries a whole grey pixel's moment reads 100 %, not a third.
  std::vector<double> largest_share;
  // Per grid point and channel (3 values each): the sum over cells of M /
  // (mu^2 + eps), and the largest single path's part of it, what
  // largest_share divides and what pooled_prediction pools.
  std::vector<double> moment_rgb, largest_term_rgb;
  int best = -1;                        // index of the highest efficiency; -1 when none is finite
  double best_weight() const { return best >= 0 ? weight[static_cast<std::size_t>(best)] : -1.0; }
};

// The time a sample takes against the rays it traces, t = per_sample +
// per_ray * rays: a path tracer spends per ray (intersection, shading, the
// next direction) and per sample whatever the path's length (the camera ray's
// set-up, the pixel's sample point, the film's accumulation, the pass's
// bookkeeping). Counting rays alone overstates how much dearer a weight with
// longer paths is.
struct CostModel {
  double per_sample = 0.0;  // seconds
  double per_ray = 0.0;     // seconds
  bool fitted = false;      // from the runs' timing (false: the prior fixed cost)
  double seconds(double rays) const { return per_sample + per_ray * rays; }
  // The fixed cost in rays, per_sample / per_ray (0 without a per-ray cost).
  double offset() const { return per_ray > 0.0 ? per_sample / per_ray : 0.0; }
};

// A cost of rays alone (no fixed cost a sample): efficiency in units of
// 1 / (relative variance * rays), for comparing weights without timing.
inline constexpr CostModel kRaysAlone{0.0, 1.0, false};

// Least-squares fit of a CostModel to (rays per sample, seconds per sample)
// points: runs at different weights trace paths of different lengths, and
// their times tell the two costs apart.
class CostFit {
 public:
  // Points with a non-positive or non-finite value are ignored.
  void add(double rays_per_sample, double seconds_per_sample);
  // The fit when the points' rays spread by at least `min_spread` of their
  // mean and it gives a positive cost per ray (a negative fixed cost is cut to
  // 0, refitted through the origin). Otherwise the points' mean time split with
  // `prior_offset` rays of fixed cost, not `fitted`. No points: all zero.
  CostModel fit(double prior_offset, double min_spread = 0.05) const;
  std::size_t points() const { return x_.size(); }

 private:
  std::vector<double> x_, y_;
};

// The model one timed point gives: `seconds_per_sample` at `rays_per_sample`
// rays, split with `fixed_rays` rays of fixed cost per sample (CostFit's
// fall-back). What prices a prediction at its own pilot's time.
CostModel anchored_cost_model(double rays_per_sample, double seconds_per_sample, double fixed_rays);

// The prediction's efficiency under `model`: 1 / (relative variance *
// model.seconds(cost)) at each weight, and its best. The model's units are the
// efficiency's: seconds per sample of every cell gives a render's efficiency.
void apply_cost_model(WeightPrediction& prediction, const CostModel& model);

// Predictions from independent sets of paths (seeds, passes) on one grid,
// pooled, each counted by its paths: at every weight the mean relative
// variance and the mean rays (each part estimates the same quantities,
// whatever weight its paths were drawn at), and the mean sampling cost; then
// priced by `model` (apply_cost_model). Pooling the variance, not averaging
// the parts' efficiencies: 1 / V is convex, and a part whose V came out near 0
// somewhere would outvote the rest. Parts on another grid are skipped.
WeightPrediction pooled_prediction(std::span<const WeightPrediction> parts, const CostModel& model);

// Accumulates paths drawn at one sampling weight, per cell (a pixel, or a block
// of pixels), and predicts over the grid. Not thread-safe: give each thread its
// own and merge() them.
class WeightPredictor {
 public:
  // `cells`: how many cells paths are filed under. `sampling_weight`: the w the
  // paths are drawn at. `grid`: the w' to predict at.
  WeightPredictor(int cells, std::vector<double> grid, double sampling_weight, WeightFamily family);

  // One path: its estimate (RGB) at the sampling weight, the densities at each
  // of its diffuse vertices, its cost (e.g. the number of rays it traced).
  // With roulette (WeightFamily::roulette) each vertex's `roulette` and
  // `segments` must be filled in, and `cost` counts segments.
  void add_path(int cell, const float rgb[3], std::span<const MixtureVertex> vertices, double cost);
  void merge(const WeightPredictor& other);  // same cells, grid, weight and family
  void clear();

  // The prediction. `mean_rgb` holds each cell's mean (from a reference or the
  // film, 3 floats a cell; for a block cell, `mean_square_rgb` may give the
  // block's mean of mu^2 per channel, otherwise mean_rgb^2 is used).
  // `seconds_per_sample` is the measured time of one sample in every cell (one
  // pass of 1 spp) at the sampling weight, so that the efficiency is a render's
  // 1 / (relMSE * seconds); 0: efficiency in units of 1 / (relative variance * cost). `cost_offset`
  // is the per-path cost that does not scale with the path's length.
  WeightPrediction predict(const std::vector<float>& mean_rgb, double seconds_per_sample, double epsilon,
                           double cost_offset = 0.0, const std::vector<float>* mean_square_rgb = nullptr) const;

  // Per cell, the grid weight with the least predicted second moment (summed
  // over channels, relative to mu^2 + eps); -1 for a cell without paths or
  // whose moment does not depend on the weight (w does not matter there).
  std::vector<float> best_weight_map(const std::vector<float>& mean_rgb, double epsilon) const;

  // The second moment per channel of one cell at grid point g (0 without paths).
  double second_moment(int cell, std::size_t g, int channel) const;
  std::uint64_t cell_paths(int cell) const { return count_[static_cast<std::size_t>(cell)]; }
  const std::vector<double>& grid() const { return grid_; }
  double sampling_weight() const { return w_; }
  std::uint64_t paths() const { return paths_; }

 private:
  int cells_;
  std::vector<double> grid_;
  double w_;
  WeightFamily family_;
  std::vector<std::uint64_t> count_;   // per cell
  std::vector<double> moment_;         // per cell, grid point and channel: sum of F^2 R
  std::vector<double> peak_;           // per cell, grid point and channel: the largest F^2 R
  std::vector<double> cost_sum_;       // per grid point: sum of cost / R (with roulette: of the segment-by-segment cost)
  std::vector<double> offset_sum_;     // per grid point: sum of 1 / R, which should approach the path count (with roulette: the count)
  double plain_cost_sum_ = 0.0;        // sum of cost, at the sampling weight
  std::vector<double> ratio_;          // scratch: R per grid point for the path being added
  std::vector<double> path_cost_;      // scratch: with roulette, the path's cost at each grid point
  std::uint64_t paths_ = 0;
};

}  // namespace pdflab
