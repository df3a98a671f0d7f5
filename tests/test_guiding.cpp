// Path guiding (renderer/sampling/guiding.h, the `guided` technique): the
// cylindrical map, the SD-tree's density against its sampler (chi-square, the
// density integrating to one) untrained and at several trained states, what
// it learns from known light, the training's independence from the thread
// count, and the guided mixtures' images against cosine's.
#include "renderer/integrator/packet.h"
#include "renderer/metrics/chi_square.h"
#include "renderer/metrics/probe.h"
#include "renderer/metrics/statistics.h"
#include "renderer/sampling/guiding.h"
#include "renderer/scene/scene_loader.h"
#include "tests/render_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace pdflab {
namespace {

constexpr double kPi = 3.141592653589793;

TEST(GuidingMap, CylindricalMapRoundTripsAndPreservesArea) {
  Rng rng(3, 5);
  for (int i = 0; i < 100000; ++i) {
    const float s = rng.uniform(), t = rng.uniform();
    const Vec3 d = direction_from_square(s, t);
    ASSERT_NEAR(length(d), 1.0f, 1e-6f);
    const SquarePoint p = square_from_direction(d);
    ASSERT_NEAR(p.s, s, 1e-6) << i;
    // t wraps at 1: compared on the circle, as a distance on the sphere
    // (the azimuth of a direction near a pole is as uncertain as it is near).
    const double dt = std::fabs(static_cast<double>(p.t) - t);
    const double r = std::sqrt(std::max(0.0, 1.0 - static_cast<double>(d.z) * d.z));
    ASSERT_LT(2.0 * kPi * std::min(dt, 1.0 - dt) * r, 1e-6) << i;
  }
  // Area preservation: the square's lower half is the lower hemisphere, a
  // band of s of width w is a band of z of width 2w (Archimedes).
  EXPECT_NEAR(direction_from_square(0.5f, 0.3f).z, 0.0f, 1e-7f);
  EXPECT_NEAR(direction_from_square(0.75f, 0.3f).z, 0.5f, 1e-7f);
}

// Records drawn uniformly over the sphere, of energy `bright` within
// `degrees` of `towards` and 1 elsewhere, at points spread over the box.
void teach(GuidingTrainer& trainer, const Vec3& towards, double degrees, double bright, int records,
           std::uint64_t seed) {
  Rng rng(seed, 7);
  const double cos_cone = std::cos(degrees * kPi / 180.0);
  for (int i = 0; i < records; ++i) {
    const Vec3 d = direction_from_square(rng.uniform(), rng.uniform());
    const Vec3 p(rng.uniform(), rng.uniform(), rng.uniform());
    const double energy = dot(d, towards) >= cos_cone ? bright : 1.0;
    trainer.record(p, Vec3(0.0f, 0.0f, 1.0f), d, energy * 4.0 * kPi);  // radiance over the uniform density
  }
  trainer.finish_pass();
}

// Where the density jumps: the edges of the D-tree's cells at `point`, about +z.
std::vector<chi_square::Point> dtree_edges(const GuidingDistribution& g, const Vec3& point,
                                           const chi_square::Frame& frame) {
  std::vector<chi_square::Point> out;
  for (const Vec3& d : g.density_edges(point, Vec3(0.0f, 0.0f, 1.0f), 48)) out.push_back(frame.coordinates(d));
  return out;
}

// The distribution's own sampler against its density at `point`: chi-square
// on a grid that the top cells align with, and the density's integral.
void expect_sampler_follows_density(const GuidingDistribution& g, const Vec3& point, std::uint64_t seed) {
  const chi_square::Frame frame(Vec3(0.0f, 0.0f, 1.0f));
  const chi_square::Grid grid(16, 32);
  const chi_square::Draw draw = [&](Rng& rng) {
    const float u1 = rng.uniform(), u2 = rng.uniform();
    const GuidingDistribution::Sample s = g.sample(point, Vec3(0.0f, 0.0f, 1.0f), u1, u2);
    return DirectionSample{s.direction, s.pdf};
  };
  const chi_square::Density density = [&](const Vec3& d) { return static_cast<double>(g.pdf(point, Vec3(0.0f, 0.0f, 1.0f), d)); };
  const chi_square::Outcome o = chi_square::run(grid, frame, draw, density, dtree_edges(g, point, frame), seed, 400000);
  EXPECT_NEAR(o.integral, 1.0, 2e-3);
  EXPECT_EQ(o.bad_pdf, 0u);
  EXPECT_EQ(o.pdf_mismatch, 0u);
  EXPECT_TRUE(o.passed(1e-3)) << "p = " << o.chi.p_value << ", zero-cell hits " << o.chi.zero_cell_hits;
}

TEST(GuidingDistribution, UntrainedIsTheUniformSphere) {
  const GuidingDistribution g(Vec3(0.0f), Vec3(1.0f));
  EXPECT_EQ(g.leaves(), kGuidingNormalBins);
  Rng rng(1, 1);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 d = direction_from_square(rng.uniform(), rng.uniform());
    EXPECT_FLOAT_EQ(g.pdf(Vec3(0.5f), d, d), static_cast<float>(1.0 / (4.0 * kPi)));
  }
  expect_sampler_follows_density(g, Vec3(0.5f), 11);
}

