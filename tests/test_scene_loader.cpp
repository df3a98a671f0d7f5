// Scene loading: the book's scene comes out as docs/scene_format.md describes,
// and every class of bad input is an InputError whose message points at the
// offending JSON path (or line and column for syntax errors).
#include "renderer/error.h"
#include "renderer/sampling/leaf.h"
#include "renderer/film/image_io.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/scene_loader.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>
#include <initializer_list>
#include <numbers>
#include <string>

namespace pdflab {
namespace {

// `text` with the first `from` replaced by `to` (unchanged where there is none).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

using json = nlohmann::json;

const std::string kBookScene = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";

// A small valid scene that each validation test breaks in exactly one place.
json minimal_scene() {
  return json::parse(R"({
    "name": "minimal",
    "camera": { "width": 8, "height": 6, "vfov": 40,
                "lookfrom": [0, 0, -10], "lookat": [0, 0, 0], "vup": [0, 1, 0] },
    "materials": {
      "white": { "type": "lambertian", "albedo": [0.5, 0.5, 0.5] },
      "lamp":  { "type": "diffuse_light", "emit": [4, 4, 4] }
    },
    "objects": [
      { "type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white" },
      { "type": "quad", "q": [-1, 3, -1], "u": [2, 0, 0], "v": [0, 0, 2], "material": "lamp" }
    ]
  })");
}

// The message of the InputError that loading `text` throws; fails the test if
// loading succeeds or throws anything else.
std::string load_error(const std::string& text) {
  try {
    (void)load_scene_text(text, "scene.json");
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError, but the scene loaded:\n" << text;
  return {};
}

void expect_error_mentions(const json& doc, std::initializer_list<const char*> needles) {
  const std::string message = load_error(doc.dump());
  for (const char* needle : needles)
    EXPECT_NE(message.find(needle), std::string::npos) << "message '" << message << "' lacks '" << needle << "'";
  EXPECT_EQ(message.rfind("scene.json", 0), 0u) << "message should start with the origin: " << message;
}

TEST(SceneLoader, MinimalSceneLoads) {
  // The base of every validation test must itself be valid, or those tests prove nothing.
  const Scene s = load_scene_text(minimal_scene().dump(), "scene.json");
  EXPECT_EQ(s.camera.width, 8);
  EXPECT_EQ(s.camera.height, 6);
  EXPECT_EQ(s.spheres.size(), 1u);
  EXPECT_EQ(s.quads.size(), 1u);
  // The emitter is a target by default; the lambertian sphere is not.
  ASSERT_EQ(s.targets.size(), 1u);
  EXPECT_EQ(s.targets[0].kind, Target::Kind::Quad);
}

// ---- The book's scene -------------------------------------------------------

struct DVec {
  double x, y, z;
};

DVec book_box_transform(double x, double y, double z) {
  const double a = 15.0 * std::numbers::pi / 180.0;
  return {std::cos(a) * x + std::sin(a) * z + 265.0, y, -std::sin(a) * x + std::cos(a) * z + 295.0};
}

bool near(const Vec3& p, const DVec& q, double tol) {
  return std::fabs(p.x - q.x) < tol && std::fabs(p.y - q.y) < tol && std::fabs(p.z - q.z) < tol;
}

TEST(SceneLoader, BookSceneCounts) {
  const Scene s = load_scene_file(kBookScene);
  EXPECT_EQ(s.quads.size(), 12u);  // 5 walls, the light, 6 box faces
  EXPECT_EQ(s.spheres.size(), 1u);
  EXPECT_EQ(s.camera.width, 600);
  EXPECT_EQ(s.camera.height, 600);
  EXPECT_FLOAT_EQ(s.camera.vfov_degrees, 40.0f);
  EXPECT_EQ(s.max_depth, 50);

  ASSERT_EQ(s.targets.size(), 2u);
  const Target& light = s.targets[0];
  const Target& glass = s.targets[1];
  ASSERT_EQ(light.kind, Target::Kind::Quad);
  ASSERT_EQ(glass.kind, Target::Kind::Sphere);
  ASSERT_LT(light.index, s.quads.size());
  ASSERT_LT(glass.index, s.spheres.size());
  EXPECT_EQ(s.materials[s.quads[light.index].material].type, MaterialType::DiffuseLight);
  EXPECT_EQ(s.materials[s.quads[light.index].material].emit, Vec3(15.0f));
  const Sphere& sphere = s.spheres[glass.index];
  EXPECT_EQ(s.materials[sphere.material].type, MaterialType::Dielectric);
  EXPECT_FLOAT_EQ(s.materials[sphere.material].ior, 1.5f);
  EXPECT_EQ(sphere.center, Vec3(190.0f, 90.0f, 190.0f));
  EXPECT_FLOAT_EQ(sphere.radius, 90.0f);
}

TEST(SceneLoader, BookLightFacesDown) {
  const Scene s = load_scene_file(kBookScene);
  const Quad& light = s.quads[s.targets[0].index];
  EXPECT_EQ(light.q, Vec3(213.0f, 554.0f, 227.0f));
  // (130,0,0) x (0,0,105) = (0, -13650, 0): the front face looks at the floor.
  EXPECT_NEAR(light.normal.x, 0.0f, 1e-6f);
  EXPECT_NEAR(light.normal.y, -1.0f, 1e-6f);
  EXPECT_NEAR(light.normal.z, 0.0f, 1e-6f);
  EXPECT_NEAR(light.area, 130.0f * 105.0f, 1e-2f);
  const Vec3 uxv = cross(light.u, light.v);
  EXPECT_GT(dot(uxv, light.normal), 0.0f);
}

TEST(SceneLoader, BookBoxIsRotatedThenTranslated) {
  const Scene s = load_scene_file(kBookScene);
  // The box is the only object after the light: quads 6..11.
  const DVec centre = book_box_transform(82.5, 165.0, 82.5);
  const DVec far_corner = book_box_transform(165.0, 330.0, 165.0);
  const DVec origin_corner = book_box_transform(0.0, 0.0, 0.0);
  bool saw_far = false, saw_origin = false;
  double total_area = 0.0;
  for (std::size_t i = 6; i < 12; ++i) {
    const Quad& f = s.quads[i];
    EXPECT_EQ(s.material_names[f.material], "white");
    total_area += f.area;
    const Vec3 corners[4] = {f.q, f.q + f.u, f.q + f.v, f.q + f.u + f.v};
    for (const Vec3& c : corners) {
      saw_far = saw_far || near(c, far_corner, 1e-3);
      saw_origin = saw_origin || near(c, origin_corner, 1e-3);
    }
    // Outward: the face centre lies on the side of the box centre opposite to
    // where the normal points, at half the box's extent along that normal.
    const Vec3 mid = f.q + 0.5f * (f.u + f.v);
    const double dx = mid.x - centre.x, dy = mid.y - centre.y, dz = mid.z - centre.z;
    const double along = dx * f.normal.x + dy * f.normal.y + dz * f.normal.z;
    EXPECT_GT(along, 80.0) << "face " << i << " normal does not point away from the box centre";
    EXPECT_NEAR(length(f.normal), 1.0f, 1e-5f);
  }
  EXPECT_TRUE(saw_far) << "no face has the corner (165,330,165) rotated 15 deg about y and moved by (265,0,295)";
  EXPECT_TRUE(saw_origin) << "no face has the corner (0,0,0) moved to (265,0,295)";
  EXPECT_NEAR(total_area, 2.0 * (165.0 * 330.0 * 2.0 + 165.0 * 165.0), 1.0);

  // The box's +x face normal is x rotated by +15 degrees about y: (cos 15, 0, -sin 15).
  const double a = 15.0 * std::numbers::pi / 180.0;
  bool saw_rotated_x = false;
  for (std::size_t i = 6; i < 12; ++i) {
    const Vec3& n = s.quads[i].normal;
    saw_rotated_x = saw_rotated_x || (std::fabs(n.x - std::cos(a)) < 1e-5 && std::fabs(n.y) < 1e-6 &&
                                      std::fabs(n.z + std::sin(a)) < 1e-5);
  }
  EXPECT_TRUE(saw_rotated_x);
}

TEST(SceneLoader, ImportanceFlagOverridesTheDefault) {
  json doc = minimal_scene();
  doc["objects"][0]["importance"] = true;
  doc["objects"][1]["importance"] = false;
  const Scene s = load_scene_text(doc.dump(), "scene.json");
  ASSERT_EQ(s.targets.size(), 1u);
  EXPECT_EQ(s.targets[0].kind, Target::Kind::Sphere);
  EXPECT_EQ(s.targets[0].index, 0u);
}

TEST(SceneLoader, MissingFileNamesThePath) {
  try {
    (void)load_scene_file("/nonexistent-folder/scene.json");
    FAIL() << "loading a missing file succeeded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/scene.json"), std::string::npos) << e.what();
  }
}

