// Analytic scenes: a lambertian floor (or a big ground sphere) lit by one light
// and nothing else, so every bit of light is direct and the exact image is known
// in closed form. The floor's outgoing radiance is albedo / pi times the
// irradiance from the light:
//  - a quad light by Lambert's polygon formula,
//    E = L / 2 * |sum_i angle(r_i, r_i+1) * (n . normalize(r_i x r_i+1))|,
//    or, where the light is seen small and that formula cancels, by quadrature
//    of L cos cos' / d^2 over its area;
//  - a sphere light fully above the horizon by its form factor,
//    E = pi * L * (r / d)^2 * cos(alpha).
// Each pixel's exact value is averaged over the pixel's footprint (the camera
// jitters inside the pixel) in double. Every strategy, rendered through the
// session (the packet tracer), must land within 3 standard errors of the exact
// image at scene scales from 1e-3 to 1e6, quad lights down to 1e-5 of the scene
// and sphere lights down to 1e-9 of it (rays aimed at a sphere that float
// cannot aim at reach it: the aimed-ray rule), including shading points
// nearly in the light's plane, and a light beside one 1e9 times as bright
// that faces away (the light choice by what a point receives).
#include "renderer/integrator/integrator.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/scene_loader.h"

#include "tests/render_support.h"
#include "tests/table_strategies.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace pdflab {
namespace {

struct D3 {
  double x = 0, y = 0, z = 0;
};
D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 operator*(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 cross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double norm(D3 a) { return std::sqrt(dot(a, a)); }
D3 unit(D3 a) { return a * (1.0 / norm(a)); }
D3 d3(const Vec3& v) { return {v.x, v.y, v.z}; }

enum class LightShape { Quad, Sphere };
enum class Ground { Floor, Sphere };

// One analytic scene. Lengths are multiples of `scale`; the light's size is
// `light_size * scale` (the quad's side or the sphere's radius), centred
// `light_height * scale` above the floor at (0, h, light_z * scale).
struct AnalyticCase {
  std::string name;
  double scale = 1.0;
  LightShape shape = LightShape::Quad;
  double light_size = 0.1;
  double light_height = 0.5;
  double light_z = 0.0;
  double sliver = 1.0;  // a quad's second edge is light_size * sliver
  Ground ground = Ground::Floor;
  double ground_radius = 0.0;  // Ground::Sphere: centre at (0, -radius, 0)
  // A second, one-sided quad light this many times as bright, off to the side
  // and facing up, away from everything (0: none): its light leaves the scene,
  // so the image is the first light's alone, but chosen by power it would get
  // all but 1 / (1 + starving) of the light samples.
  double starving = 0.0;
};

constexpr double kAlbedo = 0.5;

// The light's radiance, chosen so that the floor's radiance is of order 0.1.
double emission(const AnalyticCase& c) {
  const double a = c.light_size * c.scale, h = c.light_height * c.scale, s = c.scale;
  if (c.shape == LightShape::Sphere) return (s * s) / (std::numbers::pi * a * a);
  if (c.sliver != 1.0) return (s * s) / (a * a * c.sliver);
  // A quad seen at grazing angles (h << scale) gives E ~ L a^2 h^2 / d^4.
  const double grazing = std::min(1.0, h / s);
  return (s * s) / (a * a * grazing * grazing);
}

std::string scene_json(const AnalyticCase& c) {
  const double s = c.scale, a = c.light_size * s, b = a * c.sliver, h = c.light_height * s, lz = c.light_z * s;
  std::ostringstream o;
  o.precision(17);
  o << R"({"camera": {"width": 12, "height": 12, "vfov": 30, "max_depth": 50,)"
    << R"("lookfrom": [0, )" << 0.25 * s << ", " << -0.6 * s << R"(], "lookat": [0, 0, 0]},)"
    << R"("materials": {"floor": {"type": "lambertian", "albedo": [0.5, 0.5, 0.5]},)"
    << R"("lamp": {"type": "diffuse_light", "emit": [)" << emission(c) << ", " << emission(c) << ", "
    << emission(c) << "]}";
  if (c.starving > 0.0) {
    const double e = emission(c) * c.starving;
    o << R"(, "bright": {"type": "diffuse_light", "emit": [)" << e << ", " << e << ", " << e << "]}";
  }
  o << R"(}, "objects": [)";
  if (c.ground == Ground::Floor) {
    // Normal +y: u x v = (0, 0, 8s) x (8s, 0, 0).
    o << R"({"type": "quad", "q": [)" << -4 * s << ", 0, " << -4 * s << R"(], "u": [0, 0, )" << 8 * s
      << R"(], "v": [)" << 8 * s << R"(, 0, 0], "material": "floor"},)";
  } else {
    o << R"({"type": "sphere", "center": [0, )" << -c.ground_radius << R"(, 0], "radius": )" << c.ground_radius
      << R"(, "material": "floor"},)";
  }
  if (c.starving > 0.0) {
    // Facing up: u x v = (0, 0, a) x (a, 0, 0) = (0, a^2, 0); out of the camera's view.
    o << R"({"type": "quad", "q": [)" << 3 * s << ", " << h << ", " << lz - a / 2 << R"(], "u": [0, 0, )" << a
      << R"(], "v": [)" << a << R"(, 0, 0], "material": "bright"},)";
  }
  if (c.shape == LightShape::Quad) {
    // Facing down: u x v = (a, 0, 0) x (0, 0, a) = (0, -a^2, 0).
    o << R"({"type": "quad", "q": [)" << -a / 2 << ", " << h << ", " << lz - b / 2 << R"(], "u": [)" << a
      << R"(, 0, 0], "v": [0, 0, )" << b << R"(], "material": "lamp"}]})";
  } else {
    o << R"({"type": "sphere", "center": [0, )" << h << ", " << lz << R"(], "radius": )" << a
      << R"(, "material": "lamp"}]})";
  }
  return o.str();
}

// Irradiance at x (normal n) from the light of case c, in double.
double exact_irradiance(const AnalyticCase& c, D3 x, D3 n) {
  const double s = c.scale, a = c.light_size * s, b = a * c.sliver, h = c.light_height * s, lz = c.light_z * s;
  const double L = emission(c);
  if (c.shape == LightShape::Sphere) {
    const D3 to_centre = D3{0, h, lz} - x;
    const double d = norm(to_centre);
    const double cos_alpha = dot(n, to_centre) / d;
    if (cos_alpha * d < a) return std::numeric_limits<double>::quiet_NaN();  // not fully above the horizon
    return std::numbers::pi * L * (a / d) * (a / d) * cos_alpha;
  }
  if (!(x.y < h)) return 0.0;  // behind a one-sided light facing down
  // Seen small, the polygon formula cancels catastrophically (its four terms are
  // of order a / d and their sum can be 1e-12 of that, at grazing angles):
  // integrate L cos cos' / d^2 over the light's area instead, on a 32 x 32
  // midpoint grid, accurate to about (a / d)^2 / 10^4 there.
  const D3 centre{0, h, lz};
  if (std::min(a, b) < 1e-2 * norm(centre - x)) {
    constexpr int N = 32;
    double sum = 0.0;
    for (int j = 0; j < N; ++j)
      for (int i = 0; i < N; ++i) {
        const D3 y{-a / 2 + a * (i + 0.5) / N, h, lz - b / 2 + b * (j + 0.5) / N};
        const D3 d = y - x;
        const double d2 = dot(d, d);
        const double cos_x = dot(n, d) / std::sqrt(d2), cos_light = d.y / std::sqrt(d2);  // light faces -y
        if (cos_x > 0.0) sum += cos_x * cos_light / d2;
      }
    return L * sum * (a * b) / (N * N);
  }
  const std::array<D3, 4> v = {D3{-a / 2, h, lz - b / 2}, D3{a / 2, h, lz - b / 2}, D3{a / 2, h, lz + b / 2},
                               D3{-a / 2, h, lz + b / 2}};
  double sum = 0.0;
  for (int i = 0; i < 4; ++i) {
    const D3 r0 = v[i] - x, r1 = v[(i + 1) % 4] - x;
    const D3 g = cross(r0, r1);
    const double angle = std::atan2(norm(g), dot(r0, r1));
    sum += angle * dot(n, unit(g));
  }
  return 0.5 * L * std::fabs(sum);
}

// The floor's radiance seen along a camera ray (0 where the ray misses it).
double exact_radiance(const AnalyticCase& c, D3 origin, D3 dir) {
  D3 x, n;
  if (c.ground == Ground::Floor) {
    if (!(dir.y < 0.0)) return 0.0;
    const double t = -origin.y / dir.y;
    x = origin + dir * t;
    if (std::fabs(x.x) > 4 * c.scale || std::fabs(x.z) > 4 * c.scale) return 0.0;
    n = {0, 1, 0};
  } else {
    const D3 centre{0, -c.ground_radius, 0};
    const D3 f = origin - centre;
    const double b = -dot(f, dir);
    const D3 closest = f + dir * b;
    const double disc = c.ground_radius * c.ground_radius - dot(closest, closest);
    if (disc < 0.0) return 0.0;
    // The nearer root without cancellation: t = c / q with q = b + sqrt(disc).
    const double q = b + std::sqrt(disc);
    const double t = (dot(f, f) - c.ground_radius * c.ground_radius) / q;
    x = origin + dir * t;
    n = unit(x - centre);
  }
  return kAlbedo / std::numbers::pi * exact_irradiance(c, x, n);
}

// The exact image: each pixel averaged over its footprint on a G x G grid.
std::vector<double> exact_image(const AnalyticCase& c, const Camera& cam) {
  constexpr int G = 8;
  std::vector<double> img(static_cast<std::size_t>(cam.width * cam.height));
  const D3 o = d3(cam.lookfrom), p00 = d3(cam.pixel00), du = d3(cam.du), dv = d3(cam.dv);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      double sum = 0.0;
      for (int j = 0; j < G; ++j)
        for (int i = 0; i < G; ++i) {
          const double px = x + (i + 0.5) / G, py = y + (j + 0.5) / G;
          sum += exact_radiance(c, o, unit(p00 + du * px + dv * py));
        }
      img[static_cast<std::size_t>(y * cam.width + x)] = sum / (G * G);
    }
  return img;
}

enum class Tracer { Packets, OnePath };

struct Param {
  AnalyticCase scene;
  std::string strategy;
  std::uint32_t spp;
  Tracer tracer = Tracer::Packets;
};

// The one-path tracer, sample by sample, into a film (the session renders with packets).
testing::Rendered render_one_path(const std::shared_ptr<const Scene>& scene, const std::string& strategy,
                                  std::uint32_t spp, std::uint64_t seed) {
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse(strategy), *scene);
  testing::Rendered r{Film(scene->camera.width, scene->camera.height), {}};
  for (int y = 0; y < scene->camera.height; ++y)
    for (int x = 0; x < scene->camera.width; ++x)
      for (std::uint32_t s = 0; s < spp; ++s)
        r.film.add(static_cast<std::size_t>(y * scene->camera.width + x),
                   render_pixel_sample(*scene, plan, seed, x, y, s, r.stats.dropped));
  return r;
}

