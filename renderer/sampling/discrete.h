#pragma once
// A discrete distribution whose sampler and pmf agree exactly: entry i is
// chosen by a uniform 32-bit integer with probability count_i / 2^32, and
// pmf(i) returns that same number. Weights are rounded to multiples of 2^-32
// once, when the distribution is built, never per sample: a float compared
// with a float CDF would realise a weight of 1e-9 as 0 or 2^-24 while the pdf
// divided by 1e-9.
//
// Used for choosing a mixture's technique and a light technique's target.
#include <cstdint>
#include <span>
#include <vector>

namespace pdflab {

class DiscreteDistribution {
 public:
  static constexpr double kResolution = 0x1.0p-32;  // the smallest nonzero probability

  // How a positive weight too small for the resolution is treated.
  enum class Tiny {
    Zero,      // it gets count 0 (the caller refuses it: zero_positive() says which)
    AtLeastOne // it gets count 1, taken from the largest entry (every target stays reachable)
  };

  DiscreteDistribution() = default;
  // Weights must be finite and >= 0 with a positive sum.
  DiscreteDistribution(std::span<const double> weights, Tiny tiny);

  int size() const { return static_cast<int>(count_.size()); }
  bool empty() const { return count_.empty(); }
  // The realised probability of entry i: exactly count_i / 2^32, rounded to float.
  float pmf(int i) const { return pmf_[static_cast<std::size_t>(i)]; }
  double pmf_exact(int i) const { return static_cast<double>(count_[static_cast<std::size_t>(i)]) * kResolution; }
  // Entry for a uniform 32-bit integer: the number of cumulative counts <= u,
  // capped at the last entry with a positive count (so zero-count entries
  // after it are never chosen), which is also how the packet tracer counts.
  int sample(std::uint32_t u) const {
    int chosen = 0;
    for (int i = 0; i + 1 < size(); ++i) chosen += u >= upper_[static_cast<std::size_t>(i)] ? 1 : 0;
    return chosen < last_positive_ ? chosen : last_positive_;
  }
  // Cumulative counts (as 32-bit thresholds, clamped) and the cap, for SIMD samplers.
  const std::vector<std::uint32_t>& thresholds() const { return upper_; }
  int last_positive() const { return last_positive_; }
  // Indices of positive weights that got count 0 (only with Tiny::Zero).
  const std::vector<int>& zero_positive() const { return zero_positive_; }

 private:
  std::vector<std::uint64_t> count_;
  std::vector<std::uint32_t> upper_;  // min(count_0 + ... + count_i, 2^32 - 1)
  std::vector<float> pmf_;
  std::vector<int> zero_positive_;
  int last_positive_ = 0;
};

}  // namespace pdflab
