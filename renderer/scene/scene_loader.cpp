#include "renderer/scene/scene_loader.h"

#include "renderer/error.h"
#include "renderer/film/film.h"
#include "renderer/hash.h"
#include "renderer/input_file.h"
#include "renderer/scene/environment.h"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <algorithm>
#include <cmath>
#include <limits>
#include <filesystem>
#include <fstream>
#include <map>
#include <functional>
#include <set>
#include <vector>

namespace pdflab {

using json = nlohmann::json;

namespace {

// A scene is a few kilobytes; this bounds what a wrong path (a disk image,
// /dev/zero) can make the loader read into memory.
constexpr std::size_t kMaxSceneBytes = std::size_t{64} << 20;

// A position in double: the scene file's numbers before they are rounded to
// the rendering space's floats.
struct D3 {
  double x, y, z;
};
D3 operator+(const D3& a, const D3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator-(const D3& a, const D3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 d3(const Vec3& v) { return {v.x, v.y, v.z}; }
Vec3 to_float(const D3& a) { return {static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z)}; }
double max_abs(const D3& a) { return std::max(std::fabs(a.x), std::max(std::fabs(a.y), std::fabs(a.z))); }
double norm(const D3& a) { return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z); }

// A JSON value with the path that leads to it, for error messages.
class Node {
 public:
  Node(const json& value, std::string path, const std::string& origin) : v_(value), path_(std::move(path)), origin_(origin) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(origin_ + ": " + (path_.empty() ? std::string("top level") : path_) + ": " + what);
  }

  const json& value() const { return v_; }
  const std::string& path() const { return path_; }

  Node child(const std::string& key) const {
    return Node(v_.at(key), path_.empty() ? key : path_ + "." + key, origin_);
  }
  Node element(std::size_t i) const { return Node(v_.at(i), path_ + "[" + std::to_string(i) + "]", origin_); }
  bool has(const std::string& key) const { return v_.contains(key); }

  void expect_object() const {
    if (!v_.is_object()) fail("expected an object, found " + std::string(v_.type_name()));
  }
  void expect_array() const {
    if (!v_.is_array()) fail("expected an array, found " + std::string(v_.type_name()));
  }
  Node require(const std::string& key) const {
    if (!has(key)) fail("missing key '" + key + "'");
    return child(key);
  }
  void allow_only(const std::set<std::string>& keys) const {
    for (auto it = v_.begin(); it != v_.end(); ++it)
      if (!keys.count(it.key())) {
        std::string list;
        for (const auto& k : keys) list += (list.empty() ? "" : ", ") + k;
        fail("unknown key '" + it.key() + "' (allowed: " + list + ")");
      }
  }

  double number() const {
    if (!v_.is_number()) fail("expected a number, found " + std::string(v_.type_name()));
    const double d = v_.get<double>();
    if (!std::isfinite(d)) fail("must be a finite number");
    if (std::fabs(d) > 1e30) fail("magnitude is too large for single precision");
    return d;
  }
  float real() const { return static_cast<float>(number()); }
  int integer(int lo, int hi) const {
    if (!v_.is_number_integer()) fail("expected an integer, found " + std::string(v_.type_name()));
    const auto i = v_.get<long long>();
    if (i < lo || i > hi) fail("must be in " + std::to_string(lo) + ".." + std::to_string(hi) + ", found " + std::to_string(i));
    return static_cast<int>(i);
  }
  bool boolean() const {
    if (!v_.is_boolean()) fail("expected true or false, found " + std::string(v_.type_name()));
    return v_.get<bool>();
  }
  std::string string() const {
    if (!v_.is_string()) fail("expected a string, found " + std::string(v_.type_name()));
    return v_.get<std::string>();
  }
  // The numbers as written (in double), for positions that the rendering
  // space may move (Scene::origin) before they are rounded to float.
  D3 dvec3() const {
    if (!v_.is_array() || v_.size() != 3) fail("expected an array of 3 numbers");
    return {element(0).number(), element(1).number(), element(2).number()};
  }
  Vec3 vec3() const { return to_float(dvec3()); }

