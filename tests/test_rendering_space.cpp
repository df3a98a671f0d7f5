// The rendering space follows the camera: a room small beside its distance
// from the scene file's origin renders as it would at the origin, and what
// float cannot hold where it is placed is refused, never rendered wrong.
//
// The room: a closed box whose six faces are two-sided lights of radiance E,
// with a white lambertian sphere (albedo a) at its centre and the camera
// inside, looking at the sphere from close enough that every pixel sees it.
// The sphere is convex and sees only the walls, so every pixel is exactly
// a * E for every unbiased strategy. A path that leaves the room through a
// gap between faces meets a background 10x brighter than the walls, a path
// that meets its own sphere again brings back less: either shows.
#include "renderer/error.h"
#include "renderer/film/film.h"
#include "renderer/metrics/statistics.h"
#include "renderer/scene/scene.h"
#include "renderer/scene/scene_loader.h"

#include "tests/render_support.h"
#include "tests/table_strategies.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace pdflab {
namespace {

constexpr double kAlbedo = 0.8;
const double kEmit[3] = {1.0, 0.5, 0.25};
constexpr int kSide = 12;
constexpr std::uint32_t kSpp = 256;
// Float's rounding of a throughput (as in the furnace test): a bias no
// standard error covers, the same in every sample.
constexpr double kRounding = 1e-5;
constexpr double kFamilyAlpha = 0.01;

std::string number(double x) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}
std::string point(double x, double y, double z) {
  char text[128];
  std::snprintf(text, sizeof text, "[%.17g, %.17g, %.17g]", x, y, z);
  return text;
}

// A room `size` across centred at (d, -d / 2, d / 3), the camera inside it.
std::string room_json(double size, double d) {
  const double cx = d, cy = -d / 2, cz = d / 3, h = size / 2;
  return R"({
  "camera": { "width": )" + std::to_string(kSide) + R"(, "height": )" + std::to_string(kSide) +
         R"(, "vfov": 30,
              "lookfrom": )" + point(cx + 0.1 * size, cy + 0.05 * size, cz + 0.43 * size) +
         R"(, "lookat": )" + point(cx, cy, cz) + R"(,
              "max_depth": 8, "background": [10, 10, 10] },
  "materials": { "wall": { "type": "diffuse_light", "emit": [1, 0.5, 0.25], "two_sided": true },
                 "white": { "type": "lambertian", "albedo": [0.8, 0.8, 0.8] } },
  "objects": [
    { "type": "box", "min": )" + point(cx - h, cy - h, cz - h) + R"(, "max": )" + point(cx + h, cy + h, cz + h) +
         R"(, "material": "wall" },
    { "type": "sphere", "center": )" + point(cx, cy, cz) + R"(, "radius": )" + number(0.2 * size) + R"(,
      "material": "white" } ]
})";
}

struct Room {
  double size, distance;
};
const std::vector<Room>& rooms() {
  static const std::vector<Room> r = [] {
    std::vector<Room> all;
    for (const double size : {1e-3, 1.0, 1e3})
      for (const double distance : {1e3, 1e5, 1e7}) all.push_back({size, distance});
    return all;
  }();
  return r;
}

const std::vector<std::string>& strategies() {
  static const std::vector<std::string> s = testing::with_table_strategies(
      {"cosine", "mix:cosine=0.5,light=0.5", "nee-mis", "fastest"},
      [](const testing::TableStrategy& t) { return t.unbiased; });
  return s;
}

class FarRoom : public ::testing::TestWithParam<int> {};

TEST_P(FarRoom, RendersAsAtTheOrigin) {
  const Room room = rooms()[static_cast<std::size_t>(GetParam())];
  const auto scene = std::make_shared<const Scene>(load_scene_text(room_json(room.size, room.distance), "<room>"));
  // Moved to the camera wherever the camera is far from the origin beside the room.
  const bool far = room.distance > kCameraCentredRatio * room.size;
  EXPECT_EQ(scene->origin[0] != 0.0, far);
  if (far) {
    EXPECT_EQ(scene->camera.lookfrom, Vec3(0.0f));
  }

  const int tests = static_cast<int>(rooms().size() * strategies().size()) * 3;
  const double z_pixel = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests * kSide * kSide));
  const double z_total = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
  for (std::size_t k = 0; k < strategies().size(); ++k) {
    const std::string& strategy = strategies()[k];
    SCOPED_TRACE(strategy);
    const testing::Rendered r =
        testing::render_to_completion(scene, strategy, kSpp, 101 + k, 2, std::chrono::seconds(600));
    EXPECT_EQ(r.stats.dropped.total(), 0u);
    double worst_z = 0.0, sum_diff[3] = {}, sum_var[3] = {}, sum_mean[3] = {};
    const std::size_t pixels = static_cast<std::size_t>(kSide) * kSide;
    for (std::size_t p = 0; p < pixels; ++p) {
      double mean[3], var[3];
      r.film.mean(p, mean);
      r.film.variance_of_mean(p, var);
      for (int c = 0; c < 3; ++c) {
        const double exact = kAlbedo * kEmit[c];
        const double beyond = std::max(0.0, std::fabs(mean[c] - exact) - kRounding * exact);
        worst_z = std::max(worst_z, var[c] > 0.0 ? beyond / std::sqrt(var[c]) : (beyond > 0.0 ? INFINITY : 0.0));
        sum_diff[c] += mean[c] - exact;
        sum_var[c] += var[c];
        sum_mean[c] += mean[c];
      }
    }
    std::printf("[room %g at %g] %-40s worst pixel |z| %.2f, mean / exact %.6f\n", room.size, room.distance,
                strategy.c_str(), worst_z, sum_mean[0] / (static_cast<double>(pixels) * kAlbedo * kEmit[0]));
    EXPECT_LT(worst_z, z_pixel);
    for (int c = 0; c < 3; ++c) {
      const double exact = static_cast<double>(pixels) * kAlbedo * kEmit[c];
      const double beyond = std::max(0.0, std::fabs(sum_diff[c]) - kRounding * exact);
      const double z = beyond == 0.0 ? 0.0 : (sum_var[c] > 0.0 ? beyond / std::sqrt(sum_var[c]) : INFINITY);
      EXPECT_LT(z, z_total) << "channel " << c << ": mean " << sum_mean[c] / pixels << ", exact " << exact / pixels;
    }
  }
}

