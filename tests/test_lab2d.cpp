// The 2D lab's model: the marginal and conditional distributions it shows are
// distributions, the renderer's sampler fills its histogram as the exact pdf
// says (and the same chi-square rejects a pdf without the sin theta
// Jacobian), downsampling keeps the map's integral, and a sun smaller than a
// texel gets a pdf peak that grows with the texel count while a resolved one
// does not.
#include "renderer/error.h"
#include "renderer/lab/lab2d.h"
#include "renderer/metrics/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

namespace pdflab::lab {
namespace {

const std::string kSunSky = PDFLAB_SOURCE_DIR "/assets/environments/sun_sky.hdr";
constexpr int kMaps = static_cast<int>(TestMap::Count);

Lab2d make_lab(TestMap m) { return Lab2d(make_test_map(m, kSunSky)); }

TEST(Lab2d, LevelsHalveDownToEightTexelsAcross) {
  const Lab2d lab = make_lab(TestMap::SunSky);
  ASSERT_EQ(lab.levels(), 6);
  for (int l = 0; l < lab.levels(); ++l) {
    EXPECT_EQ(lab.map(l).width, 256 >> l);
    EXPECT_EQ(lab.map(l).height, 128 >> l);
    EXPECT_EQ(lab.environment(l).width(), 256 >> l);
  }
}

TEST(Lab2d, MarginalSumsToOneAndEveryConditionalCdfEndsAtOne) {
  for (int m = 0; m < kMaps; ++m) {
    Lab2d lab = make_lab(static_cast<TestMap>(m));
    for (int l = 0; l < lab.levels(); ++l) {
      lab.set_level(l);
      SCOPED_TRACE(lab.name() + " at level " + std::to_string(l));
      const std::vector<double> pmf = lab.marginal_pmf();
      const std::vector<double>& cdf = lab.marginal_cdf();
      ASSERT_EQ(pmf.size(), static_cast<std::size_t>(lab.map().height));
      EXPECT_NEAR(std::accumulate(pmf.begin(), pmf.end(), 0.0), 1.0, 1e-12);
      EXPECT_EQ(cdf.front(), 0.0);
      EXPECT_EQ(cdf.back(), 1.0);
      for (int y = 0; y < lab.map().height; ++y) {
        // The row's probability is its texels' (the marginal is their sum).
        double row = 0.0;
        for (int x = 0; x < lab.map().width; ++x) row += lab.environment().texel_probability(x, y);
        ASSERT_NEAR(pmf[static_cast<std::size_t>(y)], row, 1e-12) << "row " << y;
        ASSERT_GE(pmf[static_cast<std::size_t>(y)], 0.0);
        const std::vector<double> c = lab.conditional_cdf(y);
        ASSERT_EQ(c.size(), static_cast<std::size_t>(lab.map().width) + 1);
        ASSERT_EQ(c.front(), 0.0) << "row " << y;
        ASSERT_EQ(c.back(), 1.0) << "row " << y;
        for (std::size_t x = 0; x + 1 < c.size(); ++x) ASSERT_LE(c[x], c[x + 1]) << "row " << y;
        const std::vector<double> q = lab.conditional_pmf(y);
        ASSERT_NEAR(std::accumulate(q.begin(), q.end(), 0.0), 1.0, 1e-12) << "row " << y;
      }
    }
  }
}

// Every map at its full resolution (cells of 8 x 8 texels) and at 8 x 4
// (texels of 4 x 4 cells: the place within a texel is tested too).
TEST(Lab2d, HistogramFromTheSamplerAgreesWithThePdfByChiSquare) {
  constexpr int kSamples = 200000;
  const double alpha = stats::sidak_alpha(1e-3, 2 * kMaps);
  for (int m = 0; m < kMaps; ++m) {
    Lab2d lab = make_lab(static_cast<TestMap>(m));
    for (const int l : {0, lab.levels() - 1}) {
      lab.set_level(l);
      SCOPED_TRACE(lab.name() + " at " + std::to_string(lab.map().width) + " x " + std::to_string(lab.map().height));
      const std::vector<double>& p = lab.cell_probability();
      EXPECT_NEAR(std::accumulate(p.begin(), p.end(), 0.0), 1.0, 1e-12);
      lab.draw(kSamples / 2);
      lab.draw(kSamples / 2);
      ASSERT_EQ(lab.count(), static_cast<std::uint64_t>(kSamples));
      const stats::ChiSquareResult r = lab.chi_square();
      EXPECT_EQ(r.zero_cell_hits, 0u) << "samples where the pdf is zero";
      EXPECT_GT(r.p_value, alpha) << "chi-square " << r.statistic << " on " << r.dof << " dof";
      EXPECT_GT(r.dof, 100);  // the grid is really used (the black half's empty cells aside)
    }
  }
}

// The harness has power: the constant map's samples, uniform over the
// sphere, judged against a density uniform in (u, v) (the Jacobian forgotten).
TEST(Lab2d, ChiSquareRejectsAPdfWithoutTheJacobian) {
  Lab2d lab = make_lab(TestMap::Constant);
  lab.draw(200000);
  ASSERT_GT(lab.chi_square().p_value, 1e-4);
  const std::vector<double> flat(lab.histogram().size(), static_cast<double>(lab.count()) / static_cast<double>(lab.histogram().size()));
  EXPECT_LT(stats::chi_square_test(lab.histogram(), flat).p_value, 1e-12);
}

TEST(Lab2d, DownsamplingKeepsTheMapsIntegral) {
  for (int m = 0; m < kMaps; ++m) {
    const Lab2d lab = make_lab(static_cast<TestMap>(m));
    const double full = lab.environment(0).luminance_integral();
    ASSERT_GT(full, 0.0);
    for (int l = 1; l < lab.levels(); ++l)
      EXPECT_NEAR(lab.environment(l).luminance_integral() / full, 1.0, 1e-6) << lab.name() << " at level " << l;
  }
  // A constant map's integral is 4 pi exactly at every level.
  const Lab2d constant = make_lab(TestMap::Constant);
  for (int l = 0; l < constant.levels(); ++l)
    EXPECT_NEAR(constant.environment(l).luminance_integral(), 4.0 * std::numbers::pi, 1e-9);
  // Without the solid-angle weights (a plain 2 x 2 average) the sky's
  // integral changes: the weights are what keeps it.
  const LabMap sky = make_test_map(TestMap::SunSky, kSunSky);
  LatLongMap plain{{}, sky.map.width / 2, sky.map.height / 2};
  for (int y = 0; y < plain.height; ++y)
    for (int x = 0; x < plain.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const auto at = [&](int fx, int fy) { return sky.map.rgb[(static_cast<std::size_t>(fy) * 256 + static_cast<std::size_t>(fx)) * 3 + static_cast<std::size_t>(c)]; };
        plain.rgb.push_back(0.25f * (at(2 * x, 2 * y) + at(2 * x + 1, 2 * y) + at(2 * x, 2 * y + 1) + at(2 * x + 1, 2 * y + 1)));
      }
  const Environment plain_env(plain.rgb, plain.width, plain.height, 1.0f, 0.0f);
  const Lab2d lab(sky);
  EXPECT_GT(std::abs(plain_env.luminance_integral() / lab.environment(0).luminance_integral() - 1.0), 1e-5);
}

// A sun inside one texel at every level: the texel keeps the sun's share of
// the light, so the pdf's peak is that share over the texel's solid angle:
// it grows with the texel count, and stays below the sun's exact density by
// the ratio of the sun's solid angle to the texel's.
TEST(Lab2d, SubTexelSunsPdfPeakScalesWithTheTexelCount) {
  const Lab2d lab = make_lab(TestMap::SubTexelSun);
  ASSERT_TRUE(lab.sun());
  const Sun& sun = *lab.sun();
  const double integral = lab.environment(0).luminance_integral();
  const double share = sun.luminance * sun.solid_angle() / integral;
  EXPECT_NEAR(share, 0.9, 0.05);
  const std::vector<Lab2d::LevelFigures> study = lab.resolution_study();
  ASSERT_EQ(study.size(), 6u);
  const double per_texel = study[0].peak_pdf / (study[0].width * study[0].height);
  for (std::size_t l = 0; l < study.size(); ++l) {
    const Lab2d::LevelFigures& f = study[l];
    SCOPED_TRACE(std::to_string(f.width) + " x " + std::to_string(f.height));
    int x, y;
    lab.environment(static_cast<int>(l)).texel_of(sun.direction, x, y);
    EXPECT_EQ(f.peak_x, x);
    EXPECT_EQ(f.peak_y, y);
    EXPECT_EQ(f.sun_pdf, f.peak_pdf);
    EXPECT_GE(f.peak_probability, share * (1.0 - 1e-6));
    EXPECT_LE(f.peak_probability, share + 0.02);
    EXPECT_NEAR(f.peak_pdf / (f.width * f.height) / per_texel, 1.0, 0.1);
    EXPECT_LT(f.peak_pdf, lab.sun_exact_density());
    EXPECT_NEAR(f.peak_pdf / lab.sun_exact_density(), sun.solid_angle() / f.peak_solid_angle * f.peak_probability / share, 1e-9);
  }
  // Each halving: about a quarter of the peak.
  for (std::size_t l = 1; l < study.size(); ++l) EXPECT_NEAR(study[l - 1].peak_pdf / study[l].peak_pdf, 4.0, 0.4);
}

// The shipped sun spans parts of a few texels at 256 x 128: there the peak no
// longer grows as fast as the texel count, and no level's peak passes the
// sun's own density (a texel's mean radiance is at most the sun's).
TEST(Lab2d, AResolvedSunsPeakStopsGrowing) {
  const Lab2d lab = make_lab(TestMap::SunSky);
  const std::vector<Lab2d::LevelFigures> study = lab.resolution_study();
  for (const Lab2d::LevelFigures& f : study) EXPECT_LE(f.peak_pdf, lab.sun_exact_density() * (1.0 + 1e-9)) << f.width;
  EXPECT_LT(study[0].peak_pdf / study[1].peak_pdf, 3.0);
  EXPECT_GT(study[4].peak_pdf / study[5].peak_pdf, 3.0);  // 16 x 8 against 8 x 4: the sun well inside a texel
  EXPECT_GT(study[0].sun_texel_solid_angle, 0.0);
  EXPECT_LT(study[0].sun_texel_solid_angle, 2.0 * lab.sun()->solid_angle());
}

TEST(Lab2d, ReproducibleFromTheSeedAndALevelStartsOver) {
  Lab2d a = make_lab(TestMap::SunSky), b = make_lab(TestMap::SunSky);
  a.draw(5000);
  b.draw(5000);
  EXPECT_EQ(a.histogram(), b.histogram());
  EXPECT_EQ(a.dots().size(), 3000u);
  a.draw(10);
  EXPECT_NE(a.dots(), b.dots());
  b.seed = 2;
  b.reset();
  b.draw(5000);
  EXPECT_NE(a.histogram(), b.histogram());
  a.set_level(3);
  EXPECT_EQ(a.count(), 0u);
  EXPECT_EQ(a.level(), 3);
  EXPECT_EQ(std::accumulate(a.histogram().begin(), a.histogram().end(), std::uint64_t{0}), 0u);
  EXPECT_TRUE(a.dots().empty());
  a.set_level(99);
  EXPECT_EQ(a.level(), a.levels() - 1);
}

TEST(Lab2d, TheScenesMapIsSeenScaledInItsOwnFrame) {
  std::vector<float> rgb(16 * 8 * 3, 0.5f);
  rgb[(3 * 16 + 5) * 3 + 1] = 40.0f;
  const Environment scene(rgb, 16, 8, 2.0f, 30.0f);
  const LabMap m = scene_test_map(scene);
  EXPECT_EQ(m.map.width, 16);
  EXPECT_EQ(m.map.height, 8);
  EXPECT_FALSE(m.sun);
  EXPECT_EQ(m.map.rgb[(3 * 16 + 5) * 3 + 1], 80.0f);
  const Lab2d lab(m);
  EXPECT_EQ(lab.levels(), 2);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) ASSERT_DOUBLE_EQ(lab.environment().texel_probability(x, y), scene.texel_probability(x, y));
}

TEST(Lab2d, AMapWithoutLightDrawsNothing) {
  Lab2d lab(LabMap{"black", LatLongMap{std::vector<float>(16 * 8 * 3, 0.0f), 16, 8}, std::nullopt});
  lab.draw(1000);
  EXPECT_EQ(lab.count(), 0u);
  EXPECT_EQ(lab.marginal_cdf().back(), 1.0);  // uniform rows, as the sampler's CDFs are
  EXPECT_EQ(lab.resolution_study()[0].peak_pdf, 0.0);
}

TEST(Lab2d, AMissingSunSkyFileIsNamed) {
  try {
    (void)make_test_map(TestMap::SunSky, "/nonexistent/sky.hdr");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/sky.hdr"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pdflab::lab