// ---- The environment key -------------------------------------------------------

double lum(const Vec3& c) { return luminance(c.x, c.y, c.z); }

// The shipped sky: its path relative to the scene's folder, scale and
// rotation applied, and the map's texels in the content hash (a reference
// depends on them, not on the file's name).
TEST(SceneLoader, EnvironmentLoadsTheShippedSky) {
  const std::string dir = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes";
  const Scene scene = load_scene_file(dir + "/sun_sky.json");
  ASSERT_TRUE(scene.environment);
  const Environment& map = *scene.environment;
  EXPECT_EQ(map.width(), 256);
  EXPECT_EQ(map.height(), 128);
  EXPECT_FLOAT_EQ(map.scale(), 0.35f);
  EXPECT_TRUE(map.sampleable());
  // The zenith is blue, the ground below the horizon dark, the sun far brighter than both.
  const Vec3 zenith = map.radiance(Vec3(0.0f, 1.0f, 0.0f)), ground = map.radiance(Vec3(0.0f, -1.0f, 0.0f));
  EXPECT_GT(zenith.z, zenith.x);
  EXPECT_LT(lum(ground), lum(zenith));
  const double el = 35.0 * std::numbers::pi / 180.0, az = 60.0 * std::numbers::pi / 180.0;
  const Vec3 sun(static_cast<float>(std::cos(el) * std::cos(az)), static_cast<float>(std::sin(el)),
                 static_cast<float>(std::cos(el) * std::sin(az)));
  EXPECT_GT(lum(map.radiance(sun)), 100.0 * lum(zenith));

  std::ifstream in(dir + "/sun_sky.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(load_scene_text(text, "copy.json", dir).content_hash, scene.content_hash);
  const std::string brighter = replaced(text, "\"scale\": 0.35", "\"scale\": 0.5");
  ASSERT_NE(brighter, text);
  EXPECT_NE(load_scene_text(brighter, "copy.json", dir).content_hash, scene.content_hash);
  // Turned by 90 degrees: what was seen at phi is seen at phi + 90.
  const std::string turned = replaced(text, "\"rotation\": 0", "\"rotation\": 90");
  const Scene t = load_scene_text(turned, "copy.json", dir);
  const Vec3 sun_turned(-sun.z, sun.y, sun.x);
  EXPECT_EQ(lum(t.environment->radiance(sun_turned)), lum(map.radiance(sun)));
}

// A map with a negative or non-finite texel is refused with the texel's place.
TEST(SceneLoader, EnvironmentRefusesABadTexel) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "pdflab_env_texel";
  std::filesystem::create_directories(dir);
  std::vector<float> rgb(8 * 4 * 3, 1.0f);
  rgb[(2 * 8 + 5) * 3 + 1] = -1.0f;
  write_image((dir / "bad.pfm").string(), rgb, 8, 4);
  json doc = minimal_scene();
  doc["environment"] = {{"file", "bad.pfm"}};
  try {
    (void)load_scene_text(doc.dump(), "scene.json", dir.string());
    ADD_FAILURE() << "a negative texel was accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("environment.file:"), std::string::npos) << message;
    EXPECT_NE(message.find("texel (5, 2) is negative or not finite"), std::string::npos) << message;
  }
  std::filesystem::remove_all(dir);
}

