#include "renderer/sampling/guiding.h"

#include "renderer/sampling/leaf.h"
#include "renderer/scene/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <functional>
#include <limits>

namespace pdflab {

namespace {

// A record's units at most: 2^24 of the brightest emission's, so 2^24 records
// of that size still fit a slot.
constexpr double kMostUnits = 0x1.0p40;
// After the first pass the scale puts the largest record of the pass before
// at 2^36 units: records down to 2^-36 of it count, and 2^28 of that size
// still fit a slot. (The brightest emission alone misjudges a scene whose
// brightest light is not what lights it: the box beside a beacon 10^9 times
// brighter took records of under one unit, and learned nothing.)
constexpr double kLargestUnits = 0x1.0p36;

// leaf::guide_learned_light reads the root's row at float 11.
static_assert(offsetof(GuidingDistribution::QuadNode, light) == 11 * sizeof(float));

const GuidingDistribution::QuadNode kUniformRoot{{1.0f, 1.0f, 1.0f, 1.0f}, {0, 0, 0, 0}, 0.5f, {0.5f, 0.5f}};

// The energy recorded in a collecting node's four quadrants.
double total_energy(const std::uint64_t (&energy)[4]) {
  return static_cast<double>(energy[0]) + static_cast<double>(energy[1]) + static_cast<double>(energy[2]) +
         static_cast<double>(energy[3]);
}

// The two halves of the box lo..hi split at `split` along `axis`: lo..below_hi and above_lo..hi.
void halves(const Vec3& lo, const Vec3& hi, int axis, float split, Vec3& below_hi, Vec3& above_lo) {
  below_hi = hi;
  above_lo = lo;
  below_hi[axis] = split;
  above_lo[axis] = split;
}

// The energy of each quadrant of a leaf's collecting nodes that the next
// distribution keeps. A draw consumes the 24 bits of a float in [0, 1) down
// the tree, so a cell holding less than about 2^-24 of the leaf could not be
// reached as often as its density says (not at all below 2^-24): cells under
// kGuidingDrawableShare of the leaf's energy are given none, so that their
// density is 0 where the draw cannot go, and every cell the density keeps is
// drawn within about 2^-24 / kGuidingDrawableShare of its probability.
std::vector<std::array<double, 4>> drawable_energy(const std::vector<GuidingTrainer::CollectNode>& nodes) {
  std::vector<std::array<double, 4>> kept(nodes.size(), std::array<double, 4>{0.0, 0.0, 0.0, 0.0});
  const double least = total_energy(nodes[0].energy) * kGuidingDrawableShare;
  const std::function<double(std::size_t)> keep = [&](std::size_t node) {
    double sum = 0.0;
    for (int c = 0; c < 4; ++c) {
      const double e = static_cast<double>(nodes[node].energy[c]);
      if (!(e >= least)) continue;
      // An inner quadrant keeps what its cells keep.
      const std::int32_t child = nodes[node].child[c];
      kept[node][static_cast<std::size_t>(c)] = child ? keep(static_cast<std::size_t>(child)) : e;
      sum += kept[node][static_cast<std::size_t>(c)];
    }
    return sum;
  };
  keep(0);
  return kept;
}

}  // namespace

SquarePoint square_from_direction(const Vec3& direction) {
  SquarePoint p;
  leaf::guide_square(direction, p.s, p.t);
  return p;
}

Vec3 direction_from_square(float s, float t) { return leaf::guide_direction(s, t); }

// ---- GuidingDistribution ---------------------------------------------------------

void GuidingDistribution::QuadNode::derive() {
  double p[4];
  for (int c = 0; c < 4; ++c) p[c] = 0.25 * factor[c];
  left = static_cast<float>(p[0] + p[2]);
  for (int x = 0; x < 2; ++x) {
    const double column = p[x] + p[x + 2];
    low[x] = column > 0.0 ? static_cast<float>(p[x] / column) : 0.5f;
  }
}

GuidingDistribution::GuidingDistribution(const Vec3& lo, const Vec3& hi)
    : lo_(lo), hi_(hi), nodes_{kUniformRoot}, roots_(kGuidingNormalBins, 0) {
  for (int k = 0; k < kGuidingNormalBins; ++k) spatial_.push_back({-1, 0.0f, 0, k});
}

int guiding_normal_bin(const Vec3& normal) { return leaf::guide_normal_bin(normal); }

int GuidingDistribution::leaf_at(const Vec3& point, const Vec3& normal) const {
  auto i = static_cast<std::size_t>(guiding_normal_bin(normal));
  while (spatial_[i].axis >= 0) {
    const SpatialNode& n = spatial_[i];
    i = static_cast<std::size_t>(n.child + (point[n.axis] >= n.split ? 1 : 0));
  }
  return spatial_[i].leaf;
}

GuidingDistribution::Sample GuidingDistribution::sample(const Vec3& point, const Vec3& normal, float u1,
                                                        float u2) const {
  Sample s;
  leaf::guide_sample(*this, leaf::guide_root(*this, point, normal, true), u1, u2, true, s.direction, s.pdf);
  return s;
}

float GuidingDistribution::pdf(const Vec3& point, const Vec3& normal, const Vec3& direction) const {
  const SquarePoint p = square_from_direction(direction);
  return leaf::guide_density(*this, leaf::guide_root(*this, point, normal, true), p.s, p.t, true);
}

std::vector<Vec3> GuidingDistribution::density_edges(const Vec3& point, const Vec3& normal, int per_edge) const {
  std::vector<Vec3> out;
  const std::function<void(std::int32_t, double, double, double)> cells = [&](std::int32_t at, double ox, double oy,
                                                                             double size) {
    const QuadNode& n = node(at);
    const double half = 0.5 * size;
    // The node's two inner edges, where its quadrants meet.
    for (int k = 0; k <= per_edge; ++k) {
      const double f = (k + 0.5) / (per_edge + 1);
      out.push_back(direction_from_square(static_cast<float>(ox + half), static_cast<float>(oy + f * size)));
      out.push_back(direction_from_square(static_cast<float>(ox + f * size), static_cast<float>(oy + half)));
    }
    for (int c = 0; c < 4; ++c)
      if (n.child[c]) cells(n.child[c], ox + (c & 1) * half, oy + (c >> 1) * half, half);
  };
  cells(root(leaf_at(point, normal)), 0.0, 0.0, 1.0);
  return out;
}

std::vector<GuidingDistribution::Cell> GuidingDistribution::cells(int leaf) const {
  std::vector<Cell> out;
  const std::function<void(std::int32_t, float, float, float, double)> walk = [&](std::int32_t at, float s, float t,
                                                                                float size, double density) {
    const QuadNode& n = node(at);
    const float half = 0.5f * size;
    for (int c = 0; c < 4; ++c) {
      const float cs = s + static_cast<float>(c & 1) * half, ct = t + static_cast<float>(c >> 1) * half;
      const double d = density * n.factor[c];
      if (n.child[c]) walk(n.child[c], cs, ct, half, d);
      else out.push_back({cs, ct, half, static_cast<float>(d / (4.0 * kPi))});
    }
  };
  walk(root(leaf), 0.0f, 0.0f, 1.0f, 1.0);
  return out;
}

void GuidingDistribution::leaf_box(const Vec3& point, const Vec3& normal, Vec3& lo, Vec3& hi) const {
  lo = lo_;
  hi = hi_;
  auto i = static_cast<std::size_t>(guiding_normal_bin(normal));
  while (spatial_[i].axis >= 0) {
    const SpatialNode& n = spatial_[i];
    Vec3 below_hi, above_lo;
    halves(lo, hi, n.axis, n.split, below_hi, above_lo);
    const bool above = point[n.axis] >= n.split;
    if (above) lo = above_lo;
    else hi = below_hi;
    i = static_cast<std::size_t>(n.child + (above ? 1 : 0));
  }
}

GuidingDistribution::Stats GuidingDistribution::stats() const {
  Stats s;
  s.leaves = leaves();
  s.nodes = nodes_.size();
  s.bytes = spatial_.size() * sizeof(SpatialNode) + nodes_.size() * sizeof(QuadNode) +
            roots_.size() * sizeof(std::int32_t);
  const std::function<int(std::int32_t)> depth = [&](std::int32_t at) {
    int deepest = 0;
    for (int c = 0; c < 4; ++c)
      if (node(at).child[c]) deepest = std::max(deepest, depth(node(at).child[c]));
    return deepest + 1;
  };
  for (const std::int32_t r : roots_) s.max_depth = std::max(s.max_depth, depth(r));
  return s;
}

// ---- GuidingTrainer --------------------------------------------------------------

namespace {

// The box around the scene's objects, a little larger: its low corner, or its high one.
Vec3 scene_box(const Scene& scene, bool high) {
  Vec3 lo(std::numeric_limits<float>::max());
  Vec3 hi(-std::numeric_limits<float>::max());
  const auto grow = [&](const Vec3& p) {
    lo = min(lo, p);
    hi = max(hi, p);
  };
  for (const Quad& q : scene.quads) {
    grow(q.q);
    grow(q.q + q.u);
    grow(q.q + q.v);
    grow(q.q + q.u + q.v);
  }
  for (const Sphere& s : scene.spheres) {
    grow(s.center - Vec3(s.radius));
    grow(s.center + Vec3(s.radius));
  }
  if (lo.x > hi.x) lo = hi = Vec3(0.0f);
  const Vec3 margin = (hi - lo) * 1e-3f + Vec3(1e-6f);
  return high ? hi + margin : lo - margin;
}

// The scene's brightest emission (1 where nothing emits).
double brightest_emission(const Scene& scene) {
  double most = 0.0;
  for (const Material& m : scene.materials) most = std::max(most, luminance(m.emit.x, m.emit.y, m.emit.z));
  return most > 0.0 ? most : 1.0;
}

}  // namespace

GuidingTrainer::GuidingTrainer(const Scene& scene)
    : GuidingTrainer(scene_box(scene, false), scene_box(scene, true), 0x1.0p24 / brightest_emission(scene)) {}

GuidingTrainer::GuidingTrainer(const Vec3& lo, const Vec3& hi, double scale)
    : scale_(scale), leaves_(kGuidingNormalBins), current_(std::make_shared<GuidingDistribution>(lo, hi)) {
  for (Leaf& leaf : leaves_) leaf.nodes.push_back(CollectNode{{0, 0, 0, 0}, {0, 0, 0, 0}});
}

GuidingTrainer::~GuidingTrainer() = default;

void GuidingTrainer::record(const Vec3& point, const Vec3& normal, const Vec3& direction, double energy) {
  Leaf& leaf = leaves_[static_cast<std::size_t>(current_->leaf_at(point, normal))];
  std::atomic_ref<std::uint64_t>(leaf.count).fetch_add(1, std::memory_order_relaxed);
  if (!(energy > 0.0)) return;  // no light (or not a number): counted, nothing added
  // The pass's largest finite record: a positive double's bits order as it
  // does, and the largest of a set is the same whatever order it arrives in.
  std::uint64_t bits;
  std::memcpy(&bits, &energy, sizeof bits);
  std::atomic_ref<std::uint64_t> largest(largest_bits_);
  for (std::uint64_t seen = largest.load(std::memory_order_relaxed);
       std::isfinite(energy) && bits > seen &&
       !largest.compare_exchange_weak(seen, bits, std::memory_order_relaxed);) {
  }
  const double units = std::min(std::floor(energy * scale_ + 0.5), kMostUnits);
  if (units >= 1.0) collect(leaf, square_from_direction(direction), static_cast<std::uint64_t>(units));
}

void GuidingTrainer::collect(Leaf& leaf, const SquarePoint& p, std::uint64_t units) {
  float s = p.s, t = p.t;
  std::int32_t node = 0;
  for (;;) {
    CollectNode& n = leaf.nodes[static_cast<std::size_t>(node)];
    const int c = leaf::guide_quadrant(s, t);
    if (n.child[c] == 0) {
      std::atomic_ref<std::uint64_t>(n.energy[c]).fetch_add(units, std::memory_order_relaxed);
      return;
    }
    node = n.child[c];
  }
}

void GuidingTrainer::finish_pass() {
  // 1. Each quadrant's energy: its own where it is a leaf cell, its subtree's otherwise.
  for (Leaf& leaf : leaves_) {
    // (The nodes are only written, never added: references into them hold.)
    const std::function<std::uint64_t(std::int32_t)> total = [&](std::int32_t node) {
      CollectNode& n = leaf.nodes[static_cast<std::size_t>(node)];
      std::uint64_t sum = 0;
      for (int c = 0; c < 4; ++c) {
        if (n.child[c]) n.energy[c] = total(n.child[c]);
        sum += n.energy[c];
      }
      return sum;
    };
    total(0);
  }
  for (const Leaf& leaf : leaves_) records_total_ += leaf.count;

  // 2. The S-tree: a leaf with too many records splits across its longest side.
  const double threshold = kGuidingSpatialThreshold * std::sqrt(std::ldexp(1.0, passes_));
  std::vector<GuidingDistribution::SpatialNode> spatial(static_cast<std::size_t>(kGuidingNormalBins));
  std::vector<Leaf> leaves;
  std::vector<float> light;  // per new leaf, its old leaf's mean record (-1: none)
  const std::function<void(std::size_t, const Leaf&, std::uint64_t, float, Vec3, Vec3, int)> place =
      [&](std::size_t at, const Leaf& leaf, std::uint64_t count, float mean, Vec3 lo, Vec3 hi, int depth) {
        const Vec3 size = hi - lo;
        const int axis = size.x >= size.y && size.x >= size.z ? 0 : size.y >= size.z ? 1 : 2;
        if (static_cast<double>(count) > threshold && depth < 40) {
          const float split = 0.5f * (lo[axis] + hi[axis]);
          if (split > lo[axis] && split < hi[axis]) {
            const auto child = static_cast<std::int32_t>(spatial.size());
            spatial[at] = {axis, split, child, -1};
            spatial.resize(spatial.size() + 2);
            Vec3 mid_hi, mid_lo;
            halves(lo, hi, axis, split, mid_hi, mid_lo);
            place(static_cast<std::size_t>(child), leaf, count / 2, mean, lo, mid_hi, depth + 1);
            place(static_cast<std::size_t>(child) + 1, leaf, count - count / 2, mean, mid_lo, hi, depth + 1);
            return;
          }
        }
        spatial[at] = {-1, 0.0f, 0, static_cast<std::int32_t>(leaves.size())};
        leaves.push_back(leaf);
        leaves.back().count = count;
        light.push_back(mean);
      };
  const std::function<void(std::size_t, std::size_t, Vec3, Vec3, int)> rebuild = [&](std::size_t old, std::size_t at,
                                                                                      Vec3 lo, Vec3 hi, int depth) {
    const GuidingDistribution::SpatialNode& n = current_->spatial_[old];
    if (n.axis < 0) {
      const Leaf& leaf = leaves_[static_cast<std::size_t>(n.leaf)];
      // The mean record: the sum of the units over their number, in radiance.
      const float mean =
          leaf.count > 0 ? static_cast<float>(total_energy(leaf.nodes[0].energy) / scale_ / static_cast<double>(leaf.count))
                         : -1.0f;
      place(at, leaf, leaf.count, mean, lo, hi, depth);
      return;
    }
    const auto child = static_cast<std::int32_t>(spatial.size());
    spatial[at] = {n.axis, n.split, child, -1};
    spatial.resize(spatial.size() + 2);
    Vec3 mid_hi, mid_lo;
    halves(lo, hi, n.axis, n.split, mid_hi, mid_lo);
    rebuild(static_cast<std::size_t>(n.child), static_cast<std::size_t>(child), lo, mid_hi, depth + 1);
    rebuild(static_cast<std::size_t>(n.child) + 1, static_cast<std::size_t>(child) + 1, mid_lo, hi, depth + 1);
  };
  for (std::size_t k = 0; k < static_cast<std::size_t>(kGuidingNormalBins); ++k)
    rebuild(k, k, current_->lo(), current_->hi(), 0);

  // 3. The next distribution: each leaf's energies as shares.
  auto next = std::shared_ptr<GuidingDistribution>(new GuidingDistribution());
  next->lo_ = current_->lo();
  next->hi_ = current_->hi();
  next->roots_.resize(leaves.size());
  for (std::size_t k = 0; k < leaves.size(); ++k) {
    const std::vector<CollectNode>& nodes = leaves[k].nodes;
    const auto first = static_cast<std::int32_t>(next->nodes_.size());
    next->roots_[k] = first;
    if (total_energy(nodes[0].energy) == 0.0) {
      next->nodes_.push_back(kUniformRoot);
      next->nodes_.back().light = light[k];
      continue;
    }
    const std::vector<std::array<double, 4>> kept = drawable_energy(nodes);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const CollectNode& n = nodes[i];
      const std::array<double, 4>& e = kept[i];
      const double sum = e[0] + e[1] + e[2] + e[3];
      GuidingDistribution::QuadNode q{};
      for (int c = 0; c < 4; ++c) {
        q.factor[c] = sum > 0.0 ? static_cast<float>(4.0 * e[c] / sum) : 1.0f;
        q.child[c] = n.child[c] ? first + n.child[c] : 0;
      }
      q.derive();
      if (i == 0) q.light = light[k];
      next->nodes_.push_back(q);
    }
  }
  for (GuidingDistribution::SpatialNode& n : spatial)
    if (n.axis < 0) n.child = next->roots_[static_cast<std::size_t>(n.leaf)];
  next->spatial_ = std::move(spatial);