TEST(GuidingTrainer, LearnsWhereTheLightComesFrom) {
  GuidingTrainer trainer(Vec3(0.0f), Vec3(1.0f), 1024.0);
  const Vec3 towards = normalize(Vec3(0.3f, -0.5f, 0.8f));
  // A cone of 12 degrees 200 times brighter than the rest: it holds
  // 200 (1 - cos 12) / (200 (1 - cos 12) + (1 + cos 12)) of the light.
  const double c = std::cos(12.0 * kPi / 180.0);
  const double share = 200.0 * (1.0 - c) / (200.0 * (1.0 - c) + (1.0 + c));
  for (int pass = 0; pass < 3; ++pass) {
    teach(trainer, towards, 12.0, 200.0, 400000, 100 + static_cast<std::uint64_t>(pass));
    const std::shared_ptr<const GuidingDistribution> g = trainer.distribution();
    const Vec3 at(0.3f, 0.6f, 0.2f);
    // The learned mass in the cone, by sampling the learned distribution.
    Rng rng(9, 9);
    int inside = 0;
    constexpr int kDraws = 200000;
    for (int i = 0; i < kDraws; ++i) inside += dot(g->sample(at, Vec3(0.0f, 0.0f, 1.0f), rng.uniform(), rng.uniform()).direction, towards) >= c;
    const double learned = static_cast<double>(inside) / kDraws;
    std::printf("[guiding] pass %d: %d leaves, %zu nodes, depth %d; the cone's share %.3f (true %.3f)\n", pass + 1,
                g->stats().leaves, g->stats().nodes, g->stats().max_depth, learned, share);
    // The cells straddling the cone's edge blur it, and a leaf learns from
    // its own records alone (a few thousand once the S-tree has split): within
    // 25% of the truth once the quadtree has refined around it (it starts with
    // four cells), where the cone is 0.8% of the sphere.
    if (pass > 0) {
      EXPECT_NEAR(learned, share, 0.25 * share) << "pass " << pass + 1;
    }
    expect_sampler_follows_density(*g, at, 20 + static_cast<std::uint64_t>(pass));
  }
  // 1.2 million records over a pass threshold of 4000 sqrt(2^k): the S-tree split.
  EXPECT_GT(trainer.distribution()->leaves(), 8);
  EXPECT_EQ(trainer.passes(), 3);
}

// The units records are counted in follow the light the paths bring back:
// a first scale a billion times too coarse (a scene whose brightest light
// is not what lights it) loses the first pass's records, and the next
// passes, counted from the pass before's largest record, learn as any: after
// two more, as much of the cone as a trainer counting well from the start
// learns in two (GuidingTrainer.LearnsWhereTheLightComesFrom).
TEST(GuidingTrainer, CountsInUnitsOfTheLightItRecords) {
  GuidingTrainer trainer(Vec3(0.0f), Vec3(1.0f), 1e-9);
  const Vec3 towards = normalize(Vec3(-0.4f, 0.2f, 0.7f));
  teach(trainer, towards, 12.0, 200.0, 200000, 41);
  EXPECT_EQ(trainer.distribution()->stats().nodes, static_cast<std::size_t>(trainer.distribution()->leaves()))
      << "the first pass should have learned nothing: every leaf the uniform sphere";
  teach(trainer, towards, 12.0, 200.0, 200000, 42);
  teach(trainer, towards, 12.0, 200.0, 200000, 43);
  const std::shared_ptr<const GuidingDistribution> g = trainer.distribution();
  const double c = std::cos(12.0 * kPi / 180.0);
  const double share = 200.0 * (1.0 - c) / (200.0 * (1.0 - c) + (1.0 + c));
  Rng rng(5, 5);
  int inside = 0;
  constexpr int kDraws = 100000;
  for (int i = 0; i < kDraws; ++i)
    inside += dot(g->sample(Vec3(0.5f), Vec3(0.0f, 0.0f, 1.0f), rng.uniform(), rng.uniform()).direction, towards) >= c;
  EXPECT_NEAR(static_cast<double>(inside) / kDraws, share, 0.25 * share);
}