// ---- Validation errors name the JSON path ------------------------------------

TEST(SceneValidation, UnknownKeys) {
  json doc = minimal_scene();
  doc["colour"] = 1;
  expect_error_mentions(doc, {"top level", "'colour'"});

  doc = minimal_scene();
  doc["camera"]["fov"] = 40;
  expect_error_mentions(doc, {"camera:", "'fov'"});

  doc = minimal_scene();
  doc["materials"]["white"]["fuzz"] = 0.1;  // fuzz belongs to metal only
  expect_error_mentions(doc, {"materials.white:", "'fuzz'"});

  doc = minimal_scene();
  doc["objects"][1]["radius"] = 3;  // a quad has no radius
  expect_error_mentions(doc, {"objects[1]:", "'radius'"});
}

TEST(SceneValidation, MissingKeys) {
  json doc = minimal_scene();
  doc["camera"].erase("width");
  expect_error_mentions(doc, {"camera:", "missing key 'width'"});

  doc = minimal_scene();
  doc["objects"][0].erase("radius");
  expect_error_mentions(doc, {"objects[0]:", "missing key 'radius'"});

  doc = minimal_scene();
  doc["materials"]["lamp"].erase("emit");
  expect_error_mentions(doc, {"materials.lamp:", "missing key 'emit'"});

  doc = minimal_scene();
  doc.erase("objects");
  expect_error_mentions(doc, {"missing key 'objects'"});
}