 private:
  const json& v_;
  std::string path_;
  const std::string& origin_;
};

Vec3 nonnegative_colour(const Node& n) {
  const Vec3 c = n.vec3();
  if (c.x < 0.0f || c.y < 0.0f || c.z < 0.0f) n.fail("colour components must be >= 0");
  return c;
}

// The objects as the file places them, before the rendering space is chosen:
// each quad's corner (a box's faces too) and each sphere's centre in double,
// and as the book computes them in float, which a scene whose rendering space
// stays at the file's origin keeps (the same bits as ever).
struct Placement {
  struct QuadRow {
    D3 corner;
    Vec3 corner_float;
    Vec3 u, v;              // as the book computes them (a box's from its float corners)
    Vec3 u_exact, v_exact;  // from the file's numbers in double, rounded once (a quad's: u and v)
    std::uint32_t material;
  };
  struct SphereRow {
    D3 center;
    float radius;
    std::uint32_t material;
  };
  struct BoxRow {
    std::size_t first_face;  // its six faces in `quads`, from here
    float smallest_side;
    std::size_t object;  // its index in the file's objects, for the refusal's message
  };
  D3 lookfrom{}, lookat{};
  std::vector<QuadRow> quads;
  std::vector<SphereRow> spheres;
  std::vector<BoxRow> boxes;
};

void parse_camera(const Node& node, Scene& scene, Placement& placement) {
  node.expect_object();
  node.allow_only({"width", "height", "vfov", "lookfrom", "lookat", "vup", "max_depth", "background"});
  Camera& cam = scene.camera;
  cam.width = node.require("width").integer(1, kMaxImageSide);
  cam.height = node.require("height").integer(1, kMaxImageSide);
  if (const std::string problem = image_size_problem(cam.width, cam.height); !problem.empty()) node.fail(problem);
  const Node vfov = node.require("vfov");
  cam.vfov_degrees = vfov.real();
  if (!(cam.vfov_degrees > 0.0f && cam.vfov_degrees < 180.0f)) vfov.fail("must be between 0 and 180 degrees (exclusive)");
  // Placed in the rendering space with the objects (place_in_rendering_space).
  placement.lookfrom = node.require("lookfrom").dvec3();
  placement.lookat = node.require("lookat").dvec3();
  cam.vup = node.has("vup") ? node.child("vup").vec3() : Vec3(0.0f, 1.0f, 0.0f);
  const D3 view = placement.lookat - placement.lookfrom;
  if (view.x == 0.0 && view.y == 0.0 && view.z == 0.0) node.fail("lookfrom and lookat are the same point");
  scene.max_depth = node.has("max_depth") ? node.child("max_depth").integer(1, 10000) : 50;
  scene.background = node.has("background") ? nonnegative_colour(node.child("background")) : Vec3(0.0f);
}

Material parse_material(const Node& node) {
  node.expect_object();
  const Node type_node = node.require("type");
  const std::string type = type_node.string();
  Material m;
  if (type == "lambertian") {
    node.allow_only({"type", "albedo"});
    m.type = MaterialType::Lambertian;
    m.albedo = nonnegative_colour(node.require("albedo"));
  } else if (type == "metal") {
    node.allow_only({"type", "albedo", "fuzz"});
    m.type = MaterialType::Metal;
    m.albedo = nonnegative_colour(node.require("albedo"));
    if (node.has("fuzz")) {
      const Node f = node.child("fuzz");
      m.fuzz = f.real();
      if (!(m.fuzz >= 0.0f && m.fuzz <= 1.0f)) f.fail("must be in 0..1");
    }
  } else if (type == "dielectric") {
    node.allow_only({"type", "ior", "fresnel"});
    m.type = MaterialType::Dielectric;
    const Node ior = node.require("ior");
    m.ior = ior.real();
    if (!(m.ior > 0.0f)) ior.fail("must be > 0");
    if (node.has("fresnel")) {
      const Node f = node.child("fresnel");
      const std::string fresnel = f.string();
      if (fresnel == "exact") m.exact_fresnel = true;
      else if (fresnel != "schlick") f.fail("unknown Fresnel term '" + fresnel + "' (schlick, exact)");
    }
  } else if (type == "diffuse_light") {
    node.allow_only({"type", "emit", "two_sided"});
    m.type = MaterialType::DiffuseLight;
    m.emit = nonnegative_colour(node.require("emit"));
    m.two_sided = node.has("two_sided") && node.child("two_sided").boolean();
  } else if (type == "microfacet") {
    node.allow_only({"type", "alpha", "eta", "k", "ior"});
    m.type = MaterialType::Microfacet;
    const Node alpha = node.require("alpha");
    m.alpha = alpha.real();
    if (!(m.alpha >= kMinMicrofacetAlpha && m.alpha <= 1.0f)) alpha.fail("must be in 0.001..1 (the GGX roughness)");
    if (node.has("ior")) {
      // A rough dielectric: its index is all it has (no eta + i k).
      const Node ior = node.child("ior");
      if (node.has("eta") || node.has("k"))
        ior.fail("a microfacet material is a conductor ('eta' and 'k') or a dielectric ('ior'), not both");
      m.transmits = true;
      m.ior = ior.real();
      if (!(m.ior > 0.0f) || !std::isfinite(m.ior)) ior.fail("must be > 0 (the dielectric's index of refraction)");
      if (m.ior == 1.0f)
        ior.fail("must not be 1: a dielectric of the outside's index neither reflects nor bends light (its "
                 "transmission is a delta, which has no density)");
    } else {
      if (!node.has("eta") && !node.has("k"))
        node.fail("a microfacet material needs 'eta' and 'k' (a conductor) or 'ior' (a dielectric)");
      const Node eta = node.require("eta");
      m.eta = eta.vec3();
      if (!(m.eta.x > 0.0f && m.eta.y > 0.0f && m.eta.z > 0.0f))
        eta.fail("components must be > 0 (the real part of the conductor's index of refraction)");
      const Node k = node.require("k");
      m.k = k.vec3();
      if (!(m.k.x >= 0.0f && m.k.y >= 0.0f && m.k.z >= 0.0f))
        k.fail("components must be >= 0 (the imaginary part of the conductor's index of refraction)");
    }
  } else {
    type_node.fail("unknown material type '" + type + "' (lambertian, metal, dielectric, diffuse_light, microfacet)");
  }
  return m;
}

// rotate_y as in the book: x' = cos x + sin z, z' = -sin x + cos z.
Vec3 rotate_y(const Vec3& p, float cos_t, float sin_t) {
  return {cos_t * p.x + sin_t * p.z, p.y, -sin_t * p.x + cos_t * p.z};
}

void check_quad(const Node& node, const Vec3& u, const Vec3& v) {
  if (const std::string problem = quad_problem(u, v); !problem.empty()) node.fail(problem);
}

void parse_object(const Node& node, std::size_t index, const std::map<std::string, std::uint32_t>& materials,
                  Scene& scene, Placement& placement) {
  node.expect_object();
  const Node type_node = node.require("type");
  const std::string type = type_node.string();
  const Node mat_node = node.require("material");
  const std::string mat_name = mat_node.string();
  const auto mat_it = materials.find(mat_name);
  if (mat_it == materials.end()) mat_node.fail("unknown material '" + mat_name + "'");
  const std::uint32_t mat = mat_it->second;
  const bool emitter = scene.materials[mat].type == MaterialType::DiffuseLight;
  const bool importance = node.has("importance") ? node.child("importance").boolean() : emitter;

  if (type == "quad") {
    node.allow_only({"type", "q", "u", "v", "material", "importance"});
    const D3 q = node.require("q").dvec3();
    const Vec3 u = node.require("u").vec3(), v = node.require("v").vec3();
    check_quad(node, u, v);
    if (importance) scene.targets.push_back({Target::Kind::Quad, static_cast<std::uint32_t>(placement.quads.size())});
    placement.quads.push_back({q, to_float(q), u, v, u, v, mat});
  } else if (type == "sphere") {
    node.allow_only({"type", "center", "radius", "material", "importance"});
    const D3 c = node.require("center").dvec3();
    const Node r = node.require("radius");
    const float radius = r.real();
    if (!(radius > 0.0f)) r.fail("must be > 0");
    if (importance) scene.targets.push_back({Target::Kind::Sphere, static_cast<std::uint32_t>(placement.spheres.size())});
    placement.spheres.push_back({c, radius, mat});
  } else if (type == "box") {
    node.allow_only({"type", "min", "max", "rotate_y", "translate", "material", "importance"});
    const D3 lo_d = node.require("min").dvec3(), hi_d = node.require("max").dvec3();
    const Vec3 lo = to_float(lo_d), hi = to_float(hi_d);
    if (!(hi_d.x > lo_d.x && hi_d.y > lo_d.y && hi_d.z > lo_d.z))
      node.fail("box 'max' must exceed 'min' on every axis");
    const double degrees = node.has("rotate_y") ? node.child("rotate_y").number() : 0.0;
    const float angle = static_cast<float>(degrees) * (kPi / 180.0f);
    const D3 offset_d = node.has("translate") ? node.child("translate").dvec3() : D3{0.0, 0.0, 0.0};
    const Vec3 offset = to_float(offset_d);
    const float c = std::cos(angle), s = std::sin(angle);
    // The corners again in double, for a rendering space away from the file's origin.
    const double cd = std::cos(degrees * (3.14159265358979323846 / 180.0)),
                 sd = std::sin(degrees * (3.14159265358979323846 / 180.0));
    const auto rotated = [&](const D3& p) { return D3{cd * p.x + sd * p.z, p.y, -sd * p.x + cd * p.z} + offset_d; };
    const D3 corners_d[6] = {{lo_d.x, lo_d.y, hi_d.z}, {hi_d.x, lo_d.y, hi_d.z}, {hi_d.x, lo_d.y, lo_d.z},
                             {lo_d.x, lo_d.y, lo_d.z}, {lo_d.x, hi_d.y, hi_d.z}, {lo_d.x, lo_d.y, lo_d.z}};
    const Vec3 dx(hi.x - lo.x, 0, 0), dy(0, hi.y - lo.y, 0), dz(0, 0, hi.z - lo.z);
    // The sides in double: float's corners far from the origin round them to
    // its steps there (a box 1e-3 across at 1e3 had sides 6% off).
    const D3 side = hi_d - lo_d;
    const Vec3 ex(static_cast<float>(side.x), 0, 0), ey(0, static_cast<float>(side.y), 0),
        ez(0, 0, static_cast<float>(side.z));
    const Vec3 edges[6][2] = {{ex, ey}, {-ez, ey}, {-ex, ey}, {ez, ey}, {ex, -ez}, {ex, ez}};
    placement.boxes.push_back({placement.quads.size(), std::min(ex.x, std::min(ey.y, ez.z)), index});
    // Six faces, each with an outward front normal (u x v).
    const Vec3 faces[6][3] = {
        {{lo.x, lo.y, hi.z}, dx, dy},   // +z
        {{hi.x, lo.y, hi.z}, -dz, dy},  // +x
        {{hi.x, lo.y, lo.z}, -dx, dy},  // -z
        {{lo.x, lo.y, lo.z}, dz, dy},   // -x
        {{lo.x, hi.y, hi.z}, dx, -dz},  // +y
        {{lo.x, lo.y, lo.z}, dx, dz},   // -y
    };
    for (int i = 0; i < 6; ++i) {
      const auto& f = faces[i];
      check_quad(node, edges[i][0], edges[i][1]);
      if (importance) scene.targets.push_back({Target::Kind::Quad, static_cast<std::uint32_t>(placement.quads.size())});
      placement.quads.push_back({rotated(corners_d[i]), rotate_y(f[0], c, s) + offset, rotate_y(f[1], c, s),
                                 rotate_y(f[2], c, s), rotate_y(edges[i][0], c, s), rotate_y(edges[i][1], c, s), mat});
    }
  } else {
    type_node.fail("unknown object type '" + type + "' (quad, box, sphere)");
  }
}

// The distance from p to the nearest object: a quad's bounding box (a box's
// faces' too), a sphere's surface. Only a scale for choosing the rendering
// space, not a distance anything is rendered with.
double nearest_object(const Placement& placement, const D3& p) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const Placement::QuadRow& q : placement.quads) {
    const D3 u = d3(q.u_exact), v = d3(q.v_exact);
    const D3 corners[4] = {q.corner, q.corner + u, q.corner + v, q.corner + u + v};
    D3 lo = corners[0], hi = corners[0];
    for (const D3& c : corners) {
      lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
      hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
    }
    const D3 outside = {std::max({lo.x - p.x, 0.0, p.x - hi.x}), std::max({lo.y - p.y, 0.0, p.y - hi.y}),
                        std::max({lo.z - p.z, 0.0, p.z - hi.z})};
    nearest = std::min(nearest, norm(outside));
  }
  for (const Placement::SphereRow& sp : placement.spheres)
    nearest = std::min(nearest, std::fabs(norm(sp.center - p) - static_cast<double>(sp.radius)));
  return nearest;
}

