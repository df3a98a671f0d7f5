#pragma once
// Randomized quasi-Monte Carlo: Owen-scrambled Sobol points, for the `+sobol`
// sampler (Strategy::sobol).
//
// The first three Sobol dimensions (van der Corput, and the primitive
// polynomials x + 1 and x^2 + x + 1) are scrambled by a hash-based nested
// uniform scramble in the manner of Laine and Karras (2011) and Burley
// (2020, "Practical Hash-based Owen Scrambling"): a bit of the point is
// flipped by a hash of the bits above it only, so every elementary interval
// of the unscrambled net maps onto one of the same shape and the net's
// stratification is kept, while each point is uniform in [0,1)^3. Each draw
// group of a sample (one vertex's continuation, its light sample, a specular
// bounce) takes the point of its own shuffled sample index, the index itself
// Owen-scrambled with the group's seed (Burley's padding), so groups are
// mutually independent while each is stratified across a pixel's samples.
//
// Every function is a template over the integer type: std::uint32_t for the
// one-path tracer, a vector of uint32 lanes (GCC vector extensions) for the
// packet tracer, so both compute the same bits with the same code.
#include <cstdint>
#include <cstring>
#include <type_traits>

// Always inlined, so that in the packet tracer they compile inside its
// instruction set's target region, on its vectors whole.
#if defined(__GNUC__)
#define PDFLAB_QMC inline __attribute__((always_inline))
#else
#define PDFLAB_QMC inline
#endif