TEST(SceneValidation, WrongTypes) {
  json doc = minimal_scene();
  doc["camera"]["width"] = "600";
  expect_error_mentions(doc, {"camera.width:", "expected an integer"});

  doc = minimal_scene();
  doc["camera"]["width"] = 600.5;
  expect_error_mentions(doc, {"camera.width:", "expected an integer"});

  doc = minimal_scene();
  doc["objects"][0]["radius"] = "1";
  expect_error_mentions(doc, {"objects[0].radius:", "expected a number"});

  doc = minimal_scene();
  doc["objects"][0]["center"] = json::array({1, 2});
  expect_error_mentions(doc, {"objects[0].center:", "3 numbers"});

  doc = minimal_scene();
  doc["objects"][0]["center"] = json::array({1, "2", 3});
  expect_error_mentions(doc, {"objects[0].center[1]:", "expected a number"});

  doc = minimal_scene();
  doc["materials"]["white"]["albedo"] = "red";
  expect_error_mentions(doc, {"materials.white.albedo:"});

  doc = minimal_scene();
  doc["objects"][0]["importance"] = 1;
  expect_error_mentions(doc, {"objects[0].importance:", "true or false"});

  doc = minimal_scene();
  doc["objects"] = json::object();
  expect_error_mentions(doc, {"objects:", "expected an array"});

  doc = minimal_scene();
  doc["camera"] = json::array();
  expect_error_mentions(doc, {"camera:", "expected an object"});
}

TEST(SceneValidation, TooLargeFiniteNumbers) {
  // Finite in double but not in float (the renderer's type): must not turn into inf silently.
  json doc = minimal_scene();
  doc["objects"][0]["radius"] = 1e300;
  expect_error_mentions(doc, {"objects[0].radius:"});

  doc = minimal_scene();
  doc["objects"][0]["center"] = json::array({0, -4e38, 0});
  expect_error_mentions(doc, {"objects[0].center[1]:"});
}

TEST(SceneValidation, OverflowingExponentIsAnInputError) {
  // JSON has no NaN/Infinity literal; the way to smuggle one in is an exponent
  // past double's range. nlohmann/json refuses it while parsing (out_of_range
  // 406), so it must reach the user as an InputError with a location, like any
  // other syntax-level problem, not as a stray library exception.
  std::string text = minimal_scene().dump(2);
  const std::string needle = "\"radius\": 1";
  const auto at = text.find(needle);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, needle.size(), "\"radius\": 1e999");
  const std::string message = load_error(text);
  EXPECT_NE(message.find("line "), std::string::npos) << message;
  EXPECT_NE(message.find("1e999"), std::string::npos) << message;

  text.replace(text.find("1e999"), 5, "-1e999");
  (void)load_error(text);
}

TEST(SceneValidation, UnknownMaterialName) {
  json doc = minimal_scene();
  doc["objects"][1]["material"] = "lava";
  expect_error_mentions(doc, {"objects[1].material:", "'lava'"});

  doc = minimal_scene();
  doc["materials"]["white"]["type"] = "plastic";
  expect_error_mentions(doc, {"materials.white.type:", "'plastic'"});

  doc = minimal_scene();
  doc["objects"][0]["type"] = "cylinder";
  expect_error_mentions(doc, {"objects[0].type:", "'cylinder'"});
}

TEST(SceneValidation, DegenerateQuads) {
  json doc = minimal_scene();
  doc["objects"][1]["v"] = json::array({4, 0, 0});  // parallel to u
  expect_error_mentions(doc, {"objects[1]", "degenerate"});

  doc = minimal_scene();
  doc["objects"][1]["u"] = json::array({0, 0, 0});
  expect_error_mentions(doc, {"objects[1]", "degenerate"});

  doc = minimal_scene();
  doc["objects"][1]["v"] = json::array({-2, 0, 0});  // antiparallel
  expect_error_mentions(doc, {"objects[1]", "degenerate"});
}

