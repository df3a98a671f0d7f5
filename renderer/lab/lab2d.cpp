#include "renderer/lab/lab2d.h"

#include "renderer/sampling/rng.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pdflab::lab {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kSize = 256;  // the built-in maps' width (the height is half)

Vec3 direction_of(double theta, double phi) {
  const double s = std::sin(theta);
  return Vec3(static_cast<float>(s * std::cos(phi)), static_cast<float>(std::cos(theta)),
              static_cast<float>(s * std::sin(phi)));
}

double radians(double degrees) { return degrees * kPi / 180.0; }

// cos theta at the bounds of row y of a map `height` rows high.
double row_z(int y, int height) { return std::cos(kPi * static_cast<double>(y) / static_cast<double>(height)); }

// A sky from a blue zenith to a pale horizon over a dim ground: the built-in maps' background.
Vec3 sky(double theta) {
  const double elevation = kPi / 2.0 - theta;
  if (elevation < 0.0) return Vec3(0.06f, 0.055f, 0.05f);
  const auto t = static_cast<float>(std::pow(1.0 - elevation / (kPi / 2.0), 3.0));
  return Vec3(0.18f, 0.32f, 0.75f) * (1.0f - t) + Vec3(0.85f, 0.9f, 1.0f) * t;
}

template <class At>
LatLongMap fill(int w, int h, At at) {
  LatLongMap m{{}, w, h};
  m.rgb.reserve(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Vec3 c = at(x, y);
      m.rgb.insert(m.rgb.end(), {c.x, c.y, c.z});
    }
  return m;
}

double theta_of_row(int y, int h) { return kPi * (static_cast<double>(y) + 0.5) / static_cast<double>(h); }

}  // namespace

double Sun::solid_angle() const { return 2.0 * kPi * (1.0 - std::cos(radius)); }

std::string_view test_map_name(TestMap m) {
  switch (m) {
    case TestMap::SunSky: return "sun and sky (sun_sky.hdr)";
    case TestMap::SubTexelSun: return "sky, a sun smaller than a texel";
    case TestMap::BlackHalf: return "black half";
    case TestMap::Constant: return "constant";
    default: return "?";
  }
}

LabMap make_test_map(TestMap which, const std::string& sun_sky_path) {
  LabMap out;
  out.name = std::string(test_map_name(which));
  switch (which) {
    case TestMap::SunSky: {
      out.map.rgb = read_environment_image(sun_sky_path, out.map.width, out.map.height);
      // The sun as scripts/make_sky.py draws it: 35 degrees up, 60 degrees
      // round from +x, 0.8 degrees in radius, radiance (22000, 20000, 17000).
      out.sun = Sun{direction_of(radians(90.0 - 35.0), radians(60.0)), radians(0.8),
                    luminance(22000.0, 20000.0, 17000.0)};
      break;
    }
    case TestMap::SubTexelSun: {
      // The sun's centre is the centre of texel (42, 39), 55.5 degrees from
      // the zenith; its radius, 0.25 degrees, is well inside the texel's
      // 1.4 x 1.2 degrees, so it stays inside one texel at every level.
      constexpr int sx = 42, sy = 39;
      const Sun sun{direction_of(theta_of_row(sy, kSize / 2), 2.0 * kPi * (sx + 0.5) / kSize), radians(0.25), 5.0e5};
      const double texel_sr = 2.0 * kPi / kSize * (row_z(sy, kSize / 2) - row_z(sy + 1, kSize / 2));
      const auto spread = static_cast<float>(sun.luminance * sun.solid_angle() / texel_sr);
      out.map = fill(kSize, kSize / 2, [&](int x, int y) {
        const Vec3 c = sky(theta_of_row(y, kSize / 2));
        return x == sx && y == sy ? c + Vec3(spread) : c;
      });
      out.sun = sun;
      break;
    }
    case TestMap::BlackHalf:
      out.map = fill(kSize, kSize / 2, [](int x, int y) {
        return x < kSize / 2 ? Vec3(0.0f) : sky(theta_of_row(y, kSize / 2)) * (1.0f + static_cast<float>(x) / kSize);
      });
      break;
    case TestMap::Constant: out.map = fill(kSize, kSize / 2, [](int, int) { return Vec3(1.0f); }); break;
    default: break;
  }
  return out;
}

