#include "renderer/sampling/discrete.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pdflab {

DiscreteDistribution::DiscreteDistribution(std::span<const double> weights, Tiny tiny) {
  constexpr std::uint64_t kTotal = std::uint64_t{1} << 32;
  double sum = 0.0;
  for (double w : weights) {
    if (!(w >= 0.0) || !std::isfinite(w)) throw std::invalid_argument("DiscreteDistribution: a weight is negative or not finite");
    sum += w;
  }
  if (!(sum > 0.0)) throw std::invalid_argument("DiscreteDistribution: the weights sum to zero");
  const std::size_t n = weights.size();
  count_.assign(n, 0);
  std::uint64_t assigned = 0;
  std::size_t largest = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double share = weights[i] / sum;
    std::uint64_t c = static_cast<std::uint64_t>(std::llround(std::ldexp(share, 32)));
    if (weights[i] > 0.0 && c == 0) {
      if (tiny == Tiny::AtLeastOne) c = 1;
      else zero_positive_.push_back(static_cast<int>(i));
    }
    count_[i] = c;
    assigned += c;
    if (weights[i] > weights[largest]) largest = i;
  }
  // Rounding leaves the total a few counts off 2^32: the largest entry absorbs
  // it (its relative change is at most n * 2^-32 / (1/n)).
  if (assigned > kTotal) count_[largest] -= assigned - kTotal;
  else count_[largest] += kTotal - assigned;

  upper_.resize(n);
  pmf_.resize(n);
  std::uint64_t running = 0;
  for (std::size_t i = 0; i < n; ++i) {
    running += count_[i];
    upper_[i] = static_cast<std::uint32_t>(std::min<std::uint64_t>(running, kTotal - 1));
    pmf_[i] = static_cast<float>(static_cast<double>(count_[i]) * kResolution);
    if (count_[i] > 0) last_positive_ = static_cast<int>(i);
  }
}

}  // namespace pdflab