TEST(SceneValidation, QuadMessagesGiveTheTrueReason) {
  json doc = minimal_scene();
  doc["objects"][1]["v"] = json::array({4, 0, 0});
  expect_error_mentions(doc, {"objects[1]:", "u and v are parallel"});
  doc = minimal_scene();
  doc["objects"][1]["u"] = json::array({0, 0, 0});
  expect_error_mentions(doc, {"objects[1]:", "u is zero"});
  doc = minimal_scene();
  doc["objects"][1]["v"] = json::array({0, 0, 0});
  expect_error_mentions(doc, {"objects[1]:", "v is zero"});
  // Edges of 1e20: the area 1e40 cannot be held in float.
  doc = minimal_scene();
  doc["objects"][1]["u"] = json::array({1e20, 0, 0});
  doc["objects"][1]["v"] = json::array({0, 0, 1e20});
  expect_error_mentions(doc, {"objects[1]:", "area", "does not fit in single precision"});
  // Edges of 1e-20: the area 1e-40 is below float's normal range.
  doc = minimal_scene();
  doc["objects"][1]["u"] = json::array({1e-20, 0, 0});
  doc["objects"][1]["v"] = json::array({0, 0, 1e-20});
  expect_error_mentions(doc, {"objects[1]:", "area", "too small for single precision"});
  // A box face is a quad too.
  doc = minimal_scene();
  doc["objects"][1] = json{{"type", "box"}, {"min", {0, 0, 0}}, {"max", {1e20, 1e20, 1}}, {"material", "white"}};
  expect_error_mentions(doc, {"objects[1]:", "does not fit in single precision"});
}

TEST(SceneGeometry, QuadSetUpIsFiniteAndExactFromTinyToHugeEdges) {
  // In float |u x v|^2 overflows near edges of 4e9; the set-up is done in double.
  for (const double edge : {1e-12, 1e-6, 1.0, 1e6, 4e9, 1e12, 1e18}) {
    const float e = static_cast<float>(edge);
    const Vec3 u(e, 0, 0), v(0.6f * e, 0.8f * e, 0);  // 53 degrees apart
    ASSERT_EQ(quad_problem(u, v), "") << edge;
    const Quad q = make_quad(Vec3(2 * e, -e, 3 * e), u, v, 0);
    EXPECT_NEAR(q.area / (0.8 * edge * edge), 1.0, 1e-6) << edge;
    EXPECT_NEAR(length(q.normal), 1.0f, 1e-6f) << edge;
    EXPECT_NEAR(q.normal.z, 1.0f, 1e-6f) << edge;
    EXPECT_NEAR(q.plane_d / (3 * edge), 1.0, 1e-6) << edge;
    // The plane axes map the far corner to (1, 1).
    const Vec3 rel = u + v;
    EXPECT_NEAR(dot(rel, q.alpha_axis), 1.0f, 1e-5f) << edge;
    EXPECT_NEAR(dot(rel, q.beta_axis), 1.0f, 1e-5f) << edge;
    // And a ray down the middle hits it at the right distance.
    const Vec3 centre = Vec3(2 * e, -e, 3 * e) + rel * 0.5f;
    const float t = quad_hit_distance(q, centre + Vec3(0, 0, 2 * e), Vec3(0, 0, -1));
    EXPECT_NEAR(t / (2 * edge), 1.0, 1e-5) << edge;
  }
}

TEST(SceneValidation, NonPositiveRadius) {
  for (double r : {0.0, -1.0, -0.0}) {
    json doc = minimal_scene();
    doc["objects"][0]["radius"] = r;
    expect_error_mentions(doc, {"objects[0].radius:", "> 0"});
  }
}

TEST(SceneValidation, ImageSizeRange) {
  for (int w : {0, -1, 16385}) {
    json doc = minimal_scene();
    doc["camera"]["width"] = w;
    expect_error_mentions(doc, {"camera.width:", "1..16384"});
    doc = minimal_scene();
    doc["camera"]["height"] = w;
    expect_error_mentions(doc, {"camera.height:", "1..16384"});
  }
  // The limits themselves are valid: 1, 16384 per side, and exactly the pixel budget.
  for (const auto& [w, h] : {std::pair{1, 1}, std::pair{16384, 1}, std::pair{1, 16384}, std::pair{16384, 1024},
                             std::pair{4096, 4096}}) {
    json doc = minimal_scene();
    doc["camera"]["width"] = w;
    doc["camera"]["height"] = h;
    EXPECT_NO_THROW((void)load_scene_text(doc.dump(), "scene.json")) << w << "x" << h;
  }
}

TEST(SceneValidation, PixelBudgetIsEnforcedBeforeAllocation) {
  // Both sides in range, but 16384 x 16384 would need 13 GiB of film.
  for (const auto& [w, h] : {std::pair{16384, 16384}, std::pair{4097, 4096}, std::pair{16384, 1025}}) {
    json doc = minimal_scene();
    doc["camera"]["width"] = w;
    doc["camera"]["height"] = h;
    expect_error_mentions(doc, {"camera:", "more than the limit of 16777216", "GiB"});
    const std::string size = std::to_string(w) + "x" + std::to_string(h);
    EXPECT_NE(load_error(doc.dump()).find(size), std::string::npos) << size;
  }
}

