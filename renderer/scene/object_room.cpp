#include "renderer/scene/object_room.h"

#include "renderer/sampling/rng.h"
#include "renderer/scene/scene_loader.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace pdflab {

namespace {

std::string number(float x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(x));
  return buf;
}

std::string vec(const Vec3& v) {
  std::string s = "[";
  for (int c = 0; c < 3; ++c) {
    s += number(v[c]);
    s += c < 2 ? ", " : "]";
  }
  return s;
}

// A uniform direction from two random numbers.
Vec3 random_direction(Rng& rng) {
  const float z = 1.0f - 2.0f * rng.uniform();
  const float r = std::sqrt(positive_part(1.0f - z * z));
  const float phi = 2.0f * kPi * rng.uniform();
  return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace

std::string object_room_text(int objects, std::uint64_t seed) {
  std::string text = "{ \"name\": \"Object room (";
  text += std::to_string(objects);
  text += R"json( objects)",
  "description": "The book's room holding small spheres and quads at random, one in eight emitting (renderer/scene/object_room.h).",
  "camera": { "width": 600, "height": 600, "vfov": 40, "lookfrom": [278, 278, -800], "lookat": [278, 278, 0],
              "vup": [0, 1, 0], "max_depth": 50, "background": [0, 0, 0] },
  "materials": {
    "red": { "type": "lambertian", "albedo": [0.65, 0.05, 0.05] },
    "white": { "type": "lambertian", "albedo": [0.73, 0.73, 0.73] },
    "green": { "type": "lambertian", "albedo": [0.12, 0.45, 0.15] },
    "lamp": { "type": "diffuse_light", "emit": [12, 11, 9], "two_sided": true }
  },
  "objects": [
    { "type": "quad", "q": [555, 0, 0], "u": [0, 0, 555], "v": [0, 555, 0], "material": "green" },
    { "type": "quad", "q": [0, 0, 555], "u": [0, 0, -555], "v": [0, 555, 0], "material": "red" },
    { "type": "quad", "q": [0, 555, 0], "u": [555, 0, 0], "v": [0, 0, 555], "material": "white" },
    { "type": "quad", "q": [0, 0, 555], "u": [555, 0, 0], "v": [0, 0, -555], "material": "white" },
    { "type": "quad", "q": [555, 0, 555], "u": [-555, 0, 0], "v": [0, 555, 0], "material": "white" })json";
  Rng rng(seed, 0x0b1ec7);
  const char* const surfaces[] = {"white", "red", "green", "white"};
  for (int i = 0; i < objects; ++i) {
    Vec3 at;
    for (int c = 0; c < 3; ++c) at[c] = 30.0f + 495.0f * rng.uniform();  // in order: arguments have none
    const char* material = i % 8 == 0 ? "lamp" : surfaces[(i / 8) % 4];
    text += ",\n    { \"type\": ";
    if (i % 2) {
      const float radius = 3.0f + 5.0f * rng.uniform();
      text += "\"sphere\", \"center\": ";
      text += vec(at);
      text += ", \"radius\": ";
      text += number(radius);
    } else {
      // Two edges 6 to 16 long, at an angle between 45 and 90 degrees, facing anywhere.
      const Vec3 a = random_direction(rng);
      Vec3 b = random_direction(rng);
      b = normalize(b - a * dot(a, b));
      const float angle = kPi * (0.25f + 0.25f * rng.uniform());
      const Vec3 u = a * (6.0f + 10.0f * rng.uniform());
      const Vec3 v = (a * std::cos(angle) + b * std::sin(angle)) * (6.0f + 10.0f * rng.uniform());
      text += "\"quad\", \"q\": ";
      text += vec(at - (u + v) * 0.5f);
      text += ", \"u\": ";
      text += vec(u);
      text += ", \"v\": ";
      text += vec(v);
    }
    text += ", \"material\": \"";
    text += material;
    text += "\" }";
  }
  text += "\n  ]\n}\n";
  return text;
}

Scene object_room(int objects, std::uint64_t seed, BvhUse tree) {
  Scene scene = load_scene_text(object_room_text(objects, seed), "object_room");
  scene.bvh_use = tree;
  scene.prepare();
  return scene;
}

}  // namespace pdflab
