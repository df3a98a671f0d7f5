// The error and noise figures: the film's variance and relative standard error
// against distributions whose variance is known, RMSE and relMSE of images
// computed by hand, efficiency, the reference-free estimate of relMSE against a
// real reference, and the claim the project exists to show: on a small light,
// sampling the light beats the cosine lobe.
#include "renderer/film/film.h"
#include "renderer/integrator/integrator.h"
#include "renderer/metrics/metrics.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <ctime>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace pdflab {
namespace {

const std::string kScenes = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/";

// Uniform in [0, 1) from 53 bits: the transforms below are written out so the
// samples are the same with any standard library.
double uniform01(std::mt19937_64& gen) { return static_cast<double>(gen() >> 11) * 0x1.0p-53; }
double exponential(std::mt19937_64& gen, double mean) { return -mean * std::log1p(-uniform01(gen)); }

// Sampling distribution of the sample variance s^2 of n draws (Bessel-corrected):
// E[s^2] = sigma^2 and Var[s^2] = sigma^4 * (2 / (n - 1) + excess_kurtosis / n).
double sd_of_sample_variance(double variance, double excess_kurtosis, double n) {
  return variance * std::sqrt(2.0 / (n - 1.0) + excess_kurtosis / n);
}

// ---- Film variance and relative standard error ------------------------------------

TEST(FilmVariance, MatchesTheKnownVarianceOfTheSampledDistribution) {
  // Each pixel gets n samples: red uniform on [0, 1) (variance 1/12, excess
  // kurtosis -6/5), green exponential with mean 2 (variance 4, excess kurtosis
  // 6), blue a constant (variance 0). n * variance_of_mean estimates the
  // variance; averaged over P pixels its standard deviation is
  // sd(s^2) / sqrt(P). Eight samples make the Bessel factor n / (n - 1) a 14%
  // effect, well outside the 5-sigma band (3% and 8%), so dividing by n instead
  // of n - 1, or forgetting the 1 / n of the mean, fails here.
  constexpr int kSide = 64;
  constexpr std::uint32_t kN = 8;
  constexpr double kPixels = kSide * kSide;
  Film film(kSide, kSide);
  std::mt19937_64 gen(12345);
  for (std::size_t p = 0; p < film.pixel_count(); ++p)
    for (std::uint32_t i = 0; i < kN; ++i)
      film.add(p, Vec3(static_cast<float>(uniform01(gen)), static_cast<float>(exponential(gen, 2.0)), 0.375f));

  double sum[3] = {0, 0, 0};
  for (std::size_t p = 0; p < film.pixel_count(); ++p) {
    ASSERT_EQ(film.count(p), kN);
    double v[3];
    film.variance_of_mean(p, v);
    for (int c = 0; c < 3; ++c) sum[c] += kN * v[c];
  }
  const double red = sum[0] / kPixels, green = sum[1] / kPixels, blue = sum[2] / kPixels;
  const double red_tolerance = 5.0 * sd_of_sample_variance(1.0 / 12.0, -1.2, kN) / std::sqrt(kPixels);
  const double green_tolerance = 5.0 * sd_of_sample_variance(4.0, 6.0, kN) / std::sqrt(kPixels);
  EXPECT_NEAR(red, 1.0 / 12.0, red_tolerance);
  EXPECT_NEAR(green, 4.0, green_tolerance);
  // A constant has no variance; E[x^2] - E[x]^2 may round to a tiny value, never more.
  EXPECT_LE(blue, 1e-12);
  EXPECT_GE(blue, 0.0);
}

TEST(FilmVariance, FewerThanTwoSamplesReportNoVariance) {
  Film film(2, 1);
  film.add(1, Vec3(5.0f, 6.0f, 7.0f));
  for (std::size_t p = 0; p < 2; ++p) {
    double v[3];
    film.variance_of_mean(p, v);
    for (double x : v) EXPECT_EQ(x, 0.0);
  }
  EXPECT_EQ(mean_relative_standard_error(film), 0.0);
  EXPECT_EQ(estimated_relmse(film), 0.0);
}

TEST(RelativeStandardError, MatchesTheKnownValueForGreySamples) {
  // Grey samples x = a * u, u uniform: the luminance equals every channel, so
  // the relative standard error of pixel p is sigma / sqrt(n) / (mu + epsilon)
  // with mu = a/2, sigma^2 = a^2/12. Per pixel the estimate wanders by the
  // relative error of s (about sd(s^2) / (2 sigma^2)) and of the mean in the
  // denominator; averaged over P pixels that shrinks by sqrt(P). Its bias is
  // second order, below 1/n. The band (5 sigma plus 1/n, about 1.1%) leaves out
  // a missing epsilon (2%) and a standard deviation in place of the standard
  // error (a factor 16).
  constexpr int kSide = 32;
  constexpr std::uint32_t kN = 256;
  constexpr double kPixels = kSide * kSide;
  constexpr double kScale = 1.0;
  Film film(kSide, kSide);
  std::mt19937_64 gen(777);
  for (std::size_t p = 0; p < film.pixel_count(); ++p)
    for (std::uint32_t i = 0; i < kN; ++i) {
      const float x = static_cast<float>(kScale * uniform01(gen));
      film.add(p, Vec3(x, x, x));
    }

  const double mu = kScale / 2.0, sigma = kScale / std::sqrt(12.0);
  const double expected = sigma / std::sqrt(double{kN}) / (mu + kRelMseEpsilon);
  const double cv_s = 0.5 * sd_of_sample_variance(1.0, -1.2, kN);
  const double cv_mean = sigma / std::sqrt(double{kN}) / (mu + kRelMseEpsilon);
  const double per_pixel_sd = expected * std::sqrt(cv_s * cv_s + cv_mean * cv_mean);
  const double tolerance = 5.0 * per_pixel_sd / std::sqrt(kPixels) + expected / kN;

  const double rse = mean_relative_standard_error(film);
  EXPECT_NEAR(rse, expected, tolerance);

  // The heat map holds the same per-pixel values the mean summarises.
  const std::vector<float> map = relative_standard_error_map(film);
  ASSERT_EQ(map.size(), film.pixel_count());
  double map_sum = 0.0;
  for (float v : map) map_sum += v;
  EXPECT_NEAR(map_sum / kPixels, rse, 1e-6 * rse);
}

// ---- RMSE, relMSE, efficiency -------------------------------------------------------

TEST(ImageError, RmseAndRelMseByHand) {
  // Two pixels; dyadic values so the floats are exact.
  const std::vector<float> image = {1.0f, 2.0f, 3.0f, 0.5f, 0.0f, 0.0f};
  const std::vector<float> reference = {1.0f, 1.0f, 1.0f, 0.0f, 0.0f, 0.25f};
  // Squared differences 0, 1, 4, 0.25, 0, 0.0625: their sum is 5.3125.
  EXPECT_NEAR(rmse(image, reference), std::sqrt(5.3125 / 6.0), 1e-12);
  // Each square over (reference^2 + 0.01): the black reference pixel's 0.5 costs
  // 0.25 / 0.01 = 25, which is why the epsilon must stay small but not zero.
  const double by_hand = (0.0 + 1.0 / 1.01 + 4.0 / 1.01 + 0.25 / 0.01 + 0.0 + 0.0625 / (0.0625 + 0.01)) / 6.0;
  EXPECT_NEAR(relmse(image, reference), by_hand, 1e-12);
  // Without the epsilon, on a reference with no black channel: plain relative squared error.
  const std::vector<float> lit = {2.0f, 4.0f, 1.0f};
  const std::vector<float> lit_reference = {1.0f, 2.0f, 4.0f};
  EXPECT_NEAR(relmse(lit, lit_reference, 0.0), (1.0 + 1.0 + 9.0 / 16.0) / 3.0, 1e-12);

  EXPECT_EQ(rmse(reference, reference), 0.0);
  EXPECT_EQ(relmse(reference, reference), 0.0);
}

TEST(ImageError, ImagesOfDifferentSizesAreRejected) {
  const std::vector<float> three = {1, 2, 3}, six = {1, 2, 3, 4, 5, 6}, none;
  EXPECT_THROW(rmse(three, six), std::invalid_argument);
  EXPECT_THROW(relmse(six, three), std::invalid_argument);
  EXPECT_THROW(rmse(none, none), std::invalid_argument);
}

TEST(Efficiency, InverseOfRelMseTimesSeconds) {
  EXPECT_DOUBLE_EQ(efficiency(0.02, 5.0), 10.0);
  // An unbiased estimator's relMSE falls as 1/N: twice the time, half the
  // error, the same efficiency.
  EXPECT_DOUBLE_EQ(efficiency(0.04, 2.0), efficiency(0.02, 4.0));
  // Nothing measured is not "infinitely efficient".
  EXPECT_EQ(efficiency(0.0, 1.0), 0.0);
  EXPECT_EQ(efficiency(0.1, 0.0), 0.0);
  EXPECT_EQ(efficiency(std::numeric_limits<double>::quiet_NaN(), 1.0), 0.0);
  EXPECT_EQ(efficiency(-1.0, 1.0), 0.0);
}

// ---- Against the renderer -----------------------------------------------------------

double thread_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

Scene small_scene(const std::string& file, int width, int height) {
  Scene scene = load_scene_file(kScenes + file);
  scene.camera.width = width;
  scene.camera.height = height;
  scene.prepare();
  return scene;
}

struct Rendering {
  Film film;
  double cpu_seconds = 0.0;  // this thread's CPU time: unlike wall time, not stretched by other processes
  std::uint64_t dropped = 0;
};

// Renders in the calling thread, pixel by pixel, as the session would (same
// per-sample streams), so the CPU time measured is this render's alone.
Rendering render(const Scene& scene, const std::string& strategy, std::uint32_t spp, std::uint64_t seed) {
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse(strategy), scene);
  Rendering r;
  r.film.reset(scene.camera.width, scene.camera.height);
  DropCounts drops;
  const double start = thread_cpu_seconds();
  for (int y = 0; y < scene.camera.height; ++y)
    for (int x = 0; x < scene.camera.width; ++x) {
      const std::size_t pixel = static_cast<std::size_t>(y) * static_cast<std::size_t>(scene.camera.width) +
                                static_cast<std::size_t>(x);
      for (std::uint32_t s = 0; s < spp; ++s) r.film.add(pixel, render_pixel_sample(scene, plan, seed, x, y, s, drops));
    }
  r.cpu_seconds = thread_cpu_seconds() - start;
  r.dropped = drops.total();
  return r;
}

