#pragma once
// A render through the library as the tests want it: a fresh session renders
// a scene to a fixed number of samples per pixel and is waited for.
#include "renderer/film/film.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

namespace pdflab::testing {

struct Rendered {
  Film film;
  SessionStats stats;
};

// Fails the test (and returns what there is) when the render takes longer than `timeout`.
inline Rendered render_to_completion(std::shared_ptr<const Scene> scene, const std::string& strategy,
                                     std::uint32_t spp, std::uint64_t seed, int threads,
                                     std::chrono::seconds timeout, std::uint32_t first_sample = 0) {
  RenderSession session(threads);
  RenderSettings settings;
  settings.scene = std::move(scene);
  settings.strategy = Strategy::parse(strategy);
  settings.seed = seed;
  settings.target_spp = spp;
  settings.first_sample = first_sample;
  session.set_settings(settings);
  EXPECT_TRUE(session.wait_until_done(timeout)) << "the render did not finish in " << timeout.count() << " s";
  return {session.copy_film(), session.stats()};
}

// A grey floor under a sky of radiance 1 everywhere, seen from above: the
// light a floor point takes in is cos(theta) over its hemisphere.
inline std::shared_ptr<Scene> sky_floor(int width, int height) {
  auto s = std::make_shared<Scene>(load_scene_text(
      R"({"camera": {"width": 32, "height": 24, "lookfrom": [0, 3, 0.01], "lookat": [0, 0, 0], "vfov": 30,
          "max_depth": 2, "background": [1, 1, 1]},
        "materials": {"floor": {"type": "lambertian", "albedo": [0.5, 0.5, 0.5]}},
        "objects": [{"type": "quad", "q": [-2, 0, -2], "u": [0, 0, 4], "v": [4, 0, 0], "material": "floor"}]})",
      "sky floor"));
  s->camera.width = width;
  s->camera.height = height;
  s->prepare();
  return s;
}

}  // namespace pdflab::testing