// A float's step at magnitude m (the spacing of floats in [2^k, 2^(k+1))).
double float_step(double m) {
  if (!(m >= static_cast<double>(std::numeric_limits<float>::min()))) return 0.0;
  int exponent = 0;
  std::frexp(m, &exponent);  // m = f 2^exponent, f in [0.5, 1)
  return std::ldexp(1.0, exponent - 24);
}

// Chooses the rendering space (Scene::origin), rounds every position into it,
// and refuses what float cannot hold there: a box too small for its
// coordinates, a camera whose lookat rounds onto lookfrom.
void place_in_rendering_space(const Node& root, const Placement& placement, Scene& scene) {
  const D3 from = placement.lookfrom;
  const double sees = std::min(nearest_object(placement, from), norm(placement.lookat - from));
  const bool camera_centred = max_abs(from) > kCameraCentredRatio * sees;
  const D3 origin = camera_centred ? from : D3{0.0, 0.0, 0.0};
  scene.origin = {origin.x, origin.y, origin.z};
  const auto place = [&](const D3& p, const Vec3& as_book) { return camera_centred ? to_float(p - origin) : as_book; };

  // A box first: where float cannot place its faces they may not even be quads.
  for (const Placement::BoxRow& box : placement.boxes) {
    float reach = 0.0f;
    for (std::size_t i = box.first_face; i < box.first_face + 6; ++i) {
      const Placement::QuadRow& f = placement.quads[i];
      const Vec3 q = place(f.corner, f.corner_float);
      reach = std::max({reach, max_abs_component(q), max_abs_component(q + f.u_exact + f.v_exact)});
    }
    const double step = float_step(reach);
    if (static_cast<double>(box.smallest_side) < kSmallestBoxSteps * step) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "the box's smallest side (%.3g) spans fewer than %.0f steps of single precision where it is "
                    "(its corners reach %.3g from the rendering space's origin, %s, where a step is %.3g): "
                    "place it nearer the camera or the origin, or make it larger",
                    static_cast<double>(box.smallest_side), kSmallestBoxSteps, static_cast<double>(reach),
                    camera_centred ? "the camera" : "the scene's origin", step);
      root.child("objects").element(box.object).fail(text);
    }
  }
  for (const Placement::QuadRow& q : placement.quads) {
    const Vec3 u = camera_centred ? q.u_exact : q.u, v = camera_centred ? q.v_exact : q.v;
    scene.quads.push_back(make_quad(place(q.corner, q.corner_float), u, v, q.material));
  }
  for (const Placement::SphereRow& sp : placement.spheres)
    scene.spheres.push_back({place(sp.center, to_float(sp.center)), sp.radius, sp.material});

  Camera& cam = scene.camera;
  cam.lookfrom = place(placement.lookfrom, to_float(placement.lookfrom));
  cam.lookat = place(placement.lookat, to_float(placement.lookat));
  const Node camera = root.child("camera");
  const Vec3 view = cam.lookat - cam.lookfrom;
  if (view == Vec3(0.0f)) camera.fail("lookfrom and lookat are the same point in single precision");
  // Both as unit vectors whatever their length (unit_direction): a camera far
  // from its target squares its distance past float's range, and is not
  // therefore looking along vup.
  const Vec3 side = cross(unit_direction(cam.vup), unit_direction(view));
  if (!(length(side) > 1e-6f)) camera.fail("vup is zero or parallel to the viewing direction");
}

