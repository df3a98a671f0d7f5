// What nee-mis's light choice costs a sample as the emitters grow in number:
// the choice by power (the light sample's direction and the set's density,
// summed over every emitter, as the integrator asks it) against the light tree
// (the choice by a descent, the chosen emitter's density alone), and the light
// density of a continuation that reaches an emitter (by power: the sum over
// every emitter; by the tree: that emitter's, by a descent). Emitters are
// small spheres scattered through a 10 x 4 x 12 room; the points are on its
// floor. One thread; nanoseconds per call, the best of three passes.
//
//   bench_light_choice [--counts 16,128,1024,4096] [--calls N]
#include "renderer/sampling/mixture.h"
#include "renderer/sampling/rng.h"
#include "renderer/sampling/strategy.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace pdflab;

Scene room_of_spheres(int count) {
  Scene scene;
  scene.name = "spheres";
  Material lamp;
  lamp.type = MaterialType::DiffuseLight;
  Rng rng(7, 1);
  for (int i = 0; i < 4; ++i) {
    lamp.emit = Vec3(5.0f * static_cast<float>(i + 1));
    scene.materials.push_back(lamp);
    scene.material_names.push_back("lamp" + std::to_string(i));
  }
  for (int i = 0; i < count; ++i) {
    const Vec3 c(10.0f * rng.uniform(), 2.0f + 1.8f * rng.uniform(), 12.0f * rng.uniform());
    scene.spheres.push_back(Sphere{c, 0.03f, static_cast<std::uint32_t>(i % 4)});
    scene.targets.push_back({Target::Kind::Sphere, static_cast<std::uint32_t>(i)});
  }
  return scene;
}

template <class F>
double best_ns_per_call(int calls, F f) {
  double best = 1e300;
  for (int pass = 0; pass < 3; ++pass) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < calls; ++i) f(i);
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::nano>(t1 - t0).count() / calls);
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> counts = {16, 128, 1024, 4096};
  int calls = 20000;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--counts") {
      counts.clear();
      std::stringstream in(argv[i + 1]);
      for (std::string item; std::getline(in, item, ',');) counts.push_back(std::atoi(item.c_str()));
    } else if (a == "--calls") {
      calls = std::atoi(argv[i + 1]);
    } else {
      std::fprintf(stderr, "usage: bench_light_choice [--counts 16,128,1024,4096] [--calls N]\n");
      return 2;
    }
  }
  std::printf("| emitters | light sample, power (ns) | light sample, tree (ns) | continuation's light pdf, power (ns) | "
              "continuation's light pdf, tree (ns) |\n|---|---|---|---|---|\n");
  for (const int count : counts) {
    Scene scene = room_of_spheres(count);
    scene.prepare();
    const SamplingPlan power = SamplingPlan::make(Strategy::parse("nee-mis"), scene);
    const SamplingPlan tree = SamplingPlan::make(Strategy::parse("nee-mis+lights:tree"), scene);
    Rng rng(11, 3);
    struct Draw {
      Vec3 point;
      std::uint32_t u;
      float u1, u2;
    };
    std::vector<Draw> draws(static_cast<std::size_t>(calls));
    for (Draw& d : draws) d = {Vec3(10.0f * rng.uniform(), 0.0f, 12.0f * rng.uniform()), rng.next_u32(), rng.uniform(), rng.uniform()};
    const Vec3 up(0.0f, 1.0f, 0.0f);
    volatile float sink = 0.0f;
    const auto light_sample = [&](const SamplingPlan& plan, bool by_tree) {
      return best_ns_per_call(calls, [&](int i) {
        const Draw& d = draws[static_cast<std::size_t>(i)];
        leaf::SolidAngleSetup setup{-1, {}};
        const leaf::Sampled s =
            by_tree ? leaf::sample_tree_targets(plan.emitters, d.point, &up, static_cast<std::int32_t>(d.u), d.u1, d.u2, true,
                                                setup, true, nullptr, nullptr)
                    : leaf::sample_solid_angle_targets(plan.emitters, d.point, static_cast<std::int32_t>(d.u), d.u1, d.u2,
                                                       true, setup);
        sink = sink + s.pdf;
      });
    };
    const double sample_power = light_sample(power, false), sample_tree = light_sample(tree, true);
    // A continuation towards emitter i % count's centre, which it reaches.
    const auto continuation = [&](const SamplingPlan& plan, bool by_tree) {
      return best_ns_per_call(calls, [&](int i) {
        const Draw& d = draws[static_cast<std::size_t>(i)];
        const int k = i % count;
        const Vec3 direction = normalize(scene.spheres[static_cast<std::size_t>(k)].center - d.point);
        const float p = by_tree ? leaf::reached_light_pdf(plan.emitters, d.point, &up, direction, k, -1, 0.0f, true, nullptr)
                                : leaf::solid_angle_targets_pdf(plan.emitters, d.point, direction, -1, 0.0f, true, nullptr);
        sink = sink + p;
      });
    };
    const double pdf_power = continuation(power, false), pdf_tree = continuation(tree, true);
    std::printf("| %d | %.0f | %.0f | %.0f | %.0f |\n", count, sample_power, sample_tree, pdf_power, pdf_tree);
  }
  return 0;
}
