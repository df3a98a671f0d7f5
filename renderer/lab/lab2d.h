#pragma once
// The environment map's 2D distribution, taken apart for the viewer's 2D lab:
// a lat-long map, the marginal pdf and CDF over its rows, the conditional pdf
// and CDF within a row, samples drawn by Environment::sample (the renderer's
// own sampler), their 2D histogram against the exact pdf with Pearson's
// chi-square, and the map at lower resolutions with what each puts on a sun.
// No OpenGL: ui/lab2d_panel draws it; tests/test_lab2d.cpp checks it.
// docs/environment.md ("The 2D lab") explains what it shows.
#include "renderer/math.h"
#include "renderer/metrics/statistics.h"
#include "renderer/scene/environment.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pdflab::lab {

// W x H texels of linear RGB radiance, row 0 the zenith (the layout of
// renderer/scene/environment.h).
struct LatLongMap {
  std::vector<float> rgb;
  int width = 0, height = 0;
};

// A sun a map is known to hold: a disc of `radius` radians about `direction`
// (in the map's own frame, unrotated) of luminance `luminance`.
struct Sun {
  Vec3 direction;
  double radius = 0.0;
  double luminance = 0.0;
  double solid_angle() const;  // 2 pi (1 - cos radius)
};

// A map for the lab, with its sun where it has one.
struct LabMap {
  std::string name;
  LatLongMap map;
  std::optional<Sun> sun;
};

// The built-in maps, each 256 x 128.
enum class TestMap : std::uint8_t {
  SunSky,       // assets/environments/sun_sky.hdr (scripts/make_sky.py): a sun of 0.8 degrees over parts of a few texels
  SubTexelSun,  // a sky and a sun of 0.25 degrees inside one texel, holding about 90% of the light
  BlackHalf,    // black for phi < pi, a sky beyond
  Constant,     // radiance 1 everywhere: the density is 1 / (4 pi)
  Count
};
std::string_view test_map_name(TestMap m);
// `sun_sky_path`: the shipped map's file (read for SunSky only); InputError
// as read_environment_image for a file it cannot read.
LabMap make_test_map(TestMap m, const std::string& sun_sky_path);
// The scene's map as the scene sees it (scaled), in its own frame: no sun known.
LabMap scene_test_map(const Environment& environment);

// Half the width and half the height (both must be even): each new texel
// averages its 2 x 2 texels weighted by their solid angle, so the integral of
// the radiance over the sphere is kept (to float rounding).
LatLongMap downsample(const LatLongMap& map);

// The histogram's grid over the map's (u, v) = (phi / 2 pi, theta / pi): its
// cells need not line up with the texels; expected counts are exact integrals.
inline constexpr int kHistogramColumns = 32, kHistogramRows = 16;

class Lab2d {
 public:
  // The map at its own resolution and at each halving down to 8 texels across
  // (while both sides stay even): the levels, finest first.
  explicit Lab2d(LabMap map);

  const std::string& name() const { return name_; }
  const std::optional<Sun>& sun() const { return sun_; }
  int levels() const { return static_cast<int>(levels_.size()); }
  const LatLongMap& map(int level) const { return levels_[static_cast<std::size_t>(level)].map; }
  const Environment& environment(int level) const { return *levels_[static_cast<std::size_t>(level)].environment; }

  // The level being sampled; choosing another starts the samples over.
  int level() const { return level_; }
  void set_level(int level);
  const LatLongMap& map() const { return map(level_); }
  const Environment& environment() const { return environment(level_); }

  // Over the rows of the current level: row y's probability (H values
  // summing to 1) and the marginal CDF (H + 1 values from 0 to 1); within
  // row y: each column's probability given the row (W values) and the
  // conditional CDF (W + 1 values).
  std::vector<double> marginal_pmf() const;
  const std::vector<double>& marginal_cdf() const { return environment().marginal_cdf(); }
  std::vector<double> conditional_pmf(int row) const;
  std::vector<double> conditional_cdf(int row) const { return environment().conditional_cdf(row); }

  // Draws `count` directions with Environment::sample and bins each by the
  // map coordinates of the direction it returned. Reproducible from the
  // seed and the calls made.
  void draw(int count);
  void reset();
  std::uint64_t count() const { return count_; }
  std::uint64_t seed = 1;
  // The latest samples' (u, v), at most kDots of them (oldest first after a wrap).
  static constexpr std::size_t kDots = 3000;
  const std::vector<std::pair<float, float>>& dots() const { return dots_; }
  // kHistogramColumns x kHistogramRows counts, row by row from the zenith.
  const std::vector<std::uint64_t>& histogram() const { return histogram_; }
  // Each cell's probability under the sampler's density: the integral of the
  // pdf over the cell (exact for the piecewise-constant density).
  const std::vector<double>& cell_probability() const { return cell_probability_; }
  // Pearson's chi-square of the histogram against N times cell_probability.
  stats::ChiSquareResult chi_square() const;

  // What each level puts on the map's brightest texel and on its sun.
  struct LevelFigures {
    int width = 0, height = 0;
    double peak_pdf = 0.0;          // the largest density of any texel (1/sr)
    int peak_x = 0, peak_y = 0;     // that texel
    double peak_probability = 0.0;  // its probability
    double peak_solid_angle = 0.0;  // its solid angle (sr)
    double sun_pdf = 0.0;           // the density at the sun's centre (0 without a sun)
    double sun_texel_solid_angle = 0.0;
  };
  // Worked out once, when the lab is made (a large map's levels are many texels).
  const std::vector<LevelFigures>& resolution_study() const { return study_; }
  // The density a sampler exact to the radiance puts on the sun's disc:
  // its luminance over the map's luminance integral (0 without a sun).
  double sun_exact_density() const;

 private:
  struct Level {
    LatLongMap map;
    std::shared_ptr<const Environment> environment;
  };
  void compute_cells();
  std::vector<LevelFigures> study() const;

  std::string name_;
  std::optional<Sun> sun_;
  std::vector<Level> levels_;
  int level_ = 0;
  std::uint64_t count_ = 0, calls_ = 0;
  std::vector<std::pair<float, float>> dots_;
  std::size_t next_dot_ = 0;
  std::vector<std::uint64_t> histogram_;
  std::vector<double> cell_probability_;
  std::vector<LevelFigures> study_;
};

}  // namespace pdflab::lab