std::string line_and_column(const std::string& text, std::size_t byte) {
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}

}  // namespace

namespace {

// `environment`: a lat-long map (docs/environment.md) read from `file`, a path
// relative to the scene file's folder (`base`), its radiance times `scale`,
// turned `rotation` degrees about +y.
std::shared_ptr<const Environment> parse_environment(const Node& node, const std::filesystem::path& base) {
  node.expect_object();
  node.allow_only({"file", "scale", "rotation"});
  const Node file = node.require("file");
  const std::string name = file.string();
  if (name.empty()) file.fail("expected a file name, found an empty string");
  const std::filesystem::path path = std::filesystem::path(name).is_absolute() ? std::filesystem::path(name) : base / name;
  float scale = 1.0f, rotation = 0.0f;
  if (node.has("scale")) {
    const Node n = node.child("scale");
    scale = n.real();
    if (!(scale >= 0.0f)) n.fail("must be >= 0 (it multiplies the map's radiance)");
  }
  if (node.has("rotation")) {
    const Node n = node.child("rotation");
    const double degrees = n.number();
    if (!(std::fabs(degrees) <= 360.0)) n.fail("must be in -360..360 degrees");
    rotation = static_cast<float>(degrees);
  }
  int width = 0, height = 0;
  std::vector<float> rgb;
  try {
    rgb = read_environment_image(path.string(), width, height);
  } catch (const InputError& e) {
    file.fail(e.what());
  }
  auto environment = std::make_shared<Environment>(std::move(rgb), width, height, scale, rotation);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (!is_finite(environment->texel(x, y)))
        node.fail("the map times scale overflows float at texel (" + std::to_string(x) + ", " + std::to_string(y) + ")");
  return environment;
}

// The parsed document without what a reference is keyed by separately (size,
// depth) or what does not change the image (the description), dumped in one
// canonical form (sorted keys, no spaces): reformatting a file keeps its hash.
std::string content_hash(json doc) {
  doc.erase("description");
  if (doc.contains("camera") && doc["camera"].is_object())
    for (const char* key : {"width", "height", "max_depth"}) doc["camera"].erase(key);
  const std::string canonical = doc.dump();
  return fnv1a_hex(canonical.data(), canonical.size());
}

// JSON lets an object name a key twice and nlohmann's parser keeps the last
// value: a scene with two "objects" arrays would lose the first without a
// word. This follows the parser's events and keeps the path of the first key
// that appears twice in one object ("objects", "camera.vfov",
// "materials.white.albedo", "objects[2].q").
class DuplicateKeys {
 public:
  bool operator()(int /*depth*/, json::parse_event_t event, const json& parsed) {
    using E = json::parse_event_t;
    switch (event) {
      case E::object_start: frames_.push_back({true, {}, {}, 0}); break;
      case E::array_start: frames_.push_back({false, {}, {}, 0}); break;
      case E::key: {
        Frame& f = frames_.back();
        const std::string& key = parsed.get_ref<const std::string&>();
        if (!f.keys.insert(key).second && first_.empty()) first_ = path_to(key);
        f.key = key;
        break;
      }
      case E::object_end:
      case E::array_end:
        frames_.pop_back();
        next_element();
        break;
      case E::value: next_element(); break;
    }
    return true;
  }
  // Empty when no key appears twice.
  const std::string& first() const { return first_; }

