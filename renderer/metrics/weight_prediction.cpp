#include "renderer/metrics/weight_prediction.h"

#include "renderer/error.h"
#include "renderer/metrics/statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace pdflab {

std::vector<double> largest_shares(const std::vector<double>& moment_rgb, const std::vector<double>& largest_term_rgb) {
  std::vector<double> share(moment_rgb.size() / 3, std::nan(""));
  for (std::size_t g = 0; g < share.size(); ++g)
    for (std::size_t c = 0; c < 3; ++c) {
      const double sum = moment_rgb[g * 3 + c], top = largest_term_rgb[g * 3 + c];
      if (!(sum > 0.0)) continue;
      // An infinite moment (a path the weight cannot draw) or term: one path is all of it.
      const double s = std::isfinite(sum) && std::isfinite(top) ? std::min(1.0, top / sum) : 1.0;
      share[g] = std::isnan(share[g]) ? s : std::max(share[g], s);
    }
  return share;
}

std::vector<double> weight_grid(int points) {
  std::vector<double> grid;
  if (points < 2) return {0.5};
  for (int i = 0; i < points; ++i) grid.push_back(static_cast<double>(i) / static_cast<double>(points - 1));
  return grid;
}

double defended_weight(double w, double floor) { return std::clamp(w, floor, 1.0 - floor); }

WeightPredictor::WeightPredictor(int cells, std::vector<double> grid, double sampling_weight, WeightFamily family)
    : cells_(cells), grid_(std::move(grid)), w_(sampling_weight), family_(family) {
  if (cells_ < 1 || grid_.empty() || !(family_.share > 0.0 && family_.share <= 1.0))
    throw InputError("weight prediction needs at least one cell, one grid weight and a share in (0, 1]");
  count_.assign(static_cast<std::size_t>(cells_), 0);
  moment_.assign(static_cast<std::size_t>(cells_) * grid_.size() * 3, 0.0);
  peak_.assign(moment_.size(), 0.0);
  cost_sum_.assign(grid_.size(), 0.0);
  offset_sum_.assign(grid_.size(), 0.0);
  ratio_.assign(grid_.size(), 1.0);
  path_cost_.assign(grid_.size(), 0.0);
}

void WeightPredictor::clear() {
  std::fill(count_.begin(), count_.end(), 0);
  std::fill(moment_.begin(), moment_.end(), 0.0);
  std::fill(peak_.begin(), peak_.end(), 0.0);
  std::fill(cost_sum_.begin(), cost_sum_.end(), 0.0);
  std::fill(offset_sum_.begin(), offset_sum_.end(), 0.0);
  plain_cost_sum_ = 0.0;
  paths_ = 0;
}

void WeightPredictor::add_path(int cell, const float rgb[3], std::span<const MixtureVertex> vertices, double cost) {
  if (cell < 0 || cell >= cells_) return;
  const std::size_t grid_size = grid_.size();
  // R(w') = prod_k p_w(k) / p_w'(k). A vertex whose direction has density 0 at
  // w' makes R infinite: at w' the path could not have been drawn.
  std::fill(ratio_.begin(), ratio_.end(), 1.0);
  if (family_.roulette) {
    // The segments before the first diffuse vertex are traced at every weight.
    std::fill(path_cost_.begin(), path_cost_.end(), vertices.empty() ? cost : static_cast<double>(vertices[0].segments));
  }
  for (std::size_t k = 0; k < vertices.size(); ++k) {
    const MixtureVertex& v = vertices[k];
    const double here = family_.pdf(v, w_);
    const double m = static_cast<double>(v.roulette);
    const double q_here = std::min(1.0, m);
    // Segments from this vertex's continuation up to the next vertex (or the
    // path's end): traced because of everything up to and including here.
    const double after = (k + 1 < vertices.size() ? static_cast<double>(vertices[k + 1].segments) : cost) -
                         static_cast<double>(v.segments);
    for (std::size_t g = 0; g < grid_size; ++g) {
      if (family_.roulette && m > 0.0) {  // survived the check
        const double q_there = std::min(1.0, m * ratio_[g]);
        if (q_there > 0.0) ratio_[g] *= q_here / q_there;  // (0 only where the path had density 0 at w)
      }
      const double there = family_.pdf(v, grid_[g]);
      ratio_[g] *= there > 0.0 ? here / there : std::numeric_limits<double>::infinity();
      if (family_.roulette) path_cost_[g] += after / ratio_[g];
    }
  }
  double* moment = &moment_[(static_cast<std::size_t>(cell) * grid_size) * 3];
  double* peak = &peak_[(static_cast<std::size_t>(cell) * grid_size) * 3];
  for (std::size_t g = 0; g < grid_size; ++g) {
    const double r = ratio_[g];
    for (int c = 0; c < 3; ++c) {
      const double f = static_cast<double>(rgb[c]);
      if (f == 0.0) continue;  // 0 * inf stays out
      const std::size_t i = g * 3 + static_cast<std::size_t>(c);
      moment[i] += f * f * r;
      peak[i] = std::max(peak[i], f * f * r);
    }
    if (family_.roulette) {
      // Summed by segment, so a plain mean: no ratio whose mean is 1 to divide by.
      cost_sum_[g] += path_cost_[g];
      offset_sum_[g] += 1.0;
      continue;
    }
    const double inverse = 1.0 / r;  // 0 for an infinite ratio
    cost_sum_[g] += cost * inverse;
    offset_sum_[g] += inverse;
  }
  plain_cost_sum_ += cost;
  ++count_[static_cast<std::size_t>(cell)];
  ++paths_;
}

