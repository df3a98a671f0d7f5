#pragma once
// An environment light: an image of the radiance arriving from every
// direction, in latitude-longitude form, and its importance sampling by a
// piecewise-constant 2D distribution (a marginal over rows, a conditional
// within each row) with the sin(theta) Jacobian of the map. docs/environment.md
// derives the density.
//
// The map: column x and row y of a W x H image cover azimuth
// phi in [2 pi x / W, 2 pi (x + 1) / W) and polar angle theta in
// [pi y / H, pi (y + 1) / H), theta measured from +y (row 0 is the zenith) and
// phi from +x towards +z; `rotation` turns the map about +y by that many
// degrees (a texel seen at phi without rotation is seen at phi + rotation).
// The radiance is constant over a texel (nearest texel, no filtering), and
// the sampler chooses a texel with probability proportional to its luminance
// times its solid angle (the map's Jacobian sin theta integrated over it), then
// draws uniformly in solid angle within it: its density is constant over each
// texel and proportional to the luminance there, exactly.
#include "renderer/math.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pdflab {

class Environment {
 public:
  // `rgb`: W x H texels, row 0 the zenith, linear radiance, finite and >= 0;
  // `scale` multiplies them; `rotation_degrees` turns the map about +y.
  Environment(std::vector<float> rgb, int width, int height, float scale, float rotation_degrees);

  int width() const { return width_; }
  int height() const { return height_; }
  float scale() const { return scale_; }
  float rotation_degrees() const { return rotation_degrees_; }
  // The scaled radiance of texel (x, y).
  Vec3 texel(int x, int y) const;
  // Whether some texel has light: else the map cannot be sampled.
  bool sampleable() const { return total_ > 0.0; }

  // The radiance arriving from unit `direction` (towards the light).
  Vec3 radiance(const Vec3& direction) const;
  // A direction drawn in proportion to luminance over the sphere (u1 chooses
  // the row, u2 the column, each remainder the place within: cos theta and
  // phi uniform across the texel), with its density in solid angle; `none`
  // where it has none to give (a map without light).
  struct Sample {
    Vec3 direction;
    float pdf = 0.0f;
    bool none = false;
  };
  Sample sample(float u1, float u2) const;
  // The density in solid angle of `direction`: P(texel) / (texel's solid angle).
  float pdf(const Vec3& direction) const;

  // The 2D distribution itself, for the lab and the tests: the marginal CDF
  // over rows (H + 1 values from 0 to 1), row y's conditional CDF over its
  // columns (W + 1 values from 0 to 1; a row without light is uniform), and
  // the probability of texel (x, y).
  const std::vector<double>& marginal_cdf() const { return marginal_; }
  std::vector<double> conditional_cdf(int y) const;
  double texel_probability(int x, int y) const;
  // Where `direction` falls on the map: u = phi / 2 pi and v = theta / pi, in
  // [0, 1], and the texel that holds it.
  void map_coordinates(const Vec3& direction, double& u, double& v) const;
  void texel_of(const Vec3& direction, int& x, int& y) const;
  // The sampler's density in solid angle anywhere in texel (x, y).
  float texel_density(int x, int y) const;
  // The unit direction at map coordinates (u, v).
  Vec3 direction_at(double u, double v) const;
  // Points along the texel edges where the density jumps (by more than a
  // factor 1.5, or to or from zero), `per_edge` on each: where the chi-square
  // harness must split its integration (a sun one texel wide).
  std::vector<Vec3> density_edges(int per_edge) const;
  // The integral of the luminance over the sphere (sr times radiance): the sum of the weights.
  double luminance_integral() const { return integral_; }
  // A hash of the texels, the scale and the rotation (Scene::content_hash).
  std::uint64_t hash() const { return hash_; }

 private:
  int width_, height_;
  float scale_, rotation_degrees_;
  double cos_rot_, sin_rot_;
  std::vector<float> rgb_;           // scaled
  std::vector<double> marginal_;     // H + 1
  std::vector<double> conditional_;  // H rows of W + 1
  std::vector<double> row_z_;        // cos theta at the rows' bounds, H + 1 from 1 to -1
  std::vector<double> row_mass_;     // each row's sum of weights
  std::vector<double> weight_;       // each texel's luminance times solid angle
  double total_ = 0.0;
  double integral_ = 0.0;
  std::uint64_t hash_ = 0;
};

// A lat-long map from a file: Radiance .hdr (stb_image), .exr (OpenEXR) or .pfm.
// InputError naming the file for anything it cannot read, a size out of
// range, or a texel that is negative or not finite.
std::vector<float> read_environment_image(const std::string& path, int& width, int& height);

}  // namespace pdflab