 private:
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;     // an object's current key
    std::size_t index;   // an array's current element
  };
  void next_element() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
  }
  std::string path_to(const std::string& key) const {
    std::string path;
    for (std::size_t i = 0; i + 1 < frames_.size(); ++i) {
      const Frame& f = frames_[i];
      if (f.object) path += (path.empty() ? "" : ".") + f.key;
      else path += "[" + std::to_string(f.index) + "]";
    }
    return path + (path.empty() ? "" : ".") + key;
  }
  std::vector<Frame> frames_;
  std::string first_;
};

Scene parse_scene(const std::string& text, const std::string& origin, const std::filesystem::path& base) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw InputError(origin + ": the scene is empty (expected a JSON object)");
  json doc;
  DuplicateKeys duplicates;
  try {
    doc = json::parse(text, std::ref(duplicates));
  } catch (const json::parse_error& e) {
    // e.what() is "[json.exception.parse_error.101] parse error at line L, column C: ..."; keep the reason.
    std::string reason = e.what();
    const auto colon = reason.find(": ");
    reason = colon == std::string::npos ? reason : reason.substr(colon + 2);
    throw InputError(origin + ": JSON syntax error at " + line_and_column(text, e.byte) + ": " + reason);
  } catch (const json::exception& e) {
    // Numbers beyond double's range (1e999) are rejected with out_of_range, not
    // parse_error; the message quotes the number, which locates it in the text.
    std::string reason = e.what();
    const auto colon = reason.find("] ");
    reason = colon == std::string::npos ? reason : reason.substr(colon + 2);
    std::string where;
    const auto q1 = reason.find('\'');
    const auto q2 = q1 == std::string::npos ? std::string::npos : reason.find('\'', q1 + 1);
    if (q2 != std::string::npos) {
      const auto at = text.find(reason.substr(q1 + 1, q2 - q1 - 1));
      if (at != std::string::npos) where = " at " + line_and_column(text, at + 1);
    }
    throw InputError(origin + ": JSON error" + where + ": " + reason);
  }
  if (!duplicates.first().empty())
    throw InputError(origin + ": " + duplicates.first() +
                     ": the key appears twice in its object (JSON would keep only the last value)");
  Node root(doc, "", origin);
  root.expect_object();
  root.allow_only(
      {"name", "description", "camera", "materials", "objects", "environment", "light_choice", "fastest_uses_guiding"});

  Scene scene;
  scene.name = root.has("name") ? root.child("name").string() : origin;
  if (root.has("description")) (void)root.child("description").string();
  if (root.has("light_choice")) {
    const Node choice = root.child("light_choice");
    if (!parse_light_choice(choice.string(), scene.light_choice))
      choice.fail("unknown light choice '" + choice.string() + "' (allowed: power, uniform, tree)");
  }
  if (root.has("fastest_uses_guiding")) scene.fastest_uses_guiding = root.child("fastest_uses_guiding").boolean();
  Placement placement;
  parse_camera(root.require("camera"), scene, placement);

  const Node mats = root.require("materials");
  mats.expect_object();
  std::map<std::string, std::uint32_t> by_name;
  for (auto it = mats.value().begin(); it != mats.value().end(); ++it) {
    by_name[it.key()] = static_cast<std::uint32_t>(scene.materials.size());
    scene.materials.push_back(parse_material(mats.child(it.key())));
    scene.material_names.push_back(it.key());
  }

  const Node objects = root.require("objects");
  objects.expect_array();
  if (objects.value().empty()) objects.fail("the scene has no objects");
  for (std::size_t i = 0; i < objects.value().size(); ++i)
    parse_object(objects.element(i), i, by_name, scene, placement);
  place_in_rendering_space(root, placement, scene);

  if (root.has("environment")) {
    if (root.child("camera").has("background"))
      root.child("environment").fail("camera.background is given too: the environment is the radiance of every ray "
                                     "that leaves the scene; give one of them");
    scene.environment = parse_environment(root.child("environment"), base);
  }

  scene.prepare();
  scene.content_hash = content_hash(doc);
  if (scene.environment) {
    // The map's texels, not only its file name: a reference depends on them.
    const std::string both = scene.content_hash + ":" + std::to_string(scene.environment->hash());
    scene.content_hash = fnv1a_hex(both.data(), both.size());
  }
  return scene;
}

}  // namespace