// A draw spends the 24 bits of a float down the quadtree, so a cell holding
// less than about 2^-24 of a leaf's light could not be drawn as often as its
// density says: a cell below kGuidingDrawableShare gets no density at all
// (and so is never owed a draw), one above keeps its share.
TEST(GuidingTrainer, CellsTooFaintToDrawGetNoDensity) {
  GuidingTrainer trainer(Vec3(0.0f), Vec3(1.0f), 1024.0);
  const Vec3 bright = direction_from_square(0.2f, 0.2f);  // quadrant 0
  const Vec3 faint = direction_from_square(0.8f, 0.2f);   // quadrant 1
  const Vec3 dim = direction_from_square(0.2f, 0.8f);     // quadrant 2
  const Vec3 at(0.5f), up(0.0f, 0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) trainer.record(at, up, bright, 1.0e4);  // 10^7 in all
  trainer.record(at, up, faint, 1.0);  // 10^-7 of the leaf: below 2^-16
  trainer.record(at, up, dim, 1.0e4);  // 10^-3: above
  trainer.finish_pass();
  const GuidingDistribution& g = *trainer.distribution();
  EXPECT_EQ(g.pdf(at, up, faint), 0.0f);
  EXPECT_GT(g.pdf(at, up, dim), 0.0f);
  // The density the faint cell gave up went to the others: it still integrates to one.
  double integral = 0.0;
  for (const GuidingDistribution::Cell& c : g.cells(g.leaf_at(at, up)))
    integral += static_cast<double>(c.pdf) * c.size * c.size * 4.0 * kPi;
  EXPECT_NEAR(integral, 1.0, 1e-6);
  // The dim cell's share, 10^-3 / (1 + 10^-3) of the light, in its quadrant's density.
  EXPECT_NEAR(g.pdf(at, up, dim) * kPi, 1.0e-3 / (1.0 + 1.0e-3), 1e-6);
  expect_sampler_follows_density(g, at, 31);
}

// The probe's picture of a leaf's quadtree: its cells tile the map, each
// carries the density the distribution gives its directions, and together
// they integrate to one; a leaf's box holds the points that find it.
// Each D-tree's root carries its leaf's mean record, the zero records
// counted (+rr:guided reads it as the light a surface there takes in); a
// leaf that took no record, and the untrained sphere, carry -1.
TEST(GuidingTrainer, EachLeafKnowsItsMeanRecord) {
  GuidingTrainer trainer(Vec3(0.0f), Vec3(1.0f), 1024.0);
  {
    const std::shared_ptr<const GuidingDistribution> g = trainer.distribution();
    EXPECT_EQ(g->node(g->root(g->leaf_at(Vec3(0.5f), Vec3(0.0f, 0.0f, 1.0f)))).light, -1.0f);
  }
  // Under +z: one record in four brings 6 (in 1/1024 units: exact), the rest
  // nothing, so the mean is 1.5; along +x: every record 0.25.
  Rng rng(8, 8);
  for (int i = 0; i < 4000; ++i) {
    const Vec3 p(rng.uniform(), rng.uniform(), rng.uniform());
    const Vec3 d = normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, 1.0f));
    trainer.record(p, Vec3(0.0f, 0.0f, 1.0f), d, i % 4 == 0 ? 6.0 : 0.0);
    trainer.record(p, Vec3(1.0f, 0.0f, 0.0f), d, 0.25);
  }
  trainer.finish_pass();
  const std::shared_ptr<const GuidingDistribution> g = trainer.distribution();
  const auto light = [&](const Vec3& normal) { return g->node(g->root(g->leaf_at(Vec3(0.5f), normal))).light; };
  EXPECT_FLOAT_EQ(light(Vec3(0.0f, 0.0f, 1.0f)), 1.5f);
  EXPECT_FLOAT_EQ(light(Vec3(1.0f, 0.0f, 0.0f)), 0.25f);
  EXPECT_EQ(light(Vec3(0.0f, 1.0f, 0.0f)), -1.0f) << "a leaf without records";
  // Not in any other node.
  for (std::size_t i = 0; i < g->nodes().size(); ++i) {
    bool is_root = false;
    for (int leaf = 0; leaf < g->leaves(); ++leaf) is_root = is_root || g->root(leaf) == static_cast<std::int32_t>(i);
    if (!is_root) {
      EXPECT_EQ(g->nodes()[i].light, -1.0f) << "node " << i;
    }
  }
}

