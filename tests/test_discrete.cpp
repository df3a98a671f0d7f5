// The discrete distribution chooses entry i for exactly count_i of the 2^32
// possible 32-bit integers, and its pmf is count_i / 2^32: sampler and pmf
// agree exactly, for any positive weight the resolution can hold.
#include "renderer/sampling/discrete.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <vector>

namespace pdflab {
namespace {

// Walks the boundaries: the integers that choose entry i are exactly
// [C_{i-1}, C_i), so their number is pmf(i) * 2^32 (and none for a zero entry).
void expect_exact(const DiscreteDistribution& d) {
  std::uint64_t start = 0;
  double total = 0.0;
  for (int i = 0; i < d.size(); ++i) {
    const auto count = static_cast<std::uint64_t>(d.pmf_exact(i) * 0x1.0p32);
    total += d.pmf_exact(i);
    if (count == 0) continue;
    EXPECT_EQ(d.sample(static_cast<std::uint32_t>(start)), i) << "first integer of entry " << i;
    EXPECT_EQ(d.sample(static_cast<std::uint32_t>(start + count - 1)), i) << "last integer of entry " << i;
    if (start > 0) {
      EXPECT_NE(d.sample(static_cast<std::uint32_t>(start - 1)), i);
    }
    EXPECT_EQ(static_cast<double>(d.pmf(i)), static_cast<double>(static_cast<float>(d.pmf_exact(i))));
    start += count;
  }
  EXPECT_EQ(start, std::uint64_t{1} << 32);
  EXPECT_EQ(total, 1.0);
}

TEST(Discrete, HalvesSplitAtTwoToThe31) {
  const std::vector<double> w = {0.5, 0.5};
  const DiscreteDistribution d(w, DiscreteDistribution::Tiny::Zero);
  EXPECT_EQ(d.pmf(0), 0.5f);
  EXPECT_EQ(d.sample(0x7fffffffu), 0);
  EXPECT_EQ(d.sample(0x80000000u), 1);
  expect_exact(d);
}

TEST(Discrete, ABillionthIsRealisedAndThePmfSaysExactlyWhat) {
  // A float CDF compared with a 24-bit uniform would give 1e-9 a probability of
  // 0 or 2^-24 (60 times too often); here it is 4 / 2^32 and the pmf says so.
  const std::vector<double> w = {1e-9, 1.0};
  const DiscreteDistribution d(w, DiscreteDistribution::Tiny::Zero);
  EXPECT_TRUE(d.zero_positive().empty());
  EXPECT_EQ(d.pmf_exact(0), 4.0 * 0x1.0p-32);
  EXPECT_EQ(d.sample(3), 0);
  EXPECT_EQ(d.sample(4), 1);
  expect_exact(d);
}

TEST(Discrete, WeightsBelowTheResolutionAreReportedOrKeptReachable) {
  const std::vector<double> w = {1e-45, 1.0, 3e-12};
  const DiscreteDistribution refused(w, DiscreteDistribution::Tiny::Zero);
  EXPECT_EQ(refused.zero_positive(), (std::vector<int>{0, 2}));
  EXPECT_EQ(refused.pmf(0), 0.0f);
  expect_exact(refused);
  const DiscreteDistribution kept(w, DiscreteDistribution::Tiny::AtLeastOne);
  EXPECT_TRUE(kept.zero_positive().empty());
  EXPECT_EQ(kept.pmf_exact(0), 0x1.0p-32);
  EXPECT_EQ(kept.pmf_exact(2), 0x1.0p-32);
  expect_exact(kept);
}

TEST(Discrete, ZeroEntriesAreNeverChosenWhereverTheyStand) {
  for (const std::vector<double>& w : std::vector<std::vector<double>>{
           {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, {0, 2, 0, 3, 0}, {1}, {0.1, 0.2, 0.3, 0.4}}) {
    const DiscreteDistribution d(w, DiscreteDistribution::Tiny::Zero);
    for (const std::uint32_t u : {0u, 1u, 0x80000000u, 0xfffffffeu, 0xffffffffu}) {
      const int i = d.sample(u);
      ASSERT_GE(i, 0);
      ASSERT_LT(i, d.size());
      EXPECT_GT(w[static_cast<std::size_t>(i)], 0.0) << "u " << u;
    }
    expect_exact(d);
  }
}

TEST(Discrete, PowerRatiosOfABillionKeepTheirProportion) {
  // Two lights, one 1e9 times brighter, in either order.
  for (const std::vector<double>& w : std::vector<std::vector<double>>{{1.0, 1e9}, {1e9, 1.0}}) {
    const DiscreteDistribution d(w, DiscreteDistribution::Tiny::AtLeastOne);
    const int dim = w[0] < w[1] ? 0 : 1;
    EXPECT_NEAR(d.pmf_exact(dim), 1e-9, 0.5 * 0x1.0p-32);
    expect_exact(d);
  }
}

TEST(Discrete, BadWeightsAreRefused) {
  EXPECT_THROW(DiscreteDistribution(std::vector<double>{0, 0}, DiscreteDistribution::Tiny::Zero), std::invalid_argument);
  EXPECT_THROW(DiscreteDistribution(std::vector<double>{-1, 2}, DiscreteDistribution::Tiny::Zero), std::invalid_argument);
  EXPECT_THROW(DiscreteDistribution(std::vector<double>{std::numeric_limits<double>::infinity()},
                                    DiscreteDistribution::Tiny::Zero),
               std::invalid_argument);
}

}  // namespace
}  // namespace pdflab