Scene load_scene_text(const std::string& text, const std::string& origin, const std::string& base) {
  try {
    return parse_scene(text, origin, base);
  } catch (const InputError& e) {
    throw InputError(printable(e.what()));
  }
}

Scene load_scene_file(const std::string& path) {
  // A file or a device (/dev/zero is stopped by the size limit); a folder, a
  // pipe or a socket is refused before anything is read.
  std::uint64_t size = 0;
  std::FILE* in = open_input_file(path, "scene", InputKind::FileOrDevice, &size);
  std::string text;
  // A regular file's size is known: one allocation. A device grows the text
  // chunk by chunk, and is refused before it passes the limit.
  if (size <= kMaxSceneBytes) text.reserve(static_cast<std::size_t>(size));
  char chunk[1 << 16];
  for (;;) {
    const std::size_t n = std::fread(chunk, 1, sizeof chunk, in);
    if (text.size() + n > kMaxSceneBytes) {
      std::fclose(in);
      throw InputError("cannot read scene '" + path + "': larger than " + std::to_string(kMaxSceneBytes >> 20) +
                       " MiB; is it a scene file?");
    }
    text.append(chunk, n);
    if (n < sizeof chunk) break;
  }
  const bool failed = std::ferror(in) != 0;
  std::fclose(in);
  if (failed) throw InputError("cannot read scene '" + path + "': read error");
  return load_scene_text(text, path, std::filesystem::path(path).parent_path().string());
}

}  // namespace pdflab