TEST(GuidingDistribution, CellsAndBoxesDescribeTheTrees) {
  GuidingTrainer trainer(Vec3(0.0f), Vec3(1.0f), 1024.0);
  const Vec3 towards = normalize(Vec3(-0.4f, 0.2f, 0.9f));
  for (int pass = 0; pass < 2; ++pass) teach(trainer, towards, 10.0, 300.0, 300000, 40 + static_cast<std::uint64_t>(pass));
  const std::shared_ptr<const GuidingDistribution> g = trainer.distribution();
  const Vec3 up(0.0f, 0.0f, 1.0f);
  ASSERT_GT(g->leaves(), kGuidingNormalBins);
  Rng rng(5, 5);
  for (int i = 0; i < 20; ++i) {
    const Vec3 at(rng.uniform(), rng.uniform(), rng.uniform());
    const std::vector<GuidingDistribution::Cell> cells = g->cells(g->leaf_at(at, up));
    ASSERT_GT(cells.size(), 4u);
    double area = 0.0, mass = 0.0;
    for (const GuidingDistribution::Cell& c : cells) {
      area += static_cast<double>(c.size) * c.size;
      mass += static_cast<double>(c.pdf) * c.size * c.size * 4.0 * kPi;
      const Vec3 d = direction_from_square(c.s + 0.5f * c.size, c.t + 0.5f * c.size);
      EXPECT_NEAR(g->pdf(at, up, d), c.pdf, 1e-5 * c.pdf);
    }
    EXPECT_NEAR(area, 1.0, 1e-9);
    EXPECT_NEAR(mass, 1.0, 1e-5);
    Vec3 lo, hi;
    g->leaf_box(at, up, lo, hi);
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(lo[a], at[a]);
      EXPECT_GT(hi[a], at[a]);
      EXPECT_LT(hi[a] - lo[a], 1.0001f);
    }
    // The box's middle and a point just inside its far corner find the same leaf.
    EXPECT_EQ(g->leaf_at((lo + hi) * 0.5f, up), g->leaf_at(at, up));
    EXPECT_EQ(g->leaf_at(lo + (hi - lo) * 0.999f, up), g->leaf_at(at, up));
  }
}

TEST(GuidingTrainer, TheSameTreesForAnyOrderOfRecords) {
  // Records added in two orders (as threads would) give the same distribution, bit for bit, pass after pass.
  const Vec3 towards(0.0f, 0.0f, 1.0f);
  GuidingTrainer a(Vec3(0.0f), Vec3(1.0f), 1e6), b(Vec3(0.0f), Vec3(1.0f), 1e6);
  std::vector<std::pair<Vec3, Vec3>> records;
  std::vector<double> energies;
  Rng rng(4, 4);
  for (int i = 0; i < 50000; ++i) {
    const Vec3 d = direction_from_square(rng.uniform(), rng.uniform());
    records.push_back({Vec3(rng.uniform(), rng.uniform(), rng.uniform()), d});
    energies.push_back(dot(d, towards) > 0.9f ? 37.3 * rng.uniform() : 0.11 * rng.uniform());
  }
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < records.size(); ++i) a.record(records[i].first, towards, records[i].second, energies[i]);
    for (std::size_t i = records.size(); i-- > 0;) b.record(records[i].first, towards, records[i].second, energies[i]);
    a.finish_pass();
    b.finish_pass();
  }
  const GuidingDistribution &ga = *a.distribution(), &gb = *b.distribution();
  ASSERT_EQ(ga.leaves(), gb.leaves());
  ASSERT_EQ(ga.nodes().size(), gb.nodes().size());
  EXPECT_GT(ga.nodes().size(), 8u);
  EXPECT_EQ(0, std::memcmp(ga.nodes().data(), gb.nodes().data(), ga.nodes().size() * sizeof(GuidingDistribution::QuadNode)));
}

