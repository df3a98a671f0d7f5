#include "app/veach_command.h"

#include "app/measured_run.h"
#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/metrics/metrics.h"
#include "renderer/scene/scene_loader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

namespace pdflab {

namespace {

constexpr const char* kStrategies[4] = {"bsdf", "light-sa", "nee-mis:balance+bsdf", "nee-mis+bsdf"};
constexpr const char* kLabels[4] = {"BSDF only (bsdf)", "light only (light-sa)", "balance (nee-mis:balance+bsdf)",
                                    "power (nee-mis+bsdf)"};
constexpr int kGap = 4;  // white pixels between the panels

// Which plate and which light each pixel measures: the microfacet material
// its centre's camera ray hits (plates ordered by alpha, sharpest first), and
// the emitting sphere whose cone lies nearest the mirror direction there
// (lights ordered by radius, smallest first). -1: none.
struct Regions {
  std::vector<int> plate, light;
  std::vector<float> plate_alpha, light_radius;
};

Regions find_regions(const Scene& scene) {
  Regions r;
  std::vector<std::uint32_t> plates, lights;  // material indices; sphere indices
  for (std::uint32_t m = 0; m < scene.materials.size(); ++m)
    if (scene.materials[m].type == MaterialType::Microfacet) plates.push_back(m);
  std::sort(plates.begin(), plates.end(),
            [&](std::uint32_t a, std::uint32_t b) { return scene.materials[a].alpha < scene.materials[b].alpha; });
  for (std::uint32_t s = 0; s < scene.spheres.size(); ++s)
    if (scene.materials[scene.spheres[s].material].type == MaterialType::DiffuseLight) lights.push_back(s);
  std::sort(lights.begin(), lights.end(),
            [&](std::uint32_t a, std::uint32_t b) { return scene.spheres[a].radius < scene.spheres[b].radius; });
  for (std::uint32_t m : plates) r.plate_alpha.push_back(scene.materials[m].alpha);
  for (std::uint32_t s : lights) r.light_radius.push_back(scene.spheres[s].radius);
  const int w = scene.camera.width, h = scene.camera.height;
  r.plate.assign(static_cast<std::size_t>(w) * h, -1);
  r.light.assign(static_cast<std::size_t>(w) * h, -1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Ray ray = scene.camera.generate_ray(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
      Hit hit;
      if (!intersect(scene, ray, kInf, hit)) continue;
      const auto p = std::find(plates.begin(), plates.end(), hit.material);
      if (p == plates.end()) continue;
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      r.plate[i] = static_cast<int>(p - plates.begin());
      const Vec3 n = dot(ray.direction, hit.normal) < 0.0f ? hit.normal : -hit.normal;
      const Vec3 mirror = ray.direction - n * (2.0f * dot(ray.direction, n));
      double nearest = 1e300;
      for (std::size_t k = 0; k < lights.size(); ++k) {
        const Sphere& s = scene.spheres[lights[k]];
        const Vec3 to = s.center - hit.point;
        const double d = length(to);
        const double angle = std::acos(std::clamp(static_cast<double>(dot(mirror, to)) / d, -1.0, 1.0)) -
                             std::asin(std::min(1.0, static_cast<double>(s.radius) / d));
        if (angle < nearest) nearest = angle, r.light[i] = static_cast<int>(k);
      }
    }
  return r;
}

std::string format(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

// A Markdown row of four relMSE values, the lowest in bold.
std::string row(const std::string& head, const double (&v)[4], bool ratio) {
  const double best = *std::min_element(v, v + 4);
  std::string out = "| " + head + " |";
  for (double x : v) {
    const char* mark = x == best ? "**" : "";
    out.append(" ").append(mark).append(format(x)).append(mark).append(" |");
  }
  if (ratio) {
    char text[32];
    std::snprintf(text, sizeof text, " %.2f |", v[3] / std::min(v[0], v[1]));
    out += text;
  }
  return out + "\n";
}

}  // namespace

int run_veach(const VeachOptions& o) {
  if (!(o.seconds > 0.0) && o.spp == 0) throw InputError("veach needs --seconds (equal time) or --spp");
  if (o.seeds < 1) throw InputError("--seeds must be at least 1");
  check_output_path(o.out);
  if (!o.table.empty()) check_output_path(o.table);
  check_distinct_outputs({o.out, o.table});
  auto scene = std::make_shared<Scene>(load_scene_file(o.scene));
  std::vector<Strategy> strategies;
  for (const char* s : kStrategies) strategies.push_back(with_roulette(Strategy::parse(s), o.roulette_depth));
  std::vector<std::uint64_t> seeds;
  for (int k = 0; k < o.seeds; ++k) seeds.push_back(o.seed + static_cast<std::uint64_t>(k));
  const Reference reference = comparison_reference(*scene, reference_choice(o), strategies, seeds, o.quiet);
  const Regions regions = find_regions(*scene);
  const std::size_t plates = regions.plate_alpha.size(), lights = regions.light_radius.size();
  if (plates == 0) throw InputError("scene '" + o.scene + "' shows no microfacet plate to measure");
  const int w = scene->camera.width, h = scene->camera.height;

  // Sums of (x - r)^2 / (r^2 + eps) per estimator and region, and their counts.
  std::vector<double> plate_sum(4 * plates, 0.0), pair_sum(4 * plates * std::max<std::size_t>(lights, 1), 0.0);
  std::vector<double> plate_count(plates, 0.0), pair_count(plates * std::max<std::size_t>(lights, 1), 0.0);
  for (std::size_t i = 0; i < regions.plate.size(); ++i)
    if (regions.plate[i] >= 0) {
      plate_count[static_cast<std::size_t>(regions.plate[i])] += 3.0;
      if (regions.light[i] >= 0)
        pair_count[static_cast<std::size_t>(regions.plate[i]) * lights + static_cast<std::size_t>(regions.light[i])] += 3.0;
    }
  std::vector<float> panel(3 * static_cast<std::size_t>(2 * w + kGap) * (2 * h + kGap), 1.0f);
  double seconds[4] = {};
  std::uint32_t spp[4] = {};
  for (int e = 0; e < 4; ++e)
    for (std::size_t k = 0; k < seeds.size(); ++k) {
      const MeasuredRun run = render_measured(scene, strategies[e], seeds[k], {o.seconds, o.spp, o.threads},
                                              std::string(kStrategies[e]) + " seed " + std::to_string(seeds[k]),
                                              !o.quiet);
      seconds[e] += run.stats.seconds / static_cast<double>(seeds.size());
      spp[e] = std::max(spp[e], static_cast<std::uint32_t>(run.stats.spp));
      const std::vector<float> image = run.film.mean_rgb();
      for (std::size_t i = 0; i < regions.plate.size(); ++i) {
        if (regions.plate[i] < 0) continue;
        double err = 0.0;
        for (int c = 0; c < 3; ++c) {
          const double r = reference.rgb[3 * i + c], d = image[3 * i + c] - r;
          err += d * d / (r * r + kRelMseEpsilon);
        }
        const std::size_t p = static_cast<std::size_t>(regions.plate[i]);
        plate_sum[static_cast<std::size_t>(e) * plates + p] += err;
        if (regions.light[i] >= 0)
          pair_sum[(static_cast<std::size_t>(e) * plates + p) * lights + static_cast<std::size_t>(regions.light[i])] += err;
      }
      if (k == 0) {
        const int ox = (e % 2) * (w + kGap), oy = (e / 2) * (h + kGap);
        for (int y = 0; y < h; ++y)
          std::copy_n(&image[3 * static_cast<std::size_t>(y) * w], 3 * static_cast<std::size_t>(w),
                      &panel[3 * (static_cast<std::size_t>(oy + y) * (2 * w + kGap) + ox)]);
      }
    }
  write_image(o.out, panel, 2 * w + kGap, 2 * h + kGap);

  const double n = static_cast<double>(seeds.size());
  std::ostringstream t;
  t << "Veach's table: relMSE (mean of (x - r)^2 / (r^2 + 0.01) over the region's pixels and channels), the mean of "
    << seeds.size() << " seed(s), against '" << reference.path << "'. Top left to bottom right in '" << o.out
    << "'.\n\n| estimator | spp | seconds |\n|---|---|---|\n";
  for (int e = 0; e < 4; ++e) t << "| " << kLabels[e] << " | " << spp[e] << " | " << format(seconds[e]) << " |\n";
  t << "\n| plate |";
  for (const char* l : kLabels) t << " " << l << " |";
  t << "\n|---|---|---|---|---|\n";
  for (std::size_t p = 0; p < plates; ++p) {
    double v[4];
    for (int e = 0; e < 4; ++e) v[e] = plate_sum[static_cast<std::size_t>(e) * plates + p] / (plate_count[p] * n);
    t << row("alpha " + format(regions.plate_alpha[p]), v, false);
  }
  if (lights > 0) {
    t << "\n| plate, light |";
    for (const char* l : kLabels) t << " " << l << " |";
    t << " power / best single |\n|---|---|---|---|---|---|\n";
    for (std::size_t p = 0; p < plates; ++p)
      for (std::size_t l = 0; l < lights; ++l) {
        const double count = pair_count[p * lights + l];
        if (count == 0.0) continue;
        double v[4];
        for (int e = 0; e < 4; ++e) v[e] = pair_sum[(static_cast<std::size_t>(e) * plates + p) * lights + l] / (count * n);
        t << row("alpha " + format(regions.plate_alpha[p]) + ", radius " + format(regions.light_radius[l]), v, true);
      }
  }
  std::fputs(t.str().c_str(), stdout);
  if (!o.table.empty()) {
    const std::string text = t.str();
    write_file_atomic(o.table, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
  }
  return 0;
}

}  // namespace pdflab