void WeightPredictor::merge(const WeightPredictor& o) {
  if (o.cells_ != cells_ || o.grid_ != grid_ || o.w_ != w_ || o.family_.share != family_.share ||
      o.family_.roulette != family_.roulette)
    throw InputError("weight predictors with different cells, grids or weights cannot be merged");
  for (std::size_t i = 0; i < count_.size(); ++i) count_[i] += o.count_[i];
  for (std::size_t i = 0; i < moment_.size(); ++i) moment_[i] += o.moment_[i], peak_[i] = std::max(peak_[i], o.peak_[i]);
  for (std::size_t g = 0; g < grid_.size(); ++g) cost_sum_[g] += o.cost_sum_[g], offset_sum_[g] += o.offset_sum_[g];
  plain_cost_sum_ += o.plain_cost_sum_;
  paths_ += o.paths_;
}

double WeightPredictor::second_moment(int cell, std::size_t g, int channel) const {
  const std::uint64_t n = count_[static_cast<std::size_t>(cell)];
  if (n == 0) return 0.0;
  return moment_[(static_cast<std::size_t>(cell) * grid_.size() + g) * 3 + static_cast<std::size_t>(channel)] /
         static_cast<double>(n);
}

WeightPrediction WeightPredictor::predict(const std::vector<float>& mean_rgb, double seconds_per_sample, double epsilon,
                                          double cost_offset, const std::vector<float>* mean_square_rgb) const {
  if (mean_rgb.size() != static_cast<std::size_t>(cells_) * 3 ||
      (mean_square_rgb && mean_square_rgb->size() != mean_rgb.size()))
    throw InputError("weight prediction: the mean image does not have one RGB value per cell");
  WeightPrediction p;
  p.weight = grid_;
  p.paths = paths_;
  const std::size_t grid_size = grid_.size();
  p.relative_variance.assign(grid_size, 0.0);
  p.cost.assign(grid_size, 0.0);
  p.efficiency.assign(grid_size, 0.0);
  // Per grid point and channel: the sum over cells of M / (mu^2 + eps), and
  // the largest single path's part of it.
  std::vector<double> sum_rgb(grid_size * 3, 0.0), largest_rgb(grid_size * 3, 0.0);
  std::size_t terms = 0;
  for (int cell = 0; cell < cells_; ++cell) {
    if (count_[static_cast<std::size_t>(cell)] == 0) continue;
    for (int c = 0; c < 3; ++c) {
      const std::size_t i = static_cast<std::size_t>(cell) * 3 + static_cast<std::size_t>(c);
      const double mu = static_cast<double>(mean_rgb[i]);
      const double mu2 = mean_square_rgb ? static_cast<double>((*mean_square_rgb)[i]) : mu * mu;
      // relMSE's denominator is r^2 + eps with r the pixel's value; for a block, its mean.
      const double denominator = mu * mu + epsilon;
      // Not clipped per cell: with a few paths a cell's moment often falls
      // below mu^2, and clipping each would bias the sum upwards by an amount
      // that depends on w'. The sum over cells is clipped below.
      const double n = static_cast<double>(count_[static_cast<std::size_t>(cell)]);
      for (std::size_t g = 0; g < grid_size; ++g) {
        const double m = second_moment(cell, g, c);
        p.relative_variance[g] += (m - mu2) / denominator;
        const std::size_t k = g * 3 + static_cast<std::size_t>(c);
        sum_rgb[k] += m / denominator;
        largest_rgb[k] = std::max(
            largest_rgb[k], peak_[(static_cast<std::size_t>(cell) * grid_size + g) * 3 + static_cast<std::size_t>(c)] / (n * denominator));
      }
      ++terms;
    }
  }
  if (terms == 0 || paths_ == 0) return p;
  p.moment_rgb = std::move(sum_rgb);
  p.largest_term_rgb = std::move(largest_rgb);
  p.largest_share = largest_shares(p.moment_rgb, p.largest_term_rgb);
  // Cost at w' self-normalised by the mean of 1/R (whose expectation is 1): the
  // ratio estimate has less noise than the plain mean when R varies a lot
  // (with roulette, cost_sum_ holds the segment-by-segment sums and
  // offset_sum_ the path count: a plain mean). The measured time per sample
  // belongs to the plain mean cost at the sampling weight.
  const double cost_here = plain_cost_sum_ / static_cast<double>(paths_);
  p.sampling_cost = cost_here;
  double best = -1.0;
  for (std::size_t g = 0; g < grid_size; ++g) {
    p.relative_variance[g] = std::max(0.0, p.relative_variance[g] / static_cast<double>(terms));
    p.cost[g] = offset_sum_[g] > 0.0 ? cost_sum_[g] / offset_sum_[g] : std::numeric_limits<double>::infinity();
    const double time_scale =
        seconds_per_sample > 0.0 && cost_here + cost_offset > 0.0
            ? seconds_per_sample * (p.cost[g] + cost_offset) / (cost_here + cost_offset)
            : p.cost[g] + cost_offset;
    const double denominator = p.relative_variance[g] * time_scale;
    p.efficiency[g] = std::isfinite(denominator) && denominator > 0.0 ? 1.0 / denominator : 0.0;
    if (p.efficiency[g] > best) best = p.efficiency[g], p.best = static_cast<int>(g);
  }
  if (!(best > 0.0)) p.best = -1;
  return p;
}