std::string param_name(const ::testing::TestParamInfo<Param>& info) {
  std::string s = info.param.scene.name + "_" + info.param.strategy +
                  (info.param.tracer == Tracer::OnePath ? "_one_path" : "");
  for (char& ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return s;
}

// Names the case in failure messages instead of dumping its bytes.
void PrintTo(const Param& p, std::ostream* os) {
  *os << p.scene.name << " " << p.strategy << " " << p.spp << " spp"
      << (p.tracer == Tracer::OnePath ? " (one-path tracer)" : "");
}

class Analytic : public ::testing::TestWithParam<Param> {};

TEST_P(Analytic, MatchesTheClosedFormWithinThreeStandardErrors) {
  const Param& p = GetParam();
  auto scene = std::make_shared<Scene>(load_scene_text(scene_json(p.scene), p.scene.name + ".json"));
  scene->prepare();
  const std::vector<double> exact = exact_image(p.scene, scene->camera);
  for (double e : exact) ASSERT_TRUE(std::isfinite(e)) << "the case is not analytic everywhere";
  const testing::Rendered r =
      p.tracer == Tracer::OnePath
          ? render_one_path(scene, p.strategy, p.spp, 17)
          : testing::render_to_completion(scene, p.strategy, p.spp, 17, 2, std::chrono::seconds(300));
  EXPECT_EQ(r.stats.dropped.total(), 0u);
  // The whole image as one estimate: sum of the pixel means against the sum of
  // the exact values, with the variance of the sum from the film's per-pixel
  // variance of the mean.
  double est = 0.0, truth = 0.0, var = 0.0;
  for (std::size_t i = 0; i < r.film.pixel_count(); ++i) {
    double m[3], v[3];
    r.film.mean(i, m);
    r.film.variance_of_mean(i, v);
    est += m[0];
    var += v[0];
    truth += exact[i];
  }
  ASSERT_GT(truth, 0.0);
  if (std::getenv("ANALYTIC_DEBUG"))
    for (std::size_t i = 0; i < r.film.pixel_count(); ++i) {
      double m[3];
      r.film.mean(i, m);
      std::printf("%5.3f%c", exact[i] > 0 ? m[0] / exact[i] : -1.0, i % 12 == 11 ? '\n' : ' ');
    }
  const double se = std::sqrt(var);
  // The test only means something when the render is precise: a strategy that
  // rarely finds the light has a useless (and unreliable) error estimate.
  EXPECT_LT(se / truth, 0.02) << "too few samples for a meaningful comparison";
  EXPECT_LT(std::fabs(est - truth), 3.0 * se + 1e-6 * truth)
      << "estimate " << est << " exact " << truth << " (" << (est / truth - 1.0) * 100.0 << "%, z "
      << (est - truth) / se << ")";
}

// Whether the strategy gives weight to a technique that draws a target in `scene`.
bool aims_at_light(const std::string& strategy, const Scene& scene) {
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse(strategy), scene);
  for (int i = 0; i < kTechniqueCount; ++i)
    if (plan.weight[i] > 0.0f && technique_info(static_cast<Technique>(i)).draws_target) return true;
  return false;
}