TEST(EstimatedRelMse, AgreesWithTheRelMseAgainstAReference) {
  // estimated_relmse claims to predict relMSE without a reference. Check it on
  // real renders: independent renders of an unbiased strategy against one
  // reference of 16 times the samples. The reference's own noise adds its
  // expected relMSE to every measurement (the cross term averages out), so the
  // prediction is est(render) + est(reference). The small-light scene with the
  // even mixture has no caustics, so the per-sample variance is finite and
  // moderate and the sample variance is a fair estimate at 256 spp; on
  // heavy-tailed renders (glass caustics, cosine on a small light) the sample
  // variance is usually below its mean and the estimate reads low.
  // The measured ratio is itself random (squared errors of 1728 channel
  // values, correlated within a pixel, with a right tail from paths that find
  // the light after a bounce); the band is about three of its standard
  // deviations as seen across seed sets. It still fails a variance that is not
  // divided by n (a factor 256), or a wrong denominator.
  const Scene scene = small_scene("small_light.json", 24, 24);
  const std::string strategy = "mix:cosine=0.5,light=0.5";
  const Rendering reference = render(scene, strategy, 4096, 1);
  const std::vector<float> reference_rgb = reference.film.mean_rgb();
  const double reference_noise = estimated_relmse(reference.film);

  double measured = 0.0, predicted = 0.0;
  constexpr int kRuns = 4;
  for (int k = 0; k < kRuns; ++k) {
    const Rendering run = render(scene, strategy, 256, 100 + static_cast<std::uint64_t>(k));
    measured += relmse(run.film.mean_rgb(), reference_rgb);
    predicted += estimated_relmse(run.film) + reference_noise;
  }
  ASSERT_GT(predicted, 0.0);
  const double ratio = measured / predicted;
  EXPECT_GT(ratio, 0.8) << "measured relMSE " << measured / kRuns << ", predicted " << predicted / kRuns;
  EXPECT_LT(ratio, 1.25) << "measured relMSE " << measured / kRuns << ", predicted " << predicted / kRuns;
}