TEST(SceneValidation, HugeIntegerWidthIsRejected) {
  // Larger than long long: must still be "out of range", never wrap into range.
  json doc = minimal_scene();
  doc["camera"]["width"] = 18446744073709551615ULL;
  expect_error_mentions(doc, {"camera.width:"});
}

TEST(SceneValidation, FieldOfView) {
  for (double v : {0.0, 180.0, -10.0, 270.0}) {
    json doc = minimal_scene();
    doc["camera"]["vfov"] = v;
    expect_error_mentions(doc, {"camera.vfov:"});
  }
  json doc = minimal_scene();
  doc["camera"]["vfov"] = 179.5;
  EXPECT_NO_THROW((void)load_scene_text(doc.dump(), "scene.json"));
}

TEST(SceneValidation, UpVectorParallelToView) {
  // View direction is +z (lookfrom z=-10 towards the origin).
  for (const auto& vup : {json::array({0, 0, 1}), json::array({0, 0, -3}), json::array({0, 0, 0})}) {
    json doc = minimal_scene();
    doc["camera"]["vup"] = vup;
    expect_error_mentions(doc, {"camera", "vup"});
  }
  json doc = minimal_scene();
  doc["camera"]["lookat"] = doc["camera"]["lookfrom"];
  expect_error_mentions(doc, {"camera", "lookfrom"});
}

// Issue 33, item 13: a camera far from its target squares its distance past
// float's range; it is looking along +z, not along vup, and is loaded with a
// finite camera (the check and the camera's basis normalise by the largest
// component first). A vup that is tiny, or huge, is a direction too.
TEST(SceneValidation, AFarCameraIsNotCalledParallelToVup) {
  for (const double far : {1.8e19, 1e25, 1e30}) {
    json doc = minimal_scene();
    doc["camera"]["lookfrom"] = json::array({0, 0, -far});
    Scene scene;
    ASSERT_NO_THROW(scene = load_scene_text(doc.dump(), "scene.json")) << far;
    const Camera& c = scene.camera;
    for (const Vec3& v : {c.pixel00, c.du, c.dv})
      EXPECT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) << far;
    EXPECT_GT(c.pixel00.z, 0.0f) << "a camera at -z looks along +z: " << far;
  }
  for (const double up : {1e-30, 1e30}) {
    json doc = minimal_scene();
    doc["camera"]["vup"] = json::array({0, up, 0});
    EXPECT_NO_THROW((void)load_scene_text(doc.dump(), "scene.json")) << up;
  }
  // Still refused when it is parallel, near or far.
  json doc = minimal_scene();
  doc["camera"]["lookfrom"] = json::array({0, 0, -1e25});
  doc["camera"]["vup"] = json::array({0, 0, 1e-30});
  expect_error_mentions(doc, {"camera", "vup is zero or parallel"});
  // The bits of an ordinary camera are normalize()'s, as before.
  EXPECT_EQ(unit_direction(Vec3(0.3f, -2.0f, 5.0f)), normalize(Vec3(0.3f, -2.0f, 5.0f)));
}

// Issue 33, item 13: JSON lets a key appear twice and the parser kept the last
// value: two "objects" arrays lost the first without a word. Refused, with
// the key's path, at any depth.
TEST(SceneValidation, DuplicateKeysAreRefusedWithTheirPath) {
  const std::string objects = R"([{ "type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white" },
      { "type": "quad", "q": [-1, 3, -1], "u": [2, 0, 0], "v": [0, 0, 2], "material": "lamp" }])";
  const std::string head = R"({"camera": { "width": 8, "height": 6, "vfov": 40, "lookfrom": [0, 0, -10], "lookat": [0, 0, 0] },
    "materials": { "white": { "type": "lambertian", "albedo": [0.5, 0.5, 0.5] },
                   "lamp": { "type": "diffuse_light", "emit": [4, 4, 4] } },)";
  EXPECT_NO_THROW((void)load_scene_text(head + R"("objects": )" + objects + "}", "scene.json"));
  const struct {
    std::string text, needle;
  } cases[] = {
      {head + R"("objects": )" + objects + R"(, "objects": [])", "scene.json: objects: the key appears twice"},
      {R"({"camera": { "width": 8, "height": 6, "vfov": 40, "vfov": 50, "lookfrom": [0, 0, -10], "lookat": [0, 0, 0] }})",
       "scene.json: camera.vfov: the key appears twice"},
      {R"({"materials": { "white": { "type": "lambertian", "albedo": [1, 1, 1], "albedo": [0, 0, 0] } }})",
       "scene.json: materials.white.albedo: the key appears twice"},
      {R"({"objects": [ {"type": "sphere"}, {"type": "sphere", "radius": 1, "radius": 2} ]})",
       "scene.json: objects[1].radius: the key appears twice"},
      {R"({"a": [[1, 2], {"b": {"c": 1, "c": 2}}]})", "scene.json: a[1].b.c: the key appears twice"},
  };
  for (const auto& c : cases) {
    const std::string message = load_error(c.text + (c.text.back() == '}' ? "" : "}"));
    EXPECT_NE(message.find(c.needle), std::string::npos) << message;
  }
}

