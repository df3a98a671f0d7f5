#pragma once
// Deterministic random numbers. A sample's stream depends only on
// (seed, pixel, sample index), never on which thread renders it.
#include <pcg_random.hpp>

#include <cstdint>

namespace pdflab {

// SplitMix64 finaliser: a strong 64-bit mix, used to derive independent streams.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

class Rng {
 public:
  Rng(std::uint64_t state, std::uint64_t stream) : pcg_(state, stream) {}
  Rng() : Rng(0, 0) {}  // a placeholder until a stream is assigned

  // The stream for one pixel sample.
  static Rng for_sample(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample) {
    return for_sample_keyed(seed_key(seed), pixel, sample);
  }
  // The same with the seed's part computed once for many samples.
  static constexpr std::uint64_t seed_key(std::uint64_t seed) { return mix64(seed); }
  static Rng for_sample_keyed(std::uint64_t seed_key, std::uint64_t pixel, std::uint64_t sample) {
    const std::uint64_t key = mix64(seed_key ^ (pixel * 0x9e3779b97f4a7c15ULL + sample));
    return Rng(key, mix64(key ^ 0x632be59bd9b4e019ULL));
  }

  // Uniform in [0, 1): 24 random bits, exact in float, never 1.
  float uniform() { return static_cast<float>(pcg_() >> 8) * 0x1.0p-24f; }
  std::uint32_t next_u32() { return pcg_(); }

 private:
  pcg32 pcg_;
};

}  // namespace pdflab