namespace pdflab::qmc {

// How many bits a dimension of the point has (the word's width; how many
// samples are stratified in full is kIndexBits, below).
inline constexpr int kBits = 32;

// Each step swaps neighbouring groups of bits as a bitwise select of the word
// shifted down and up (one AVX-512 ternary-logic instruction after the shifts).
template <class U>
PDFLAB_QMC constexpr U reverse_bits(const U& bits) {
  U v = bits;
  v = ((v >> 1) & 0x55555555u) | ((v << 1) & 0xaaaaaaaau);
  v = ((v >> 2) & 0x33333333u) | ((v << 2) & 0xccccccccu);
  v = ((v >> 4) & 0x0f0f0f0fu) | ((v << 4) & 0xf0f0f0f0u);
  v = ((v >> 8) & 0x00ff00ffu) | ((v << 8) & 0xff00ff00u);
  return (v >> 16) | (v << 16);
}

// The generator matrices' columns of Sobol's dimensions 1 and 2 (dimension 0,
// van der Corput, is the bit reversal): column k is the point of index 2^k.
// Bratley and Fox's recurrence with the direction numbers m = (1) for x + 1
// and m = (1, 3) for x^2 + x + 1.
struct Directions {
  std::uint32_t column[2][kBits]{};
};
constexpr Directions make_directions() {
  Directions d;
  // x + 1 (degree 1): v_k = v_{k-1} ^ (v_{k-1} >> 1).
  d.column[0][0] = 1u << 31;
  for (int k = 1; k < kBits; ++k) d.column[0][k] = d.column[0][k - 1] ^ (d.column[0][k - 1] >> 1);
  // x^2 + x + 1 (degree 2, a_1 = 1): v_k = v_{k-1} ^ v_{k-2} ^ (v_{k-2} >> 2).
  d.column[1][0] = 1u << 31;  // m_1 = 1
  d.column[1][1] = 3u << 30;  // m_2 = 3
  for (int k = 2; k < kBits; ++k)
    d.column[1][k] = d.column[1][k - 1] ^ d.column[1][k - 2] ^ (d.column[1][k - 2] >> 2);
  return d;
}
inline constexpr Directions kDirections = make_directions();

// A 32-bit integer hash (a two-multiply xorshift finaliser), for seeds.
template <class U>
PDFLAB_QMC U hash(const U& value) {
  U x = value;
  x ^= x >> 16;
  x *= 0x21f0aaadu;
  x ^= x >> 15;
  x *= 0x735a2d97u;
  return x ^ (x >> 15);
}

// Laine and Karras's permutation, applied to bit-reversed words: an addition
// and products by even constants carry only towards the more significant bits,
// so bit j of the result depends on bits j and below alone. On reversed words
// that is a nested uniform (Owen) scramble: a bit of the value is flipped by a
// hash of the bits above it.
template <class U>
PDFLAB_QMC U laine_karras(const U& value, const U& seed) {
  U v = value + seed;
  v ^= v * 0x6c50b47cu;
  v ^= v * 0xb82f1e52u;
  v ^= v * 0xc7afe638u;
  v ^= v * 0x8d22f6e6u;
  return v;
}

// Owen scramble of v by `seed` (a bijection of [0, 2^32)).
template <class U>
PDFLAB_QMC U owen_scramble(const U& v, const U& seed) {
  return reverse_bits(laine_karras(reverse_bits(v), seed));
}

// The stratified points are made from the low kIndexBits of the sample index;
// each further block of 2^kIndexBits samples takes a scramble of its own.
inline constexpr int kIndexBits = 16;

// reverse_bits(sobol(i, dim)) for i below 2^kIndexBits: the columns reversed,
// so that the scramble, which works on reversed words, needs no reversal first.
struct ReversedDirections {
  std::uint32_t column[2][kIndexBits]{};
};
constexpr ReversedDirections make_reversed_directions() {
  ReversedDirections r;
  for (int d = 0; d < 2; ++d)
    for (int k = 0; k < kIndexBits; ++k) r.column[d][k] = reverse_bits(kDirections.column[d][k]);
  return r;
}
inline constexpr ReversedDirections kReversedDirections = make_reversed_directions();

// A product by a generator matrix over GF(2) (the XOR of the columns that the
// index's set bits name), four index bits at a time: chunk k of the index
// selects, from a table of sixteen, the XOR of columns 4k to 4k + 3 that its
// bits name.
template <int Columns>
struct ChunkTables {
  static constexpr int kChunks = Columns / 4;
  std::uint32_t xor_of[2][kChunks][16]{};  // by dimension 1 or 2, chunk, chunk value
};
template <int Columns>
constexpr ChunkTables<Columns> make_chunk_tables(const std::uint32_t (&columns)[2][Columns]) {
  ChunkTables<Columns> t;
  for (int d = 0; d < 2; ++d)
    for (int k = 0; k < ChunkTables<Columns>::kChunks; ++k)
      for (std::uint32_t bits = 0; bits < 16; ++bits)
        for (int b = 0; b < 4; ++b)
          if ((bits >> b) & 1u) t.xor_of[d][k][bits] ^= columns[d][4 * k + b];
  return t;
}
inline constexpr ChunkTables<kBits> kSobolTables = make_chunk_tables(kDirections.column);
inline constexpr ChunkTables<kIndexBits> kReversedTables = make_chunk_tables(kReversedDirections.column);

template <class U, int Columns>
PDFLAB_QMC U gf2_product(const U& index, const std::uint32_t (&table)[Columns / 4][16],
                         const std::uint32_t (&columns)[Columns]) {
  constexpr int chunks = Columns / 4;
  if constexpr (std::is_integral_v<U>) {
    U result = 0;
    for (int k = 0; k < chunks; ++k) result ^= table[k][(index >> (4 * k)) & 15u];
    return result;
  } else {
    U result = index ^ index;  // zero, of U's type
#if defined(__GNUC__) && !defined(__clang__)
    constexpr int lanes = static_cast<int>(sizeof(U) / sizeof(std::uint32_t));
    if constexpr (lanes == 8 || lanes == 16) {
      // A table of sixteen is one vector of sixteen lanes, or two of eight:
      // one lane-wise look-up (a permute) a chunk.
      for (int k = 0; k < chunks; ++k) {
        const U chunk = (index >> (4 * k)) & 15u;
        if constexpr (lanes == 16) {
          U t;
          std::memcpy(&t, table[k], sizeof t);
          result ^= __builtin_shuffle(t, chunk);
        } else {
          U low, high;
          std::memcpy(&low, table[k], sizeof low);
          std::memcpy(&high, table[k] + lanes, sizeof high);
          result ^= __builtin_shuffle(low, high, chunk);
        }
      }
      return result;
    }
#endif
    // Narrower vectors (and clang, which has no look-up by lane): bit by bit.
    for (int k = 0; k < Columns; ++k) result ^= columns[k] & (0u - ((index >> k) & 1u));
    return result;
  }
}

// Sobol dimension `dim` (0, 1 or 2) of point `index`, unscrambled, as 32 bits.
template <class U>
PDFLAB_QMC U sobol(const U& index, int dim) {
  if (dim == 0) return reverse_bits(index);
  return gf2_product<U, kBits>(index, kSobolTables.xor_of[dim - 1], kDirections.column[dim - 1]);
}

// reverse_bits(sobol(i, dim)) for i below 2^kIndexBits (its low kIndexBits bits).
template <class U>
PDFLAB_QMC U sobol_reversed(const U& index, int dim) {
  if (dim == 0) return index;  // van der Corput is the reversal itself
  return gf2_product<U, kIndexBits>(index, kReversedTables.xor_of[dim - 1], kReversedDirections.column[dim - 1]);
}

// What each draw group of a vertex is, for its seed.
enum class Group : std::uint32_t { Continuation = 0, Light = 1, Specular = 2 };
// The vertices (by path depth: the camera ray is segment 0) whose draws are
// stratified; the draws of deeper vertices stay independent. The first alone:
// stratifying the second as well (`fastest`, 100x100, equal samples, seeds
// 11-13) lowered relMSE by 0-4% on the shipped scenes and cost 5-8% more time a
// sample, so it was 1-8% less efficient on every one of them.
inline constexpr int kDepths = 1;

// The seed of draw group `group` at the vertex reached by segment `depth` of a
// sample whose pixel seed is `pixel_seed`.
template <class U>
PDFLAB_QMC U group_seed(const U& pixel_seed, const U& depth, Group group) {
  return hash(pixel_seed ^ hash(depth * 4u + (static_cast<std::uint32_t>(group) + 1u)));
}

// The group's point for sample `index` of the pixel: `dims` (at most three)
// dimensions of an Owen-scrambled Sobol point at the group's shuffled index
// (Burley's padding: the index itself Owen-scrambled by the seed), as 32 bits
// each (bits >> 8 scaled by 2^-24 is the uniform in [0, 1), Rng::to_unit).
// Dimensions 0 and 1 form a (0,2)-sequence; with dimension 2 the three form a
// (1,3)-sequence. The shuffle keeps every block of 2^k consecutive indices
// (k <= kIndexBits) a block of 2^k indices of the sequence, up to bits below
// the 2^-k strata that the value's scramble randomises anyway.
template <class U>
struct Point {
  U dim[3];
};
template <class U>
PDFLAB_QMC Point<U> point(const U& index, const U& block_seed, int dims = 3) {
  const U seed = hash(block_seed ^ (index >> kIndexBits));
  // The shuffled index, its low kIndexBits bits only (the others are the
  // seed's, the same for every sample of the block).
  const U shuffled = owen_scramble(index, seed) & ((1u << kIndexBits) - 1u);
  Point<U> p{};
  for (int d = 0; d < dims; ++d)
    p.dim[d] = reverse_bits(laine_karras(sobol_reversed(shuffled, d), hash(seed + 0x9e3779b9u * (d + 1u))));
  return p;
}

// The point of draw group `group` at the vertex reached by segment `depth`,
// for sample `index` of the pixel whose seed is `pixel_seed` (Rng::qmc_*).
template <class U>
PDFLAB_QMC Point<U> group_point(const U& index, const U& pixel_seed, const U& depth, Group group, int dims) {
  return point(index, group_seed(pixel_seed, depth, group), dims);
}

}  // namespace pdflab::qmc