// `fastest_uses_guiding`: false unless the scene says true; anything but a
// boolean is refused by name.
TEST(SceneLoader, FastestUsesGuidingIsABoolean) {
  EXPECT_FALSE(load_scene_text(minimal_scene().dump(), "scene.json").fastest_uses_guiding);
  json doc = minimal_scene();
  doc["fastest_uses_guiding"] = true;
  EXPECT_TRUE(load_scene_text(doc.dump(), "scene.json").fastest_uses_guiding);
  doc["fastest_uses_guiding"] = "yes";
  expect_error_mentions(doc, {"fastest_uses_guiding"});
}

// Issue 33, item 13: a NUL in a key no longer cuts the message short (it was
// a C string once made into the exception); it shows as \x00 with the rest.
TEST(SceneValidation, ANulInAKeyIsShownNotCut) {
  const std::string message = load_error(R"({"cam\u0000era": 1, "camera": {}})");
  EXPECT_NE(message.find("unknown key 'cam\\x00era' (allowed: camera, description, environment, fastest_uses_guiding, "
                         "light_choice, materials, name, objects)"),
            std::string::npos)
      << message;
}

TEST(SceneValidation, BoxExtentsAndMaterialRanges) {
  json doc = minimal_scene();
  doc["objects"][0] = json::parse(R"({"type": "box", "min": [0,0,0], "max": [1,0,1], "material": "white"})");
  expect_error_mentions(doc, {"objects[0]", "max"});

  doc = minimal_scene();
  doc["materials"]["white"]["albedo"] = json::array({0.5, -0.1, 0.5});
  expect_error_mentions(doc, {"materials.white.albedo:", ">= 0"});

  doc = minimal_scene();
  doc["materials"]["alu"] = json::parse(R"({"type": "metal", "albedo": [1,1,1], "fuzz": 1.5})");
  expect_error_mentions(doc, {"materials.alu.fuzz:"});
}

// ---- Syntax errors report line and column ------------------------------------

TEST(SceneSyntax, LineAndColumnMidLine) {
  // The second comma on line 3 is column 16: 4 spaces, "width": (8), a space, 8, comma.
  const std::string text = "{\n  \"camera\": {\n    \"width\": 8,,\n  }\n}\n";
  const std::string message = load_error(text);
  EXPECT_NE(message.find("line 3, column 16"), std::string::npos) << message;
  EXPECT_NE(message.find("syntax"), std::string::npos) << message;
}

TEST(SceneSyntax, LineAndColumnAtStartOfLine) {
  const std::string text = "{\n\"camera\":\n]\n";
  const std::string message = load_error(text);
  EXPECT_NE(message.find("line 3, column 1"), std::string::npos) << message;
}

TEST(SceneSyntax, TruncatedFile) {
  std::string text = minimal_scene().dump(2);
  text.resize(text.size() / 2);
  const std::string message = load_error(text);
  EXPECT_NE(message.find("line "), std::string::npos) << message;
}

TEST(SceneSyntax, NotAnObject) {
  const std::string message = load_error("[1, 2, 3]");
  EXPECT_NE(message.find("top level"), std::string::npos) << message;
}

// ---- The microfacet conductor -------------------------------------------------

json with_microfacet(const json& material) {
  json doc = minimal_scene();
  doc["materials"]["rough"] = material;
  doc["objects"][0]["material"] = "rough";
  return doc;
}