// A plan mixing cosine with a trained `guided`, through both samplers (the
// one-path code and the packet kernel), against the mixture's density.
TEST(GuidingPlan, TrainedMixtureThroughBothSamplers) {
  Scene scene = load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/door_ajar.json");
  GuidingTrainer trainer(Vec3(0.0f), Vec3(1.0f), 1024.0);
  for (int pass = 0; pass < 2; ++pass)
    teach(trainer, normalize(Vec3(0.6f, 0.2f, 0.7f)), 20.0, 50.0, 200000, 300 + static_cast<std::uint64_t>(pass));
  const std::shared_ptr<const GuidingDistribution> g = trainer.distribution();
  for (const char* strategy : {"mix:cosine=0.5,guided=0.5", "guided", "nee-mis+mix:cosine=0.3,guided=0.7"}) {
    SCOPED_TRACE(strategy);
    SamplingPlan plan = SamplingPlan::make(Strategy::parse(strategy), scene);
    plan.guiding = g.get();
    const Vec3 at(0.4f, 0.5f, 0.5f), normal(0.0f, 0.0f, 1.0f);
    const chi_square::Frame frame(normal);
    const chi_square::Density density = [&](const Vec3& d) { return static_cast<double>(plan.pdf(at, normal, d)); };
    std::vector<chi_square::Draw> draws = {chi_square::plan_sampler(plan, at, normal, chi_square::Sampler::OnePath),
                                           chi_square::plan_sampler(plan, at, normal, chi_square::Sampler::Packet)};
    const std::vector<chi_square::Outcome> outcomes =
        chi_square::run_each(chi_square::Grid(16, 32), frame, draws, density, dtree_edges(*g, at, frame), 41, 400000);
    for (const chi_square::Outcome& o : outcomes) {
      EXPECT_NEAR(o.integral, 1.0, 2e-3);
      EXPECT_EQ(o.bad_pdf, 0u);
      EXPECT_TRUE(o.passed(1e-3)) << "p = " << o.chi.p_value << ", zero-cell hits " << o.chi.zero_cell_hits;
    }
    // The same draws, bit for bit, from the same numbers.
    std::vector<PlanDraw> input(256);
    Rng rng(8, 8);
    for (PlanDraw& d : input) d = {at, normal, rng.next_u32(), rng.uniform(), rng.uniform(), rng.next_u32()};
    std::vector<DirectionSample> packet(input.size());
    sample_plan(best_packet_isa(), plan, input.data(), input.size(), packet.data());
    for (std::size_t i = 0; i < input.size(); ++i) {
      const DirectionSample one =
          plan.sample_at(at, normal, input[i].u1, input[i].u2, input[i].u0, input[i].u_choice);
      EXPECT_EQ(one.direction, packet[i].direction) << i;
      EXPECT_EQ(one.pdf, packet[i].pdf) << i;
    }
  }
  // Alone, trained, it is biased and says why; untrained (0 passes) it is the uniform sphere.
  EXPECT_FALSE(Strategy::parse("guided").is_unbiased());
  EXPECT_NE(Strategy::parse("guided").bias_reason().find("learned light"), std::string::npos);
  EXPECT_TRUE(Strategy::parse("guided:0").is_unbiased());
  EXPECT_TRUE(Strategy::parse("mix:cosine=0.5,guided=0.5").is_unbiased());
}

