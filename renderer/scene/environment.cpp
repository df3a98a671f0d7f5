#include "renderer/scene/environment.h"

#include "renderer/error.h"
#include "renderer/film/exr_io.h"
#include "renderer/film/film.h"
#include "renderer/film/image_io.h"
#include "renderer/hash.h"
#include "renderer/input_file.h"

#include <stb_image.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

namespace pdflab {

namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
}  // namespace

Environment::Environment(std::vector<float> rgb, int width, int height, float scale, float rotation_degrees)
    : width_(width), height_(height), scale_(scale), rotation_degrees_(rotation_degrees), rgb_(std::move(rgb)) {
  const double r = static_cast<double>(rotation_degrees) * std::numbers::pi / 180.0;
  cos_rot_ = std::cos(r);
  sin_rot_ = std::sin(r);
  for (float& c : rgb_) c *= scale;
  const auto W = static_cast<std::size_t>(width), H = static_cast<std::size_t>(height);
  row_z_.resize(H + 1);
  for (std::size_t y = 0; y <= H; ++y) row_z_[y] = std::cos(std::numbers::pi * static_cast<double>(y) / static_cast<double>(H));
  row_z_[0] = 1.0;
  row_z_[H] = -1.0;
  weight_.assign(W * H, 0.0);
  row_mass_.assign(H, 0.0);
  conditional_.assign(H * (W + 1), 0.0);
  marginal_.assign(H + 1, 0.0);
  for (std::size_t y = 0; y < H; ++y) {
    // A texel's weight: its luminance times its solid angle, the integral of
    // the map's Jacobian sin theta over it: (2 pi / W) (cos theta0 - cos theta1).
    const double texel_sr = kTwoPi / static_cast<double>(W) * (row_z_[y] - row_z_[y + 1]);
    double sum = 0.0;
    for (std::size_t x = 0; x < W; ++x) {
      weight_[y * W + x] = luminance(&rgb_[(y * W + x) * 3]) * texel_sr;
      sum += weight_[y * W + x];
    }
    row_mass_[y] = sum;
    double* cdf = &conditional_[y * (W + 1)];
    double run = 0.0;
    for (std::size_t x = 0; x < W; ++x) {
      run += sum > 0.0 ? weight_[y * W + x] / sum : 1.0 / static_cast<double>(W);
      cdf[x + 1] = run;
    }
    cdf[W] = 1.0;
    total_ += sum;
  }
  for (std::size_t y = 0; y < H; ++y)
    marginal_[y + 1] = marginal_[y] + (total_ > 0.0 ? row_mass_[y] / total_ : 1.0 / static_cast<double>(H));
  marginal_[H] = 1.0;
  integral_ = total_;
  hash_ = fnv1a64(rgb_.data(), rgb_.size() * sizeof(float));
  hash_ = fnv1a64(&scale_, sizeof scale_, hash_);
  hash_ = fnv1a64(&rotation_degrees_, sizeof rotation_degrees_, hash_);
}

Vec3 Environment::texel(int x, int y) const {
  const float* c = &rgb_[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3];
  return Vec3(c[0], c[1], c[2]);
}

void Environment::map_coordinates(const Vec3& d, double& u, double& v) const {
  const double x = static_cast<double>(d.x), y = static_cast<double>(d.y), z = static_cast<double>(d.z);
  // Into the map's frame: turned back by the rotation about +y.
  const double mx = x * cos_rot_ + z * sin_rot_, mz = -x * sin_rot_ + z * cos_rot_;
  double phi = std::atan2(mz, mx);
  if (phi < 0.0) phi += kTwoPi;
  u = phi / kTwoPi;
  if (!(u < 1.0)) u = 0.0;  // atan2's -0 turned into 2 pi, or a NaN direction
  const double length = std::sqrt(x * x + y * y + z * z);
  const double c = length > 0.0 ? std::clamp(y / length, -1.0, 1.0) : 1.0;
  v = std::acos(c) / std::numbers::pi;
}

Vec3 Environment::direction_at(double u, double v) const {
  const double theta = std::numbers::pi * v, phi = kTwoPi * u;
  const double s = std::sin(theta);
  const double mx = s * std::cos(phi), mz = s * std::sin(phi);
  return Vec3(static_cast<float>(mx * cos_rot_ - mz * sin_rot_), static_cast<float>(std::cos(theta)),
              static_cast<float>(mx * sin_rot_ + mz * cos_rot_));
}

Vec3 Environment::radiance(const Vec3& direction) const {
  int x, y;
  texel_of(direction, x, y);
  return texel(x, y);
}

double Environment::texel_probability(int x, int y) const {
  if (!(total_ > 0.0)) return 0.0;
  return weight_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)] / total_;
}

std::vector<double> Environment::conditional_cdf(int y) const {
  const auto W = static_cast<std::size_t>(width_);
  const auto begin = conditional_.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(y) * (W + 1));
  return std::vector<double>(begin, begin + static_cast<std::ptrdiff_t>(W + 1));
}

float Environment::texel_density(int x, int y) const {
  const double texel_sr = kTwoPi / static_cast<double>(width_) *
                          (row_z_[static_cast<std::size_t>(y)] - row_z_[static_cast<std::size_t>(y) + 1]);
  return static_cast<float>(texel_probability(x, y) / texel_sr);
}

void Environment::texel_of(const Vec3& direction, int& x, int& y) const {
  double u, v;
  map_coordinates(direction, u, v);
  x = std::clamp(static_cast<int>(u * width_), 0, width_ - 1);
  y = std::clamp(static_cast<int>(v * height_), 0, height_ - 1);
}