std::vector<Param> cases() {
  std::vector<Param> out;
  // Russian roulette trades samples' cost for their variance: more of them
  // reach the precision the comparison needs.
  const auto light_spp = [](const std::string& s) { return s.find("+rr") != std::string::npos ? 256u : 64u; };
  std::vector<std::string> light_strategies = {"light",        "light-sa", "mix:cosine=0.5,light=0.5",
                                                     "mix:cosine=0.5,light-sa=0.5", "nee-mis", "nee-mis:balance",
                                                     // continuations drawn by a mixture, Russian roulette
                                                     "nee-mis+mix:cosine=0.5,light=0.5", "mix:cosine=0.5,light=0.5+rr:1",
                                                     "nee-mis:balance+mix:cosine=0.5,light-sa=0.5+rr:1",
                                                     // the +sobol sampler
                                                     "mix:cosine=0.5,light=0.5+sobol", "nee-mis+sobol"};
  // Half of uniform-sphere's samples go below the floor (and untrained
  // guiding's, guided:0, the uniform sphere).
  const auto blind_spp = [](const std::string& s) {
    return s == "cosine"                                ? 4096u
           : s.find("light") != std::string::npos       ? 256u
           : s == "uniform-sphere" || s == "guided:0"   ? 16384u
                                                        : 8192u;
  };
  std::vector<std::string> blind_strategies = {"cosine", "uniform-hemisphere", "mix:uniform-sphere=0.5,light=0.5"};
  // Every technique of the table, alone and mixed with cosine: those that aim
  // at the light with the light strategies, the others (unbiased) with the blind ones.
  {
    AnalyticCase probe;
    const Scene scene = load_scene_text(scene_json(probe), "probe.json");
    for (const testing::TableStrategy& t : testing::table_strategies()) {
      if (t.technique == Technique::SpecularObjects && t.text == "specular-objects") continue;  // no glass or metal here
      if (t.needs_environment) continue;  // no map here: EnvironmentFloor below
      std::vector<std::string>& into = aims_at_light(t.text, scene) ? light_strategies : blind_strategies;
      if ((&into == &blind_strategies && !t.unbiased) || std::find(into.begin(), into.end(), t.text) != into.end()) continue;
      into.push_back(t.text);
    }
  }
  for (const double scale : {1e-3, 1.0, 1e3, 1e6}) {
    char sc[16];
    std::snprintf(sc, sizeof sc, "s%g", scale);
    for (const double size : {1e-1, 1e-3, 1e-5, 1e-7, 1e-9}) {
      char sz[16];
      std::snprintf(sz, sizeof sz, "%g", size);
      for (const LightShape shape : {LightShape::Quad, LightShape::Sphere}) {
        // Sphere lights down to 1e-9 of their distance (the aimed-ray rule's).
        if (size < 1e-5 && shape == LightShape::Quad) continue;
        AnalyticCase c;
        c.scale = scale;
        c.shape = shape;
        c.light_size = size;
        c.light_z = 0.3;
        c.name = std::string(sc) + (shape == LightShape::Quad ? "_quad" : "_sphere") + sz;
        for (const auto& s : light_strategies) out.push_back({c, s, light_spp(s)});
        // Strategies blind to the light find it only when it is large.
        if (size >= 1e-1 && shape == LightShape::Quad)
          for (const auto& s : blind_strategies)
            out.push_back({c, s, blind_spp(s)});
      }
      if (size < 1e-5) continue;
      // A quad barely above the floor, behind the camera: every floor point in
      // view is nearly in the light's plane and sees it at a grazing angle.
      AnalyticCase g;
      g.scale = scale;
      g.light_size = size;
      g.light_height = 1e-3;
      g.light_z = -0.9;
      g.name = std::string(sc) + "_grazing" + sz;
      for (const auto& s : light_strategies) out.push_back({g, s, light_spp(s)});
    }
  }
  // Slivers: a strip 1e-1 of the scene long and 1e-8 of it wide subtends less
  // than float's precision for a direction, so rays aimed at it miss it unless
  // the tracer knows where they were aimed.
  for (const double scale : {1e-3, 1.0, 1e6}) {
    AnalyticCase c;
    c.scale = scale;
    c.light_size = 0.1;
    c.sliver = 1e-7;
    c.light_z = 0.3;
    char sc[16];
    std::snprintf(sc, sizeof sc, "s%g", scale);
    c.name = std::string(sc) + "_sliver";
    for (const auto& s : light_strategies) out.push_back({c, s, light_spp(s)});
  }
  // Big ground spheres (the first book's ground sphere has radius 1000).
  for (const double radius : {1e3, 1e5}) {
    AnalyticCase c;
    c.ground = Ground::Sphere;
    c.ground_radius = radius;
    c.light_size = 0.1;
    c.light_z = 0.3;
    c.name = radius == 1e3 ? "ground_sphere_1e3" : "ground_sphere_1e5";
    for (const auto& s : light_strategies) out.push_back({c, s, light_spp(s)});
  }
  // A light starved by another's power: a lamp 1e9 times as bright as the
  // scene's light, facing away from everything. Chosen by power alone, the
  // scene's light got 1e-9 of the light samples and light-sa rendered black;
  // chosen by what the point receives (the floor is behind the bright lamp),
  // and with the defensive floor, it gets 99% of them.
  for (const double scale : {1.0, 1e6}) {
    AnalyticCase c;
    c.scale = scale;
    c.light_size = 0.1;
    c.light_z = 0.3;
    c.starving = 1e9;
    c.name = scale == 1.0 ? "starved" : "s1e6_starved";
    // The book's `light` still chooses the two lamps alike: half its samples find nothing.
    for (const auto& s : light_strategies) out.push_back({c, s, 4 * light_spp(s)});
  }
  // Every case again through the one-path tracer.
  const std::size_t n = out.size();
  for (std::size_t i = 0; i < n; ++i) {
    Param p = out[i];
    p.tracer = Tracer::OnePath;
    out.push_back(p);
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(Scenes, Analytic, ::testing::ValuesIn(cases()), param_name);

// ---- A floor under a constant environment ---------------------------------
// A floor of albedo a under an environment of radiance 1 from every direction
// (and nothing else) reflects exactly a: its irradiance is pi, and it sends
// a / pi of it towards the camera. Every strategy that can see the
// environment converges to a, cosine sample by sample (its weight is the
// albedo and the environment is 1).

// The strategies for the floor: every unbiased one of the table that uses
// the environment or has none to aim at (a mixture with light leaves it
// cosine), nee-mis with the environment as its only light.
std::vector<std::string> environment_floor_strategies() {
  std::vector<std::string> out = {"nee-mis", "nee-mis:balance", "nee-mis+mix:cosine=0.5,environment=0.5",
                                  "environment", "mix:uniform-sphere=0.5,environment=0.5"};
  for (const testing::TableStrategy& t : testing::table_strategies())
    if (t.unbiased && !t.aims && std::find(out.begin(), out.end(), t.text) == out.end()) out.push_back(t.text);
  return out;
}

std::shared_ptr<const Scene> environment_floor(const Vec3& albedo) {
  char text[1024];
  std::snprintf(text, sizeof text, R"({
    "camera": { "width": 8, "height": 8, "vfov": 40, "lookfrom": [0, 1, 0], "lookat": [0, 0, 0], "vup": [0, 0, 1] },
    "materials": { "floor": { "type": "lambertian", "albedo": [%.9g, %.9g, %.9g] } },
    "objects": [ { "type": "quad", "q": [-5000, 0, -5000], "u": [0, 0, 10000], "v": [10000, 0, 0], "material": "floor" } ]
  })", static_cast<double>(albedo.x), static_cast<double>(albedo.y), static_cast<double>(albedo.z));
  auto scene = std::make_shared<Scene>(load_scene_text(text, "environment_floor.json"));
  scene->environment = std::make_shared<Environment>(std::vector<float>(16 * 8 * 3, 1.0f), 16, 8, 1.0f, 0.0f);
  return scene;
}

class EnvironmentFloor : public ::testing::TestWithParam<std::string> {};

TEST_P(EnvironmentFloor, ReflectsExactlyItsAlbedo) {
  const Vec3 albedo(0.3f, 0.6f, 0.9f);
  const std::shared_ptr<const Scene> scene = environment_floor(albedo);
  const testing::Rendered r = testing::render_to_completion(scene, GetParam(), 1024, 29, 2, std::chrono::seconds(300));
  double sum[3] = {}, var[3] = {};
  const std::size_t n = r.film.pixel_count();
  for (std::size_t i = 0; i < n; ++i) {
    double m[3], v[3];
    r.film.mean(i, m);
    r.film.variance_of_mean(i, v);
    for (int c = 0; c < 3; ++c) sum[c] += m[c] / static_cast<double>(n), var[c] += v[c] / static_cast<double>(n * n);
    if (GetParam() == "cosine") {
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], albedo[c], 1e-6) << "pixel " << i << ": cosine's every sample is a";
    }
  }
  for (int c = 0; c < 3; ++c) {
    const double a = albedo[c], se = std::sqrt(var[c]);
    EXPECT_LT(se / a, 0.01) << "too few samples for a meaningful comparison";
    EXPECT_LT(std::fabs(sum[c] - a), 4.0 * se + 1e-6 * a)
        << "channel " << c << ": estimate " << sum[c] << ", exact " << a << " (z " << (sum[c] - a) / se << ")";
  }
  EXPECT_EQ(r.stats.dropped.total(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Strategies, EnvironmentFloor, ::testing::ValuesIn(environment_floor_strategies()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return testing::test_name(p.param); });

}  // namespace
}  // namespace pdflab