void CostFit::add(double rays, double seconds) {
  if (!(rays > 0.0 && std::isfinite(rays) && seconds > 0.0 && std::isfinite(seconds))) return;
  x_.push_back(rays);
  y_.push_back(seconds);
}

CostModel CostFit::fit(double prior_offset, double min_spread) const {
  CostModel m;
  if (x_.empty()) return m;
  const double n = static_cast<double>(x_.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x_.size(); ++i) mx += x_[i] / n, my += y_[i] / n;
  const auto [lo, hi] = std::minmax_element(x_.begin(), x_.end());
  if (x_.size() >= 2 && *hi - *lo >= min_spread * mx) {
    const std::optional<std::vector<double>> line = stats::polynomial_fit(x_, y_, 1);
    if (line && (*line)[1] > 0.0) {
      m.fitted = true;
      m.per_sample = (*line)[0];
      m.per_ray = (*line)[1];
      if (m.per_sample < 0.0) {  // no negative fixed cost: all of it per ray, through the origin
        m.per_sample = 0.0;
        m.per_ray = (*stats::least_squares(x_, 1, y_))[0];  // x > 0: determined
      }
      return m;
    }
  }
  // Too little spread (or time falling with rays, which is noise): the mean
  // time, split between the fixed cost and the rays by the prior.
  const double offset = std::max(0.0, prior_offset);
  m.per_ray = my / (mx + offset);
  m.per_sample = offset * m.per_ray;
  return m;
}