LabMap scene_test_map(const Environment& environment) {
  LabMap out;
  out.name = "the scene's map";
  out.map = fill(environment.width(), environment.height(), [&](int x, int y) { return environment.texel(x, y); });
  return out;
}

LatLongMap downsample(const LatLongMap& m) {
  LatLongMap out{{}, m.width / 2, m.height / 2};
  out.rgb.assign(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height) * 3, 0.0f);
  for (int y = 0; y < out.height; ++y) {
    // The two fine rows' solid angles differ (sin theta changes): each
    // weighs by its own, and their sum is the coarse row's.
    const double a = row_z(2 * y, m.height) - row_z(2 * y + 1, m.height);
    const double b = row_z(2 * y + 1, m.height) - row_z(2 * y + 2, m.height);
    const double wa = a / (a + b) * 0.5, wb = b / (a + b) * 0.5;
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const auto at = [&](int fx, int fy) {
          return static_cast<double>(
              m.rgb[(static_cast<std::size_t>(fy) * static_cast<std::size_t>(m.width) + static_cast<std::size_t>(fx)) * 3 +
                    static_cast<std::size_t>(c)]);
        };
        const double v = wa * (at(2 * x, 2 * y) + at(2 * x + 1, 2 * y)) + wb * (at(2 * x, 2 * y + 1) + at(2 * x + 1, 2 * y + 1));
        out.rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) + static_cast<std::size_t>(x)) * 3 +
                static_cast<std::size_t>(c)] = static_cast<float>(v);
      }
  }
  return out;
}

Lab2d::Lab2d(LabMap m) : name_(std::move(m.name)), sun_(m.sun) {
  LatLongMap at = std::move(m.map);
  while (true) {
    auto env = std::make_shared<const Environment>(at.rgb, at.width, at.height, 1.0f, 0.0f);
    const bool halve = at.width >= 16 && at.width % 2 == 0 && at.height % 2 == 0;
    LatLongMap next = halve ? downsample(at) : LatLongMap{};
    levels_.push_back({std::move(at), std::move(env)});
    if (!halve) break;
    at = std::move(next);
  }
  study_ = study();
  set_level(0);
}

void Lab2d::set_level(int level) {
  level_ = std::clamp(level, 0, levels() - 1);
  compute_cells();
  reset();
}

void Lab2d::reset() {
  count_ = 0;
  calls_ = 0;
  dots_.clear();
  next_dot_ = 0;
  histogram_.assign(static_cast<std::size_t>(kHistogramColumns * kHistogramRows), 0);
}

std::vector<double> Lab2d::marginal_pmf() const {
  const std::vector<double>& cdf = marginal_cdf();
  std::vector<double> p(cdf.size() - 1);
  for (std::size_t y = 0; y < p.size(); ++y) p[y] = cdf[y + 1] - cdf[y];
  return p;
}

std::vector<double> Lab2d::conditional_pmf(int row) const {
  const std::vector<double> cdf = conditional_cdf(row);
  std::vector<double> p(cdf.size() - 1);
  for (std::size_t x = 0; x < p.size(); ++x) p[x] = cdf[x + 1] - cdf[x];
  return p;
}