TEST(SmallLight, LightMixtureIsMoreEfficientThanCosine) {
  // Efficiency is 1 / (relMSE * time), but wall time on a shared machine says
  // more about the neighbours than about the strategy. So the claim is split
  // into a load-independent part and a cost bound:
  // - At equal spp the cosine render's relMSE must exceed the mixture's by a
  //   factor kMargin = 10. The mixture's extra work per diffuse bounce is one
  //   light pdf evaluation (one quad here) and, half the time, a light sample
  //   in place of a cosine sample; its paths are no longer than cosine's
  //   (they end on the light sooner). Its cost per sample is therefore within
  //   a small factor of cosine's, far below 10, so this ratio implies the
  //   mixture also wins at equal time.
  // - The cost bound is checked too, with each render's CPU time in its own
  //   thread, which other processes do not stretch (unlike wall time).
  // Both renders are unbiased and share one reference; its noise adds the same
  // amount to both relMSEs, which can only shrink the ratio.
  constexpr double kMargin = 10.0;
  const Scene scene = small_scene("small_light.json", 32, 32);
  const Rendering reference = render(scene, "mix:cosine=0.5,light=0.5", 4096, 1);
  const std::vector<float> reference_rgb = reference.film.mean_rgb();

  const Rendering cosine = render(scene, "cosine", 64, 2);
  const Rendering mixture = render(scene, "mix:cosine=0.5,light=0.5", 64, 2);
  const double cosine_relmse = relmse(cosine.film.mean_rgb(), reference_rgb);
  const double mixture_relmse = relmse(mixture.film.mean_rgb(), reference_rgb);
  ASSERT_GT(mixture_relmse, 0.0);
  EXPECT_GT(cosine_relmse / mixture_relmse, kMargin)
      << "relMSE at 64 spp: cosine " << cosine_relmse << ", mixture " << mixture_relmse;

  const double cost_ratio = mixture.cpu_seconds / cosine.cpu_seconds;
  EXPECT_LT(cost_ratio, kMargin) << "the mixture costs " << cost_ratio << " times cosine per sample";
  EXPECT_GT(efficiency(mixture_relmse, mixture.cpu_seconds), efficiency(cosine_relmse, cosine.cpu_seconds));
  std::printf("relMSE at 64 spp: cosine %.4g, mixture %.4g (%.0fx); CPU cost mixture/cosine %.2f\n", cosine_relmse,
              mixture_relmse, cosine_relmse / mixture_relmse, cost_ratio);
}

}  // namespace
}  // namespace pdflab