TEST(SceneLoader, MicrofacetLoads) {
  const json doc = with_microfacet(json::parse(
      R"({"type": "microfacet", "alpha": 0.2, "eta": [1.657, 0.88, 0.521], "k": [9.224, 6.27, 4.837]})"));
  const Scene s = load_scene_text(doc.dump(), "scene.json");
  const Material& m = s.materials[s.spheres[0].material];
  EXPECT_EQ(m.type, MaterialType::Microfacet);
  EXPECT_FLOAT_EQ(m.alpha, 0.2f);
  EXPECT_FLOAT_EQ(m.eta.y, 0.88f);
  EXPECT_FLOAT_EQ(m.k.z, 4.837f);
  // A conductor is no light target and no specular object.
  EXPECT_EQ(s.targets.size(), 1u);
}

TEST(SceneLoader, MicrofacetRefusesBadParameters) {
  const json good = json::parse(R"({"type": "microfacet", "alpha": 0.2, "eta": [1, 1, 1], "k": [3, 3, 3]})");
  for (const double alpha : {0.0, -0.1, 0.0005, 1.5}) {
    json m = good;
    m["alpha"] = alpha;
    expect_error_mentions(with_microfacet(m), {"materials.rough.alpha", "0.001..1"});
  }
  json m = good;
  m["eta"] = {1, 0, 1};
  expect_error_mentions(with_microfacet(m), {"materials.rough.eta", "> 0"});
  m = good;
  m["k"] = {1, -1, 1};
  expect_error_mentions(with_microfacet(m), {"materials.rough.k", ">= 0"});
  for (const char* key : {"alpha", "eta", "k"}) {
    m = good;
    m.erase(key);
    expect_error_mentions(with_microfacet(m), {"missing key", key});
  }
  m = good;
  m["fuzz"] = 0.1;
  expect_error_mentions(with_microfacet(m), {"unknown key 'fuzz'", "alpha, eta, ior, k, type"});
  m = good;
  m["type"] = "microfacets";
  expect_error_mentions(with_microfacet(m), {"unknown material type", "microfacet)"});
}

// ---- The rough dielectric -------------------------------------------------------

TEST(SceneLoader, RoughDielectricLoads) {
  const json doc = with_microfacet(json::parse(R"({"type": "microfacet", "alpha": 0.2, "ior": 1.5})"));
  const Scene s = load_scene_text(doc.dump(), "scene.json");
  const Material& m = s.materials[s.spheres[0].material];
  EXPECT_EQ(m.type, MaterialType::Microfacet);
  EXPECT_TRUE(m.transmits);
  EXPECT_FLOAT_EQ(m.alpha, 0.2f);
  EXPECT_FLOAT_EQ(m.ior, 1.5f);
  // The conductor does not transmit.
  const json conductor =
      with_microfacet(json::parse(R"({"type": "microfacet", "alpha": 0.2, "eta": [1, 1, 1], "k": [3, 3, 3]})"));
  EXPECT_FALSE(load_scene_text(conductor.dump(), "scene.json").materials[s.spheres[0].material].transmits);
  // The shipped frosted glass scene loads, with its sphere frosted.
  const Scene frosted = load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/frosted_glass.json");
  bool found = false;
  for (const Material& fm : frosted.materials) found = found || (fm.type == MaterialType::Microfacet && fm.transmits);
  EXPECT_TRUE(found);
}

TEST(SceneLoader, RoughDielectricRefusesBadCombinations) {
  const json good = json::parse(R"({"type": "microfacet", "alpha": 0.2, "ior": 1.5})");
  // A conductor's index beside a dielectric's: which one is meant is unclear.
  for (const char* key : {"eta", "k"}) {
    json m = good;
    m[key] = {1, 1, 1};
    expect_error_mentions(with_microfacet(m), {"materials.rough.ior", "conductor ('eta' and 'k') or a dielectric ('ior')"});
  }
  for (const double ior : {0.0, -1.5}) {
    json m = good;
    m["ior"] = ior;
    expect_error_mentions(with_microfacet(m), {"materials.rough.ior", "> 0"});
  }
  json m = good;
  m["ior"] = 1.0;
  expect_error_mentions(with_microfacet(m), {"materials.rough.ior", "must not be 1"});
  m = good;
  m.erase("ior");
  expect_error_mentions(with_microfacet(m), {"materials.rough", "needs 'eta' and 'k' (a conductor) or 'ior' (a dielectric)"});
  m = good;
  m["alpha"] = 2.0;
  expect_error_mentions(with_microfacet(m), {"materials.rough.alpha", "0.001..1"});
  m = good;
  m["fresnel"] = "exact";
  expect_error_mentions(with_microfacet(m), {"unknown key 'fresnel'"});
}

}  // namespace
}  // namespace pdflab
