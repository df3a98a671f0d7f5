#pragma once
// Path guiding: a density over directions learned from the paths already
// traced, the `guided` technique's (techniques/guided.inc). The structure is
// Müller, Gross and Novák's SD-tree ("Practical Path Guiding for Efficient
// Light-Transport Simulation", 2017): a binary tree over the scene's box
// (S-tree) whose leaves each hold a quadtree over the sphere of directions
// (D-tree). docs/guiding.md explains it for a student.
//
// The D-tree lives on the sphere's cylindrical map (s, t) = ((z + 1) / 2,
// phi / 2 pi), which preserves area: dw = 4 pi ds dt, so a cell's share of the
// square is its share of the sphere, and a density q on the square is
// q / (4 pi) in solid angle. A node splits its square into four quadrants
// (child c = x + 2 y, x the half in s, y the half in t) and keeps each one's
// share of its energy; drawing descends it: the half in s by its share, the
// half in t by its share within that column, the random numbers rescaled at
// each level (the 2D inverse CDF of a piecewise-constant density, made
// adaptive), then uniformly within the leaf cell. The density is the product
// of 4 x share down the cells visited, over 4 pi.
//
// Learning (GuidingTrainer) runs in passes: a pass renders with the current
// distribution and records at each diffuse vertex the radiance that arrived
// along the drawn direction times its cosine to the normal, divided by that
// direction's density (each record an estimate of the light the surface
// takes in through its cell: the cosine is the diffuse BRDF's share of the
// product f L cos that a continuation's weight divides by its density).
// Then each S-tree leaf that took more than kSpatialThreshold sqrt(2^pass)
// records splits in half across its longest side (both halves keep its
// D-tree); each leaf's recorded energies become its next distribution (cells
// under kDrawableShare of the leaf's given none); and the D-trees the next
// pass records into are refined from them: a cell holding more than
// kSplitShare of its leaf's energy is split, finer cells holding less are
// merged, down to kMaxDepth levels. Records are added as integers (fixed
// point, in units set from the pass before's largest record), so a pass's
// sums, and with them every tree, are the same for any thread count and any
// order of the records.
#include "renderer/math.h"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace pdflab {

struct Scene;

// The cylindrical map and back (unit directions; (s, t) in [0, 1)^2): the
// leaf math's (leaf::guide_square, leaf::guide_direction), in float.
struct SquarePoint {
  float s, t;
};
SquarePoint square_from_direction(const Vec3& direction);
Vec3 direction_from_square(float s, float t);

inline constexpr int kGuidingMaxDepth = 16;  // D-tree levels at most
inline constexpr double kGuidingSplitShare = 0.01;  // a cell above this share of its leaf's energy is split
inline constexpr double kGuidingDrawableShare = 0x1.0p-16;  // a cell below this share of its leaf's energy gets none
inline constexpr double kGuidingSpatialThreshold = 16000.0;  // records before a leaf splits, times sqrt(2^pass)
// The S-tree is six trees, one for the surfaces that face each way along each
// axis (the normal's largest component and its sign): a floor and the wall
// beside it never share a distribution, which would send half a floor's
// guided samples into the floor, towards light that only the wall receives.
inline constexpr int kGuidingNormalBins = 6;
int guiding_normal_bin(const Vec3& normal);  // 2 axis + (component < 0)

// What `guided` samples: immutable while a pass renders with it. Its trees
// are tables of 64-byte rows, which the packet tracer reads for all its lanes
// at once (lane_rows16): the draw and the density are leaf math
// (leaf_math.inc: guide_root, guide_sample, guide_density), one definition for
// both tracers; the functions here are their one-lane forms.
class GuidingDistribution {
 public:
  // One D-tree node: the density's factor in each quadrant (4 x its share of
  // the node's energy; all 1 in a node without energy: uniform), its child
  // node (0: the quadrant is a leaf cell; a root is never a child), the
  // probability of the half s < 1/2, and in each half of s the probability
  // of the half t < 1/2.
  struct alignas(64) QuadNode {
    float factor[4];
    std::int32_t child[4];
    float left;
    float low[2];
    // In a D-tree's root: the mean of the records its leaf took in the pass
    // it was learned from (an estimate of the light a surface there takes
    // in, the integral of L cos over the sphere), -1 where it took none
    // (untrained) and in every other node. The roulette by the learned light
    // reads it (leaf::guide_learned_light).
    float light = -1.0f;
    float unused[4] = {};  // kept zero, so that trees compare byte by byte
    // The fields after factor, from it.
    void derive();
  };
  // One S-tree node (the first kGuidingNormalBins are the trees' roots): an interior node (axis >= 0) splits its box at `split`
  // along `axis` into nodes `child` (below) and `child + 1`; a leaf (axis -1)
  // is leaf number `leaf`, and `child` is its D-tree's root node.
  struct alignas(64) SpatialNode {
    std::int32_t axis;
    float split;
    std::int32_t child;
    std::int32_t leaf;
    float unused[12] = {};
  };
  struct Sample {
    Vec3 direction;
    float pdf;
  };
  struct Stats {
    int leaves = 0;         // S-tree leaves
    std::size_t nodes = 0;  // D-tree nodes, over all leaves
    int max_depth = 0;      // of the deepest D-tree
    std::size_t bytes = 0;  // the trees' memory
  };