CostModel anchored_cost_model(double rays_per_sample, double seconds_per_sample, double fixed_rays) {
  CostFit one;
  one.add(rays_per_sample, seconds_per_sample);
  return one.fit(fixed_rays);
}

void apply_cost_model(WeightPrediction& p, const CostModel& model) {
  p.best = -1;
  double best = -1.0;
  for (std::size_t g = 0; g < p.weight.size() && g < p.efficiency.size(); ++g) {
    const double denominator = p.relative_variance[g] * model.seconds(p.cost[g]);
    p.efficiency[g] = std::isfinite(denominator) && denominator > 0.0 ? 1.0 / denominator : 0.0;
    if (p.efficiency[g] > best) best = p.efficiency[g], p.best = static_cast<int>(g);
  }
  if (!(best > 0.0)) p.best = -1;
}

WeightPrediction pooled_prediction(std::span<const WeightPrediction> parts, const CostModel& model) {
  WeightPrediction out;
  if (parts.empty()) return out;
  out.weight = parts.front().weight;
  const std::size_t n = out.weight.size();
  out.relative_variance.assign(n, 0.0);
  out.cost.assign(n, 0.0);
  out.efficiency.assign(n, 0.0);
  double paths = 0.0;
  // The largest path of all the parts' over the sum of all their terms, per
  // channel: each part's largest term and sum are in units of its own paths
  // per cell, so both are counted by its paths.
  std::vector<double> largest(n * 3, 0.0), total(n * 3, 0.0);
  bool shares = false;
  for (const WeightPrediction& p : parts) {
    if (p.weight != out.weight || p.relative_variance.size() != n || p.cost.size() != n) continue;
    const double k = static_cast<double>(p.paths);
    if (p.moment_rgb.size() == n * 3 && p.largest_term_rgb.size() == n * 3) {
      shares = true;
      for (std::size_t i = 0; i < n * 3; ++i)
        largest[i] = std::max(largest[i], p.largest_term_rgb[i] * k), total[i] += p.moment_rgb[i] * k;
    }
    paths += k;
    out.paths += p.paths;
    out.sampling_cost += k * p.sampling_cost;
    for (std::size_t g = 0; g < n; ++g) out.relative_variance[g] += k * p.relative_variance[g], out.cost[g] += k * p.cost[g];
  }
  if (!(paths > 0.0)) return out;
  out.sampling_cost /= paths;
  for (std::size_t g = 0; g < n; ++g) out.relative_variance[g] /= paths, out.cost[g] /= paths;
  if (shares) {
    for (std::size_t i = 0; i < n * 3; ++i) largest[i] /= paths, total[i] /= paths;
    out.largest_share = largest_shares(total, largest);
    out.moment_rgb = std::move(total);
    out.largest_term_rgb = std::move(largest);
  }
  apply_cost_model(out, model);
  return out;
}

std::vector<float> WeightPredictor::best_weight_map(const std::vector<float>& mean_rgb, double epsilon) const {
  if (mean_rgb.size() != static_cast<std::size_t>(cells_) * 3)
    throw InputError("weight prediction: the mean image does not have one RGB value per cell");
  std::vector<float> map(static_cast<std::size_t>(cells_), -1.0f);
  for (int cell = 0; cell < cells_; ++cell) {
    if (count_[static_cast<std::size_t>(cell)] == 0) continue;
    double least = std::numeric_limits<double>::infinity(), most = 0.0;
    for (std::size_t g = 0; g < grid_.size(); ++g) {
      double m = 0.0;
      for (int c = 0; c < 3; ++c) {
        const double mu = static_cast<double>(mean_rgb[static_cast<std::size_t>(cell) * 3 + static_cast<std::size_t>(c)]);
        m += second_moment(cell, g, c) / (mu * mu + epsilon);
      }
      most = std::max(most, m);
      if (m < least) least = m, map[static_cast<std::size_t>(cell)] = static_cast<float>(grid_[g]);
    }
    // A moment that does not depend on w' (no light found, or only lights
    // seen directly, through no diffuse vertex) has no best weight.
    if (!(most > least * (1.0 + 1e-6))) map[static_cast<std::size_t>(cell)] = -1.0f;
  }
  return map;
}

}  // namespace pdflab
