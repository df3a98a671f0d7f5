// The `+sobol` sampler's points (renderer/sampling/sobol.h): in [0, 1),
// stratified as a (0,2)-sequence in dimensions 0 and 1 and a (1,3)-sequence
// in all three at every power-of-two prefix, before and after scrambling,
// uniform and decorrelated across seeds and draw groups; and the strategy
// spelling that turns it on.
// Vectors wider than the baseline's registers pass between inline functions
// of this file only (VectorFormsGiveTheScalarBits): GCC's note that their ABI
// differs with AVX does not apply.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
#include "renderer/sampling/rng.h"
#include "renderer/sampling/sobol.h"
#include "renderer/sampling/strategy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <set>
#include <vector>

namespace pdflab {
namespace {

// The point's dimension d in [0, 1), as the tracers use it (Rng::to_unit).
float unit(std::uint32_t bits) { return Rng::to_unit(bits); }

// Whether every elementary interval [a 2^-i, (a+1) 2^-i) x [b 2^-j, (b+1) 2^-j)
// with i + j = m holds exactly one of the 2^m points (x[n], y[n]).
bool is_02_net(const std::vector<std::uint32_t>& x, const std::vector<std::uint32_t>& y, int m) {
  for (int i = 0; i <= m; ++i) {
    const int j = m - i;
    std::vector<int> count(std::size_t{1} << m, 0);
    for (std::size_t n = 0; n < x.size(); ++n) {
      const std::uint32_t a = i ? x[n] >> (32 - i) : 0u, b = j ? y[n] >> (32 - j) : 0u;
      if (++count[(static_cast<std::size_t>(a) << j) | b] > 1) return false;
    }
  }
  return true;
}

// Whether every elementary box of volume 2^(1-m) holds exactly two of the 2^m points.
bool is_13_net(const std::vector<qmc::Point<std::uint32_t>>& p, int m) {
  const int k = m - 1;  // the box's side exponents sum to k
  for (int i = 0; i <= k; ++i)
    for (int j = 0; i + j <= k; ++j) {
      const int l = k - i - j;
      std::vector<int> count(std::size_t{1} << k, 0);
      for (const auto& q : p) {
        const std::uint32_t a = i ? q.dim[0] >> (32 - i) : 0u, b = j ? q.dim[1] >> (32 - j) : 0u,
                            c = l ? q.dim[2] >> (32 - l) : 0u;
        ++count[(((static_cast<std::size_t>(a) << j) | b) << l) | c];
      }
      for (int n : count)
        if (n != 2) return false;
    }
  return true;
}

TEST(Sobol, UnscrambledDimensionsAreSobolsAndNets) {
  // The first points of the three dimensions, known by hand.
  const std::uint32_t half = 1u << 31;
  EXPECT_EQ(qmc::sobol(1u, 0), half);
  EXPECT_EQ(qmc::sobol(1u, 1), half);
  EXPECT_EQ(qmc::sobol(1u, 2), half);
  EXPECT_EQ(qmc::sobol(2u, 0), half >> 1);
  EXPECT_EQ(qmc::sobol(2u, 1), 3u << 30);  // 0.75
  EXPECT_EQ(qmc::sobol(2u, 2), 3u << 30);  // m_2 = 3: 0.75
  EXPECT_EQ(qmc::sobol(3u, 2), (3u << 30) ^ half);  // 0.25
  for (int m = 0; m <= 12; ++m) {
    std::vector<std::uint32_t> x, y;
    std::vector<qmc::Point<std::uint32_t>> p;
    for (std::uint32_t n = 0; n < (1u << m); ++n) {
      x.push_back(qmc::sobol(n, 0)), y.push_back(qmc::sobol(n, 1));
      p.push_back({{x.back(), y.back(), qmc::sobol(n, 2)}});
    }
    EXPECT_TRUE(is_02_net(x, y, m)) << "2^" << m;
    if (m >= 1 && m <= 10) {
      EXPECT_TRUE(is_13_net(p, m)) << "2^" << m;
    }
  }
  // The reversed columns the scramble uses (looked up four bits at a time) are
  // the columns reversed, for every index they take.
  for (std::uint32_t n = 0; n < (1u << qmc::kIndexBits); ++n)
    for (int d = 0; d < 3; ++d) ASSERT_EQ(qmc::sobol_reversed(n, d), qmc::reverse_bits(qmc::sobol(n, d))) << n;
}

// The packet tracer's vectors of 4, 8 and 16 lanes (each computed its own way:
// bit by bit, or by lane-wise look-ups in one or two vectors) give the one-path
// tracer's bits, lane by lane: the points, their 16-bit products and the
// unscrambled 32-bit ones.
typedef std::uint32_t Lanes4 __attribute__((vector_size(16)));
typedef std::uint32_t Lanes8 __attribute__((vector_size(32)));
typedef std::uint32_t Lanes16 __attribute__((vector_size(64)));
template <class UV>
void expect_vector_points_match() {
  constexpr int Lanes = static_cast<int>(sizeof(UV) / sizeof(std::uint32_t));
  const std::uint32_t seeds[] = {0u, 1u, 0x9e3779b9u, 0xdeadbeefu};
  for (std::uint32_t seed : seeds)
    for (std::uint32_t first = 0; first < (1u << 17); first += 997u * Lanes) {
      UV index, block_seed;
      for (int l = 0; l < Lanes; ++l) index[l] = first + 131u * static_cast<std::uint32_t>(l), block_seed[l] = seed + l;
      const qmc::Point<UV> p = qmc::point(index, block_seed, 3);
      for (int d = 0; d < 3; ++d) {
        const UV r = qmc::sobol_reversed(index & 0xffffu, d), b = qmc::reverse_bits(index);
        const UV u = qmc::sobol(index * 40503u, d);  // all 32 bits (the pixel jitter's)
        for (int l = 0; l < Lanes; ++l) {
          ASSERT_EQ(p.dim[d][l], qmc::point(index[l], block_seed[l], 3).dim[d]) << Lanes << " lanes, " << index[l];
          ASSERT_EQ(r[l], qmc::sobol_reversed(index[l] & 0xffffu, d));
          ASSERT_EQ(u[l], qmc::sobol(index[l] * 40503u, d));
          ASSERT_EQ(b[l], qmc::reverse_bits(index[l]));
        }
      }
    }
}
TEST(Sobol, VectorFormsGiveTheScalarBits) {
  expect_vector_points_match<Lanes4>();
  expect_vector_points_match<Lanes8>();
  expect_vector_points_match<Lanes16>();
}

TEST(Sobol, OwenScrambleIsABijectionThatKeepsPrefixes) {
  // A bit depends only on the bits above it: values sharing their top k bits
  // are mapped to values sharing their top k bits, and none collide.
  for (std::uint32_t seed : {0u, 1u, 0xdeadbeefu}) {
    std::set<std::uint32_t> seen;
    for (std::uint32_t v = 0; v < 65536; ++v) {
      const std::uint32_t w = qmc::owen_scramble(v << 16, seed);
      EXPECT_TRUE(seen.insert(w >> 16).second) << "collision at " << v;
      if (v % 2 == 1) {
        EXPECT_EQ(w >> 17, qmc::owen_scramble((v - 1) << 16, seed) >> 17);
      }
    }
  }
  EXPECT_NE(qmc::owen_scramble(0x12345678u, 1u), qmc::owen_scramble(0x12345678u, 2u));
}

TEST(Sobol, ScrambledPrefixesStayNetsForEverySeed) {
  for (std::uint32_t pixel = 0; pixel < 6; ++pixel)
    for (const qmc::Group g : {qmc::Group::Continuation, qmc::Group::Light, qmc::Group::Specular})
      for (std::uint32_t depth = 0; depth < 2; ++depth) {
        const std::uint32_t pixel_seed = qmc::hash(pixel * 977u + 3u);
        for (int m = 0; m <= 11; ++m) {
          std::vector<std::uint32_t> x, y;
          std::vector<qmc::Point<std::uint32_t>> p;
          for (std::uint32_t n = 0; n < (1u << m); ++n) {
            p.push_back(qmc::group_point(n, pixel_seed, depth, g, 3));
            x.push_back(p.back().dim[0]), y.push_back(p.back().dim[1]);
            for (int d = 0; d < 3; ++d) {
              const float u = unit(p.back().dim[d]);
              ASSERT_TRUE(u >= 0.0f && u < 1.0f) << u;
            }
          }
          ASSERT_TRUE(is_02_net(x, y, m)) << "2^" << m << " pixel " << pixel;
          if (m >= 1 && m <= 9) {
            ASSERT_TRUE(is_13_net(p, m)) << "2^" << m << " pixel " << pixel;
          }
        }
      }
}

TEST(Sobol, BlocksBeyondTheIndexBitsAreScrambledAfresh) {
  // Sample i and sample i + 2^16 are different points, and each block of 2^16
  // is stratified on its own.
  const std::uint32_t seed = 0x1234u;
  int same = 0;
  std::vector<std::uint32_t> x, y;
  for (std::uint32_t n = 0; n < 1024; ++n) {
    const auto a = qmc::point(n, seed), b = qmc::point(n + (1u << qmc::kIndexBits), seed);
    same += a.dim[0] == b.dim[0];
    x.push_back(b.dim[0]), y.push_back(b.dim[1]);
  }
  EXPECT_EQ(same, 0);
  EXPECT_TRUE(is_02_net(x, y, 10));
}

// The mean and the correlation of two sets of uniforms.
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
  ma /= static_cast<double>(a.size()), mb /= static_cast<double>(b.size());
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    sab += (a[i] - ma) * (b[i] - mb), saa += (a[i] - ma) * (a[i] - ma), sbb += (b[i] - mb) * (b[i] - mb);
  return sab / std::sqrt(saa * sbb);
}

TEST(Sobol, SeedsAndGroupsDecorrelate) {
  // Across 20000 pixels, one sample index: each dimension is uniform (its mean
  // and the share in each eighth), and the points of different pixels, of
  // different groups and depths of one pixel, and of the camera's own pair
  // are uncorrelated. Four standard errors of a correlation of 20000 pairs: 0.028.
  constexpr int kPixels = 20000;
  for (std::uint32_t index : {0u, 1u, 5u, 100u}) {
    std::vector<double> cont[3], light[3], deeper[3], next_pixel[3];
    std::vector<int> eighths(8, 0);
    for (std::uint32_t pixel = 0; pixel < kPixels; ++pixel) {
      const std::uint32_t s = static_cast<std::uint32_t>(mix64(pixel * 2654435761ull + 17u));
      const std::uint32_t t = static_cast<std::uint32_t>(mix64((pixel + 1u) * 2654435761ull + 17u));
      const auto c = qmc::group_point(index, s, 0u, qmc::Group::Continuation, 3);
      const auto l = qmc::group_point(index, s, 0u, qmc::Group::Light, 3);
      const auto d = qmc::group_point(index, s, 1u, qmc::Group::Continuation, 3);
      const auto n = qmc::group_point(index, t, 0u, qmc::Group::Continuation, 3);
      for (int k = 0; k < 3; ++k) {
        cont[k].push_back(unit(c.dim[k])), light[k].push_back(unit(l.dim[k]));
        deeper[k].push_back(unit(d.dim[k])), next_pixel[k].push_back(unit(n.dim[k]));
        ++eighths[c.dim[k] >> 29];
      }
    }
    for (int k = 0; k < 3; ++k) {
      double mean = 0;
      for (double v : cont[k]) mean += v;
      mean /= kPixels;
      EXPECT_NEAR(mean, 0.5, 4.0 * std::sqrt(1.0 / 12.0 / kPixels)) << "index " << index << " dim " << k;
      for (int j = 0; j < 3; ++j) {
        EXPECT_LT(std::abs(correlation(cont[k], light[j])), 0.028) << index << " " << k << " " << j;
        EXPECT_LT(std::abs(correlation(cont[k], deeper[j])), 0.028) << index << " " << k << " " << j;
        EXPECT_LT(std::abs(correlation(cont[k], next_pixel[j])), 0.028) << index << " " << k << " " << j;
        if (j != k) {
          EXPECT_LT(std::abs(correlation(cont[k], cont[j])), 0.028) << index << " " << k << " " << j;
        }
      }
    }
    for (int e : eighths) EXPECT_NEAR(e, 3 * kPixels / 8, 4.0 * std::sqrt(3.0 * kPixels / 8.0)) << "index " << index;
  }
}

TEST(Sobol, StrategySpelling) {
  EXPECT_FALSE(Strategy::parse("mix:cosine=0.5,light=0.5").sobol);
  const Strategy s = Strategy::parse("mix:cosine=0.5,light=0.5+sobol");
  EXPECT_TRUE(s.sobol);
  EXPECT_EQ(s.to_string(), "mix:cosine=0.5,light=0.5+sobol");
  EXPECT_EQ(Strategy::parse("nee-mis+sobol+rr:2").to_string(), "nee-mis+sobol+rr:2");
  EXPECT_EQ(Strategy::parse("nee-mis+rr:2+sobol").to_string(), "nee-mis+sobol+rr:2");  // either order
  EXPECT_EQ(Strategy::parse("nee-mis+mix:cosine=0.5,light=0.5+sobol").weights,
            Strategy::parse("nee-mis+mix:cosine=0.5,light=0.5").weights);
  EXPECT_TRUE(Strategy::parse("fastest+sobol").sobol);
  for (const char* text : {"cosine+sobol", "nee-mis:balance+light-sa+sobol+rr", "light+sobol"}) {
    const Strategy a = Strategy::parse(text);
    EXPECT_EQ(Strategy::parse(a.to_string()), a) << text;
  }
  EXPECT_THROW(Strategy::parse("cosine+sobol+sobol"), std::exception);
  EXPECT_THROW(Strategy::parse("sobol"), std::exception);
  EXPECT_THROW(Strategy::parse("cosine+sobo"), std::exception);
}

}  // namespace
}  // namespace pdflab