std::shared_ptr<const Scene> small_door(int width, int height) {
  auto s = std::make_shared<Scene>(load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/door_ajar.json"));
  s->camera.width = width;
  s->camera.height = height;
  s->prepare();
  return s;
}

// The spatial tree's overlay: each pixel's leaf holds the surface point the
// pixel sees, and a floor and a wall never share a leaf (one tree per way a
// surface faces).
TEST(GuidingDistribution, LeafMapFollowsTheSurfaces) {
  const auto scene = small_door(48, 36);
  GuidingTrainer trainer(*scene);
  const Vec3 lo = trainer.distribution()->lo(), hi = trainer.distribution()->hi();
  Rng rng(3, 3);
  const Vec3 faces[] = {Vec3(0.0f, 1.0f, 0.0f), Vec3(0.0f, -1.0f, 0.0f), Vec3(1.0f, 0.0f, 0.0f),
                        Vec3(-1.0f, 0.0f, 0.0f), Vec3(0.0f, 0.0f, 1.0f), Vec3(0.0f, 0.0f, -1.0f)};
  for (int i = 0; i < 400000; ++i) {
    const Vec3 p = lo + (hi - lo) * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    const Vec3 d = direction_from_square(rng.uniform(), rng.uniform());
    trainer.record(p, faces[i % 6], d, 1.0);
  }
  trainer.finish_pass();
  const GuidingDistribution& g = *trainer.distribution();
  const std::vector<std::int32_t> leaves = guiding_leaf_map(*scene, g);
  ASSERT_EQ(leaves.size(), 48u * 36u);
  std::vector<int> bin_of_leaf(static_cast<std::size_t>(g.leaves()), -1);
  int distinct = 0;
  for (int y = 0; y < 36; ++y)
    for (int x = 0; x < 48; ++x) {
      const std::int32_t leaf = leaves[static_cast<std::size_t>(y * 48 + x)];
      const ProbePoint at = first_diffuse_hit(*scene, x, y);
      ASSERT_EQ(leaf >= 0, at.found) << x << ", " << y;
      if (!at.found) continue;
      Vec3 box_lo, box_hi;
      g.leaf_box(at.point, at.normal, box_lo, box_hi);
      for (int a = 0; a < 3; ++a) {
        EXPECT_LE(box_lo[a], at.point[a]);
        EXPECT_GE(box_hi[a], at.point[a]);
      }
      int& bin = bin_of_leaf[static_cast<std::size_t>(leaf)];
      if (bin < 0) ++distinct;
      else EXPECT_EQ(bin, guiding_normal_bin(at.normal)) << "leaf " << leaf << " holds two ways of facing";
      bin = guiding_normal_bin(at.normal);
    }
  EXPECT_GT(distinct, 6);
}

// Whether two films hold the same mean in every pixel, bit for bit.
bool same_image(const Film& a, const Film& b) {
  if (a.pixel_count() != b.pixel_count()) return false;
  for (std::size_t p = 0; p < a.pixel_count(); ++p) {
    double x[3], y[3];
    a.mean(p, x);
    b.mean(p, y);
    if (x[0] != y[0] || x[1] != y[1] || x[2] != y[2]) return false;
  }
  return true;
}

// The training passes record through the packet tracer from every worker at
// once; the trees, and so the image, are the same for 1, 2 and 4 threads, with
// the roulette by the learned light too (which reads them).
TEST(GuidingSession, TrainsTheSameForAnyThreadCount) {
  const auto scene = small_door(40, 30);
  for (const char* strategy : {"nee-mis+mix:cosine=0.5,guided:4=0.5", "mix:cosine=0.5,guided:4=0.5+rr:guided:3"}) {
    SCOPED_TRACE(strategy);
    const testing::Rendered one = testing::render_to_completion(scene, strategy, 4, 5, 1, std::chrono::seconds(300));
    const testing::Rendered two = testing::render_to_completion(scene, strategy, 4, 5, 2, std::chrono::seconds(300));
    // More workers than this machine may have cores: the blocks interleave differently again.
    const testing::Rendered four = testing::render_to_completion(scene, strategy, 4, 5, 4, std::chrono::seconds(300));
    EXPECT_EQ(one.stats.guiding_pass, 4);
    EXPECT_EQ(one.stats.guiding_passes, 4);
    EXPECT_GT(one.stats.guiding.nodes, 1u);
    EXPECT_GT(one.stats.guiding_records, 40u * 30u * 15u);  // at least one vertex for each of 15 samples a pixel
    EXPECT_EQ(one.stats.guiding.nodes, two.stats.guiding.nodes);
    EXPECT_EQ(one.stats.guiding_records, two.stats.guiding_records);
    EXPECT_EQ(one.stats.guiding.nodes, four.stats.guiding.nodes);
    EXPECT_EQ(one.stats.guiding_records, four.stats.guiding_records);
    EXPECT_EQ(one.stats.spp, 4u);
    EXPECT_TRUE(same_image(one.film, two.film)) << "1 and 2 threads gave different images";
    EXPECT_TRUE(same_image(one.film, four.film)) << "1 and 4 threads gave different images";
  }
}

// +rr:guided decides by what the guide learned and, where it learned
// nothing, by the throughput rule: untrained (guided:0) it renders the very
// image +rr renders; trained, another (its convergence to the same image:
// Convergence.GuidedMixturesAgreeOnTheDoorScene).
TEST(GuidingSession, RouletteByTheLearnedLightFallsBackToTheThroughputRule) {
  const auto scene = small_door(24, 18);
  const auto render = [&](const std::string& strategy) {
    return testing::render_to_completion(scene, strategy, 8, 9, 2, std::chrono::seconds(300)).film;
  };
  EXPECT_TRUE(same_image(render("nee-mis+mix:cosine=0.5,guided:0=0.5+rr:guided:2"),
                         render("nee-mis+mix:cosine=0.5,guided:0=0.5+rr:2")));
  EXPECT_FALSE(same_image(render("nee-mis+mix:cosine=0.5,guided:3=0.5+rr:guided:2"),
                          render("nee-mis+mix:cosine=0.5,guided:3=0.5+rr:2")));
}

// Runs `session` on `settings` to its end (it renders with two workers).
void run_to_end(RenderSession& session, const RenderSettings& settings) {
  session.set_settings(settings);
  ASSERT_TRUE(session.wait_until_done(std::chrono::seconds(300)));
}

// What the training passes record is the light a surface takes in, L cos:
// under a sky of one radiance a floor's learned distribution is the cosine
// lobe, three quarters of it within 60 degrees of the normal (a record of L
// alone would learn the uniform hemisphere: half).
TEST(GuidingSession, LearnsTheLightTimesTheCosine) {
  RenderSettings settings;
  settings.scene = testing::sky_floor(32, 24);
  settings.strategy = Strategy::parse("mix:cosine=0.5,guided:4=0.5");
  settings.seed = 3;
  settings.target_spp = 1;
  RenderSession session(2);
  run_to_end(session, settings);
  const std::shared_ptr<const GuidingDistribution> g = session.guiding();
  ASSERT_NE(g, nullptr);
  const Vec3 at(0.3f, 0.0f, -0.2f), up(0.0f, 1.0f, 0.0f);
  Rng rng(4, 4);
  constexpr int kDraws = 100000;
  int steep = 0;
  for (int i = 0; i < kDraws; ++i) steep += g->sample(at, up, rng.uniform(), rng.uniform()).direction.y > 0.5f;
  EXPECT_NEAR(static_cast<double>(steep) / kDraws, 0.75, 0.04);
}

// Auto weight's later passes: a session given a distribution draws from it
// as it is and trains nothing; given the one a trained session learned, it
// renders that session's very image.
TEST(GuidingSession, AGivenDistributionIsDrawnFromAsItIs) {
  RenderSettings settings;
  settings.scene = small_door(40, 30);
  settings.strategy = Strategy::parse("nee-mis+mix:cosine=0.5,guided:3=0.5");
  settings.seed = 5;
  settings.target_spp = 4;
  RenderSession trained(2);
  run_to_end(trained, settings);
  EXPECT_EQ(trained.stats().guiding_passes, 3);
  settings.guiding = trained.guiding();
  ASSERT_NE(settings.guiding, nullptr);
  RenderSession given(2);
  run_to_end(given, settings);
  EXPECT_EQ(given.stats().guiding_passes, 0);
  EXPECT_EQ(given.stats().guiding_records, 0u);
  EXPECT_EQ(given.guiding(), settings.guiding);
  EXPECT_EQ(given.stats().guiding.nodes, trained.stats().guiding.nodes);
  EXPECT_TRUE(same_image(trained.copy_film(), given.copy_film())) << "the given distribution rendered another image";
}

}  // namespace
}  // namespace pdflab