void Lab2d::compute_cells() {
  // A texel's probability spreads over the cells it overlaps in proportion
  // to the overlap's solid angle: the fraction of its phi range times the
  // fraction of its cos theta range (the density is uniform in solid angle
  // within a texel).
  const Environment& env = environment();
  const int W = env.width(), H = env.height();
  cell_probability_.assign(static_cast<std::size_t>(kHistogramColumns * kHistogramRows), 0.0);
  // fractions[t] lists (cell, fraction of texel t) along one axis.
  const auto overlaps = [](int texels, int cells, bool cosine) {
    std::vector<std::vector<std::pair<int, double>>> out(static_cast<std::size_t>(texels));
    const auto measure = [&](double a, double b) { return cosine ? std::cos(kPi * a) - std::cos(kPi * b) : b - a; };
    for (int t = 0; t < texels; ++t) {
      const double a = static_cast<double>(t) / texels, b = static_cast<double>(t + 1) / texels;
      const double whole = measure(a, b);
      const int first = static_cast<int>(a * cells), last = std::min(cells - 1, static_cast<int>(std::ceil(b * cells)) - 1);
      for (int c = first; c <= last; ++c) {
        const double lo = std::max(a, static_cast<double>(c) / cells), hi = std::min(b, static_cast<double>(c + 1) / cells);
        if (hi > lo) out[static_cast<std::size_t>(t)].emplace_back(c, measure(lo, hi) / whole);
      }
    }
    return out;
  };
  const auto across = overlaps(W, kHistogramColumns, false), down = overlaps(H, kHistogramRows, true);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double p = env.texel_probability(x, y);
      if (p == 0.0) continue;
      for (const auto& [row, fy] : down[static_cast<std::size_t>(y)])
        for (const auto& [col, fx] : across[static_cast<std::size_t>(x)])
          cell_probability_[static_cast<std::size_t>(row * kHistogramColumns + col)] += p * fy * fx;
    }
}

void Lab2d::draw(int count) {
  const Environment& env = environment();
  if (!env.sampleable()) return;
  // Each call draws from its own stream, keyed by (seed, call index).
  Rng rng(mix64(seed) ^ calls_, 0x2d1ab);
  ++calls_;
  for (int i = 0; i < count; ++i) {
    const float u1 = rng.uniform(), u2 = rng.uniform();
    const Environment::Sample s = env.sample(u1, u2);
    double u, v;
    env.map_coordinates(s.direction, u, v);
    const int col = std::clamp(static_cast<int>(u * kHistogramColumns), 0, kHistogramColumns - 1);
    const int row = std::clamp(static_cast<int>(v * kHistogramRows), 0, kHistogramRows - 1);
    ++histogram_[static_cast<std::size_t>(row * kHistogramColumns + col)];
    ++count_;
    const std::pair<float, float> dot(static_cast<float>(u), static_cast<float>(v));
    if (dots_.size() < kDots) {
      dots_.push_back(dot);
    } else {
      dots_[next_dot_] = dot;
      next_dot_ = (next_dot_ + 1) % kDots;
    }
  }
}

stats::ChiSquareResult Lab2d::chi_square() const {
  std::vector<double> expected(cell_probability_.size());
  for (std::size_t i = 0; i < expected.size(); ++i) expected[i] = cell_probability_[i] * static_cast<double>(count_);
  return stats::chi_square_test(histogram_, expected);
}

double Lab2d::sun_exact_density() const {
  if (!sun_) return 0.0;
  const double integral = levels_.front().environment->luminance_integral();
  return integral > 0.0 ? sun_->luminance / integral : 0.0;
}

std::vector<Lab2d::LevelFigures> Lab2d::study() const {
  std::vector<LevelFigures> out;
  for (const Level& l : levels_) {
    const Environment& env = *l.environment;
    LevelFigures f;
    f.width = env.width();
    f.height = env.height();
    const auto texel_sr = [&](int y) {
      return 2.0 * kPi / env.width() * (row_z(y, env.height()) - row_z(y + 1, env.height()));
    };
    // In double (Environment::texel_density is the renderer's float).
    for (int y = 0; y < env.height(); ++y)
      for (int x = 0; x < env.width(); ++x)
        if (const double d = env.texel_probability(x, y) / texel_sr(y); d > f.peak_pdf) {
          f.peak_pdf = d;
          f.peak_x = x;
          f.peak_y = y;
        }
    f.peak_probability = env.texel_probability(f.peak_x, f.peak_y);
    f.peak_solid_angle = texel_sr(f.peak_y);
    if (sun_) {
      int x, y;
      env.texel_of(sun_->direction, x, y);
      f.sun_texel_solid_angle = texel_sr(y);
      f.sun_pdf = env.texel_probability(x, y) / f.sun_texel_solid_angle;
    }
    out.push_back(f);
  }
  return out;
}

}  // namespace pdflab::lab