namespace {
// The cell of `cdf` (n + 1 values, nondecreasing from 0 to 1) that holds u:
// cdf[i] <= u < cdf[i + 1] (a cell of zero width is never chosen), and u's
// place within it in [0, 1).
int find_cell(const double* cdf, int n, double u, double& within) {
  const double* at = std::upper_bound(cdf, cdf + n + 1, u);
  int i = static_cast<int>(at - cdf) - 1;
  i = std::clamp(i, 0, n - 1);
  while (i > 0 && !(cdf[i + 1] > cdf[i])) --i;  // u == 1 rounded: the last cell with mass
  const double width = cdf[i + 1] - cdf[i];
  within = width > 0.0 ? std::clamp((u - cdf[i]) / width, 0.0, std::nextafter(1.0, 0.0)) : 0.0;
  return i;
}
}  // namespace

Environment::Sample Environment::sample(float u1, float u2) const {
  Sample s;
  s.direction = Vec3(0.0f, 1.0f, 0.0f);
  if (!sampleable()) {
    s.none = true;
    return s;
  }
  double dv, du;
  const int y = find_cell(marginal_.data(), height_, static_cast<double>(u1), dv);
  const int x = find_cell(&conditional_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_ + 1)], width_,
                          static_cast<double>(u2), du);
  // Uniform in solid angle within the texel: cos theta uniform between the
  // row's bounds, phi uniform across the column.
  const double z0 = row_z_[static_cast<std::size_t>(y)], z1 = row_z_[static_cast<std::size_t>(y) + 1];
  const double z = z0 - dv * (z0 - z1);
  const double phi = kTwoPi * (x + du) / width_;
  const double r = std::sqrt(std::max(0.0, (1.0 - z) * (1.0 + z)));
  const double mx = r * std::cos(phi), mz = r * std::sin(phi);
  s.direction = Vec3(static_cast<float>(mx * cos_rot_ - mz * sin_rot_), static_cast<float>(z),
                     static_cast<float>(mx * sin_rot_ + mz * cos_rot_));
  s.pdf = texel_density(x, y);
  return s;
}

float Environment::pdf(const Vec3& direction) const {
  if (!sampleable()) return 0.0f;
  int x, y;
  texel_of(direction, x, y);
  return texel_density(x, y);
}

std::vector<Vec3> Environment::density_edges(int per_edge) const {
  std::vector<Vec3> out;
  const auto jumps = [](double a, double b) {
    const double lo = std::min(a, b), hi = std::max(a, b);
    return hi > 0.0 && !(hi <= 1.5 * lo);
  };
  const auto at = [&](double z, double phi) {
    const double r = std::sqrt(std::max(0.0, (1.0 - z) * (1.0 + z)));
    const double mx = r * std::cos(phi), mz = r * std::sin(phi);
    return Vec3(static_cast<float>(mx * cos_rot_ - mz * sin_rot_), static_cast<float>(z),
                static_cast<float>(mx * sin_rot_ + mz * cos_rot_));
  };
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const double here = texel_density(x, y);
      const double z0 = row_z_[static_cast<std::size_t>(y)], z1 = row_z_[static_cast<std::size_t>(y) + 1];
      if (jumps(here, texel_density((x + 1) % width_, y))) {  // the meridian on its right
        const double phi = kTwoPi * (x + 1) / width_;
        for (int k = 0; k < per_edge; ++k) out.push_back(at(z0 + (z1 - z0) * (k + 0.5) / per_edge, phi));
      }
      if (y + 1 < height_ && jumps(here, texel_density(x, y + 1)))  // the circle below it
        for (int k = 0; k < per_edge; ++k) out.push_back(at(z1, kTwoPi * (x + (k + 0.5) / per_edge) / width_));
    }
  return out;
}

std::vector<float> read_environment_image(const std::string& path, int& width, int& height) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::vector<float> rgb;
  if (ext == ".hdr") {
    check_input_file(path, "environment map");
    if (!stbi_is_hdr(path.c_str())) throw InputError("'" + path + "' is not a Radiance HDR image");
    int w = 0, h = 0, channels = 0;
    float* data = stbi_loadf(path.c_str(), &w, &h, &channels, 3);
    if (!data) {
      const char* why = stbi_failure_reason();
      throw InputError("cannot read '" + path + "': " + std::string(why ? why : "unknown reason"));
    }
    if (const std::string problem = image_size_problem(w, h); !problem.empty()) {
      stbi_image_free(data);
      throw InputError("'" + path + "': " + problem);
    }
    rgb.assign(data, data + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
    stbi_image_free(data);
    width = w;
    height = h;
  } else if (ext == ".exr") {
    rgb = read_exr(path, width, height);
  } else if (ext == ".pfm") {
    rgb = read_pfm(path, width, height);
  } else {
    throw InputError("'" + path + "': unknown environment map format '" + ext +
                     "' (a lat-long image: .hdr, .exr or .pfm)");
  }
  for (std::size_t i = 0; i < rgb.size(); ++i)
    if (!(rgb[i] >= 0.0f) || !std::isfinite(rgb[i])) {
      const std::size_t texel = i / 3;
      throw InputError("'" + path + "': texel (" + std::to_string(texel % static_cast<std::size_t>(width)) + ", " +
                       std::to_string(texel / static_cast<std::size_t>(width)) +
                       ") is negative or not finite (radiance must be finite and >= 0)");
    }
  return rgb;
}

}  // namespace pdflab