  // 4. The D-trees the next pass records into: cells above kGuidingSplitShare
  // of their leaf's energy split (where a cell was a leaf, its energy is
  // taken as spread evenly over its quadrants), the rest merged; energies reset.
  for (Leaf& leaf : leaves) {
    const CollectNode& root = leaf.nodes[0];
    const double leaf_total = total_energy(root.energy);
    std::vector<CollectNode> refined;
    // A node for a square holding `energy[c]` in its quadrants (`old`: its node
    // in the old tree, -1: none, the energy spread evenly), at `depth`.
    const std::function<std::int32_t(std::int32_t, const double*, int)> build = [&](std::int32_t old,
                                                                                      const double* energy, int depth) {
      const auto index = static_cast<std::int32_t>(refined.size());
      refined.push_back(CollectNode{{0, 0, 0, 0}, {0, 0, 0, 0}});
      for (int c = 0; c < 4; ++c) {
        if (!(leaf_total > 0.0) || energy[c] / leaf_total <= kGuidingSplitShare || depth + 1 >= kGuidingMaxDepth)
          continue;
        double below[4];
        std::int32_t old_child = -1;
        if (old >= 0 && leaf.nodes[static_cast<std::size_t>(old)].child[c]) {
          old_child = leaf.nodes[static_cast<std::size_t>(old)].child[c];
          for (int k = 0; k < 4; ++k)
            below[k] = static_cast<double>(leaf.nodes[static_cast<std::size_t>(old_child)].energy[k]);
        } else {
          for (double& b : below) b = 0.25 * energy[c];
        }
        const std::int32_t child = build(old_child, below, depth + 1);
        refined[static_cast<std::size_t>(index)].child[c] = child;
      }
      return index;
    };
    const double energy[4] = {static_cast<double>(root.energy[0]), static_cast<double>(root.energy[1]),
                              static_cast<double>(root.energy[2]), static_cast<double>(root.energy[3])};
    build(0, energy, 0);
    leaf.nodes = std::move(refined);
    leaf.count = 0;
  }

  // The next pass's units, from this one's largest record.
  double largest;
  std::memcpy(&largest, &largest_bits_, sizeof largest);
  if (largest > 0.0 && std::isfinite(largest)) scale_ = kLargestUnits / largest;
  largest_bits_ = 0;

  leaves_ = std::move(leaves);
  current_ = std::move(next);
  ++passes_;
}

}  // namespace pdflab