  // Untrained: one leaf over `lo`..`hi` whose D-tree is the uniform sphere.
  GuidingDistribution(const Vec3& lo, const Vec3& hi);

  // A direction drawn at `point` of a surface facing `normal` from u1, u2 in
  // [0, 1), with its density in solid angle (the density of the direction
  // returned, as pdf() gives it).
  Sample sample(const Vec3& point, const Vec3& normal, float u1, float u2) const;
  // The density in solid angle of unit `direction` there.
  float pdf(const Vec3& point, const Vec3& normal, const Vec3& direction) const;
  // The S-tree leaf holding `point` in the tree of `normal`'s bin (a point
  // outside the box: the leaf on its side).
  int leaf_at(const Vec3& point, const Vec3& normal) const;
  int leaves() const { return static_cast<int>(roots_.size()); }
  // Leaf `leaf`'s D-tree: its root, and any node of it.
  std::int32_t root(int leaf) const { return roots_[static_cast<std::size_t>(leaf)]; }
  const QuadNode& node(std::int32_t i) const { return nodes_[static_cast<std::size_t>(i)]; }
  // One leaf cell of a D-tree: its square [s, s + size) x [t, t + size) in
  // the map, and the density there per steradian.
  struct Cell {
    float s, t, size;
    float pdf;
  };
  // Leaf `leaf`'s D-tree as its cells (the 2D picture of the quadtree; the
  // cells tile the unit square, so sum(pdf x size^2) x 4 pi = 1).
  std::vector<Cell> cells(int leaf) const;
  // The box of the S-tree leaf holding `point` (in the tree of `normal`'s bin).
  void leaf_box(const Vec3& point, const Vec3& normal, Vec3& lo, Vec3& hi) const;
  // Points on the edges between the cells of `point`'s D-tree, `per_edge` on
  // each inner edge of each node, as unit directions: where the density may
  // jump (for the chi-square harness).
  std::vector<Vec3> density_edges(const Vec3& point, const Vec3& normal, int per_edge) const;
  Stats stats() const;
  const Vec3& lo() const { return lo_; }
  const Vec3& hi() const { return hi_; }
  // The tables the leaf math reads.
  const float* spatial_rows() const { return reinterpret_cast<const float*>(spatial_.data()); }
  const float* node_rows() const { return reinterpret_cast<const float*>(nodes_.data()); }
  const std::vector<QuadNode>& nodes() const { return nodes_; }

 private:
  friend class GuidingTrainer;
  GuidingDistribution() = default;
  Vec3 lo_{0.0f}, hi_{0.0f};
  std::vector<SpatialNode> spatial_;
  std::vector<QuadNode> nodes_;  // every leaf's D-tree, one after another
  std::vector<std::int32_t> roots_;  // per leaf
};

// Learns a GuidingDistribution pass by pass (see the top of this file).
class GuidingTrainer {
 public:
  // Over the scene's objects' box; `scale`: the first pass's records are kept
  // as integers in units of 1 / scale (the scene's brightest emission over
  // 2^24 by default); each later pass's in units that put the largest record
  // of the pass before at 2^36.
  explicit GuidingTrainer(const Scene& scene);
  GuidingTrainer(const Vec3& lo, const Vec3& hi, double scale);
  ~GuidingTrainer();
  GuidingTrainer(const GuidingTrainer&) = delete;
  GuidingTrainer& operator=(const GuidingTrainer&) = delete;

  // What the pass in progress samples with (the untrained sphere before the first pass ends).
  std::shared_ptr<const GuidingDistribution> distribution() const { return current_; }
  // One record: at `point` of a surface facing `normal`, light `energy` (>= 0: radiance over the drawn
  // direction's density) arrived along unit `direction`. Any thread, at once.
  void record(const Vec3& point, const Vec3& normal, const Vec3& direction, double energy);
  // Ends a pass: the S-tree split, the next distribution, the refined D-trees.
  void finish_pass();
  int passes() const { return passes_; }
  std::uint64_t records() const { return records_total_; }

  // A node of a D-tree being recorded into: each quadrant's energy and child.
  struct CollectNode {
    std::uint64_t energy[4];
    std::int32_t child[4];
  };

 private:
  struct Leaf {  // of current_'s S-tree, by its leaf number
    std::vector<CollectNode> nodes;
    std::uint64_t count = 0;
  };
  void collect(Leaf& leaf, const SquarePoint& p, std::uint64_t units);

  double scale_ = 1.0;  // units a record's energy is counted in: 1 / scale_
  std::uint64_t largest_bits_ = 0;  // the pass's largest record (a double's bits)
  int passes_ = 0;
  std::uint64_t records_total_ = 0;
  std::vector<Leaf> leaves_;
  std::shared_ptr<const GuidingDistribution> current_;
};

}  // namespace pdflab
