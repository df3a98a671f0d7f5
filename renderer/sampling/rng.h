#pragma once
// Deterministic random numbers. A sample's stream depends only on
// (seed, pixel, sample index), never on which thread renders it.
#include <cmath>
#include <cstdint>

// Always inlined where it runs on vectors: in the packet tracer it then
// compiles inside its instruction set's target region, on its vectors whole.
#if defined(__GNUC__)
#define PDFLAB_LANES inline __attribute__((always_inline))
#else
#define PDFLAB_LANES inline
#endif

namespace pdflab {

// SplitMix64 finaliser: a strong 64-bit mix, used to derive independent streams.
// For one word or for a vector of 64-bit lanes (the packet tracer's sample starts).
template <class U>
PDFLAB_LANES constexpr U mix64_lanes(U x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}
constexpr std::uint64_t mix64(std::uint64_t x) { return mix64_lanes(x); }

// PCG32 (O'Neill's XSH RR 64/32 with a selectable stream): the same numbers as
// pcg-cpp's pcg32 (tests/test_sampling_unit.cpp compares them), written out so
// that the packet tracer can step eight streams at once with the same arithmetic.
class Rng {
 public:
  static constexpr std::uint64_t kMultiplier = 6364136223846793005ULL;

  Rng(std::uint64_t seed, std::uint64_t stream)
      : increment_(stream_increment(stream)), state_(stream_start(seed, increment_)) {}

  // The stream for one pixel sample.
  static Rng for_sample(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample) {
    return for_sample_keyed(seed_key(seed), pixel, sample);
  }
  // The same with the seed's part computed once for many samples.
  static constexpr std::uint64_t seed_key(std::uint64_t seed) { return mix64(seed); }
  static Rng for_sample_keyed(std::uint64_t seed_key, std::uint64_t pixel, std::uint64_t sample) {
    const std::uint64_t key = sample_key(seed_key, pixel, sample);
    return Rng(key, sample_stream(key));
  }
  // for_sample_keyed's parts, for one word or for vectors of 64-bit lanes: the
  // seed and stream of a pixel sample, and the state and increment they give.
  template <class U>
  PDFLAB_LANES static constexpr U sample_key(std::uint64_t seed_key, U pixel, U sample) {
    return mix64_lanes(seed_key ^ (pixel * 0x9e3779b97f4a7c15ULL + sample));
  }
  template <class U>
  PDFLAB_LANES static constexpr U sample_stream(U key) {
    return mix64_lanes(key ^ 0x632be59bd9b4e019ULL);
  }
  template <class U>
  PDFLAB_LANES static constexpr U stream_increment(U stream) {
    return (stream << 1) | 1u;
  }
  template <class U>
  PDFLAB_LANES static constexpr U stream_start(U seed, U increment) {
    return (seed + increment) * kMultiplier + increment;
  }

  std::uint32_t next_u32() {
    const std::uint64_t old = state_;
    state_ = old * kMultiplier + increment_;
    return output(old);
  }
  // Uniform in [0, 1): 24 random bits, exact in float, never 1.
  float uniform() { return to_unit(next_u32()); }

  // The parts, for stepping many streams in SIMD lanes, and back.
  static Rng from_parts(std::uint64_t state, std::uint64_t increment) { return Rng(Parts{}, state, increment); }
  std::uint64_t state() const { return state_; }
  std::uint64_t increment() const { return increment_; }
  static std::uint32_t output(std::uint64_t old) {
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18) ^ old) >> 27);
    const auto rot = static_cast<std::uint32_t>(old >> 59);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  static float to_unit(std::uint32_t bits) { return static_cast<float>(bits >> 8) * 0x1.0p-24f; }

  // The sample's key for the `+sobol` sampler's stratified draws
  // (renderer/sampling/sobol.h): its index within the pixel and the pixel's
  // scramble seed, both from (seed, pixel, sample index). Unused otherwise.
  std::uint32_t qmc_index = 0, qmc_seed = 0;

 private:
  struct Parts {};
  Rng(Parts, std::uint64_t state, std::uint64_t increment) : increment_(increment), state_(state) {}
  std::uint64_t increment_;  // odd; selects the stream
  std::uint64_t state_;
};

// u1's last cell refined. Rng::uniform's 24 bits put 1 - u1 on a grid of
// 2^-24, so a warp that raises 1 - u1 to a small power (cosine-power's
// (1 - u1)^(1 / (N + 1))) never reaches the directions that 1 - u1 < 2^-24
// maps to. Where u1 is the largest value (kLargestUniform: 1 - u1 = 2^-24, the
// cell (0, 2^-24]), this draws the point within that cell with relative
// precision: 2^-(k + 1) (1 + m 2^-32), k geometric (the zero bits before the
// first one bit, up to kTailWords words of them) and m the next word, and
// returns log2(1 - u1) itself, -24 - (k + 1) + log2(1 + m 2^-32), down to
// -281 (every bit zero). `next` gives 32 random bits; it is called at most
// kTailWords + 1 times, and the same numbers give the same value in every
// tracer (one scalar formula).
inline constexpr float kLargestUniform = 1.0f - 0x1.0p-24f;
inline constexpr int kTailWords = 8;
template <class Next>
float uniform_tail_log2(Next next) {
  int zeros = 0;
  std::uint32_t word = 0;
  for (int i = 0; i < kTailWords && word == 0; ++i) {
    word = next();
    zeros += word == 0 ? 32 : __builtin_clz(word);
  }
  const std::uint32_t mantissa = next();
  return static_cast<float>(-24.0 - (zeros + 1) + std::log2(1.0 + static_cast<double>(mantissa) * 0x1.0p-32));
}

}  // namespace pdflab