std::string room_name(const ::testing::TestParamInfo<int>& info) {
  const Room room = rooms()[static_cast<std::size_t>(info.param)];
  char text[64];
  std::snprintf(text, sizeof text, "size%g_at%g", room.size, room.distance);
  std::string name = text;
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Rooms, FarRoom, ::testing::Range(0, static_cast<int>(rooms().size())), room_name);

TEST(RenderingSpace, ShippedScenesKeepTheFileOrigin) {
  // The book's scenes and every shipped one have cameras near what they see:
  // their coordinates, and so their images' bits, are the file's own.
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(PDFLAB_SOURCE_DIR "/assets/scenes")) {
    if (entry.path().extension() != ".json") continue;
    const Scene scene = load_scene_file(entry.path().string());
    EXPECT_EQ(scene.origin, (std::array<double, 3>{0.0, 0.0, 0.0})) << entry.path();
    ++scenes;
  }
  EXPECT_GE(scenes, 8);
}

TEST(RenderingSpace, FilePointTurnsARenderingSpacePointBack) {
  const Scene scene = load_scene_text(room_json(1.0, 1e6), "<room>");
  ASSERT_NE(scene.origin[0], 0.0);
  // The sphere's centre, 1e6 from the file's origin, is where the file put it
  // to float's precision near the camera, not to float's precision at 1e6.
  const auto centre = file_point(scene, scene.spheres[0].center);
  EXPECT_NEAR(centre[0], 1e6, 1e-6);
  EXPECT_NEAR(centre[1], -5e5, 1e-6);
  EXPECT_NEAR(centre[2], 1e6 / 3, 1e-6);
}

TEST(RenderingSpace, ABoxFloatCannotPlaceIsRefused) {
  // A box 1e-3 across 1e7 from the camera, where float's steps are 1: its
  // faces cannot meet. Refused with the object and the sizes, not rendered.
  const std::string json = R"({
    "camera": { "width": 8, "height": 8, "vfov": 30, "lookfrom": [0, 0, 0], "lookat": [0, 0, 1] },
    "materials": { "white": { "type": "lambertian", "albedo": [0.5, 0.5, 0.5] } },
    "objects": [ { "type": "sphere", "center": [0, 0, 5], "radius": 1, "material": "white" },
                 { "type": "box", "min": [1e7, 0, 0], "max": [10000000.001, 0.001, 0.001], "material": "white" } ]
  })";
  try {
    (void)load_scene_text(json, "<tiny box>");
    FAIL() << "a box of 1e-3 at 1e7 was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("<tiny box>: objects[1]"), std::string::npos) << what;
    EXPECT_NE(what.find("steps of single precision"), std::string::npos) << what;
  }
  // The same box near the camera is accepted: the rendering space moves to it.
  const std::string near = R"({
    "camera": { "width": 8, "height": 8, "vfov": 30, "lookfrom": [1e7, 0.0005, 0.01], "lookat": [1e7, 0.0005, 0] },
    "materials": { "white": { "type": "lambertian", "albedo": [0.5, 0.5, 0.5] } },
    "objects": [ { "type": "box", "min": [1e7, 0, 0], "max": [10000000.001, 0.001, 0.001], "material": "white" } ]
  })";
  const Scene scene = load_scene_text(near, "<near box>");
  EXPECT_EQ(scene.origin[0], 1e7);
}

TEST(RenderingSpace, ACameraFarFromTheOriginKeepsItsDirection) {
  // lookat 1e-3 from lookfrom, both 1e7 from the origin: in float they were
  // one point ("the same point"); in the camera's space the view is exact.
  const std::string json = R"({
    "camera": { "width": 8, "height": 8, "vfov": 30, "lookfrom": [1e7, 0, 0], "lookat": [1e7, 0, 0.001] },
    "materials": { "white": { "type": "lambertian", "albedo": [0.5, 0.5, 0.5] } },
    "objects": [ { "type": "sphere", "center": [1e7, 0, 3e5], "radius": 1e5, "material": "white" } ]
  })";
  const Scene scene = load_scene_text(json, "<far camera>");
  EXPECT_EQ(scene.camera.lookfrom, Vec3(0.0f));
  EXPECT_FLOAT_EQ(scene.camera.lookat.z, 0.001f);
  EXPECT_EQ(scene.camera.lookat.x, 0.0f);
}

}  // namespace
}  // namespace pdflab
