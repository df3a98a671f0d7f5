// Rendering a reference in the background (ReferenceBuild, as the viewer's Make
// reference uses it): each goal stops it, the reference carries the reserved
// seed and its variance, a cancel (destruction mid-render) is prompt, and a
// biased strategy is refused. Labelled `session`: CI runs it under ThreadSanitizer.
#include "renderer/error.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/reference_build.h"

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <thread>

namespace {

std::shared_ptr<const pdflab::Scene> small_scene() {
  auto scene = std::make_shared<pdflab::Scene>(
      pdflab::load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/tests/gui/cornell_small.json"));
  scene->camera.width = 24;
  scene->camera.height = 20;
  scene->max_depth = 8;
  scene->prepare();
  return scene;
}

pdflab::ReferenceJob job(const pdflab::ReferenceGoal& goal) {
  pdflab::ReferenceJob j;
  j.scene = small_scene();
  j.scene_file = "cornell_small.json";
  j.strategy = pdflab::default_reference_strategy(*j.scene);
  j.goal = goal;
  j.threads = 2;
  j.version = "test";
  return j;
}

// Polls as the viewer does, once a frame, until the goal; false after `limit`.
bool run_to_goal(pdflab::ReferenceBuild& build, double limit_seconds = 120.0) {
  const auto start = std::chrono::steady_clock::now();
  double last_fraction = 0.0;
  while (!build.poll().reached) {
    const pdflab::ReferenceProgress p = build.poll();
    EXPECT_GE(p.fraction + 1e-12, last_fraction * 0.5) << "progress does not run backwards by much";
    last_fraction = p.fraction;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > limit_seconds) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

TEST(ReferenceBuild, StopsAtSppWithTheReservedSeedAndItsVariance) {
  pdflab::ReferenceBuild build(job({32, 0.0, 0.0}));
  ASSERT_TRUE(run_to_goal(build));
  EXPECT_TRUE(build.done());
  const pdflab::Reference ref = build.finish();
  EXPECT_EQ(ref.info.spp, 32u);
  EXPECT_EQ(ref.width, 24);
  EXPECT_EQ(ref.height, 20);
  ASSERT_TRUE(ref.has_variance());
  EXPECT_TRUE(pdflab::is_reference_seed(ref.info.seed));
  EXPECT_EQ(ref.info.max_depth, 8);
  EXPECT_EQ(ref.info.strategy, "mix:cosine=0.5,light=0.5");
  EXPECT_EQ(ref.info.scene_hash, small_scene()->content_hash);
  EXPECT_GT(ref.info.estimated_relmse, 0.0);
}

TEST(ReferenceBuild, StopsAtAnEstimatedRelMse) {
  constexpr double kTarget = 0.02;
  pdflab::ReferenceBuild build(job({0, 0.0, kTarget}));
  ASSERT_TRUE(run_to_goal(build));
  const pdflab::Reference ref = build.finish();
  // The pass in flight when it stopped adds samples: at the target or below.
  EXPECT_LE(ref.info.estimated_relmse, kTarget * 1.02);
  EXPECT_GT(ref.info.spp, 1u);
}

TEST(ReferenceBuild, CancelIsPromptAndBiasedIsRefused) {
  auto build = std::make_unique<pdflab::ReferenceBuild>(job({0, 1000.0, 0.0}));
  for (int i = 0; i < 20; ++i) {
    (void)build->poll();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_FALSE(build->done());
  const auto t0 = std::chrono::steady_clock::now();
  build.reset();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);

  pdflab::ReferenceJob biased = job({16, 0.0, 0.0});
  biased.strategy = pdflab::Strategy::single(pdflab::Technique::Light);
  EXPECT_THROW(pdflab::ReferenceBuild{biased}, pdflab::InputError);
  EXPECT_THROW(pdflab::ReferenceBuild(job({16, 5.0, 0.0})), pdflab::InputError) << "two goals";
}

}  // namespace
