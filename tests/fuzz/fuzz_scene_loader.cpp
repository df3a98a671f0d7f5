// libFuzzer target for the scene loader (scripts/fuzz.sh builds and runs it).
// Any input must either load or be refused with an InputError whose message is
// one printable line starting with the origin; any other
// exception, a sanitizer report, a hang or a scene that loads but breaks an
// invariant the renderer relies on is a finding. A scene that loads also
// renders a few samples, so that the loader's validation is checked against
// what the integrator actually does with the numbers.
#include "renderer/error.h"
#include "renderer/film/film.h"
#include "renderer/integrator/integrator.h"
#include "renderer/scene/scene_loader.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

[[noreturn]] void broken(const char* what) {
  std::fprintf(stderr, "fuzz_scene_loader: invariant broken: %s\n", what);
  std::abort();
}

void check_loaded(const pdflab::Scene& scene) {
  using namespace pdflab;
  const Camera& cam = scene.camera;
  if (!image_size_problem(cam.width, cam.height).empty()) broken("image size outside the limits");
  if (!(cam.vfov_degrees > 0.0f && cam.vfov_degrees < 180.0f)) broken("vfov outside (0, 180)");
  if (scene.quads.empty() && scene.spheres.empty()) broken("a scene without objects");
  if (scene.max_depth < 1) broken("max_depth < 1");
  for (const Sphere& s : scene.spheres)
    if (!(s.radius > 0.0f) || s.material >= scene.materials.size()) broken("bad sphere");
  for (const Quad& q : scene.quads)
    if (q.material >= scene.materials.size()) broken("quad with a material out of range");
  for (const Target& t : scene.targets) {
    const std::size_t n = t.kind == Target::Kind::Quad ? scene.quads.size() : scene.spheres.size();
    if (t.index >= n) broken("importance target out of range");
  }

  // A few samples at the centre and a corner, with light sampling when the scene has targets.
  const Strategy strategy = scene.targets.empty() ? Strategy::single(Technique::Cosine)
                                                  : Strategy::parse("mix:cosine=0.5,light=0.5");
  const SamplingPlan plan = SamplingPlan::make(strategy, scene);
  DropCounts drops;
  for (std::uint32_t s = 0; s < 4; ++s) {
    for (const auto& [x, y] : {std::pair{cam.width / 2, cam.height / 2}, std::pair{0, 0}}) {
      const Vec3 L = render_pixel_sample(scene, plan, 1, x, y, s, drops);
      if (!(std::isfinite(L.x) && std::isfinite(L.y) && std::isfinite(L.z))) broken("non-finite radiance returned");
      if (L.x < 0.0f || L.y < 0.0f || L.z < 0.0f) broken("negative radiance");
    }
  }
}

// A message is one line of valid UTF-8 without control bytes: it goes to a terminal.
bool printable_utf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      if (c < 0x20 || c == 0x7f) return false;
      ++i;
      continue;
    }
    const std::size_t n = (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3 : (c & 0xF8) == 0xF0 ? 4 : 0;
    if (n == 0 || i + n > s.size() || c == 0xC0 || c == 0xC1 || c > 0xF4) return false;
    for (std::size_t k = 1; k < n; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return false;
    i += n;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  pdflab::Scene scene;
  try {
    scene = pdflab::load_scene_text(text, "fuzz");
  } catch (const pdflab::InputError& e) {
    const std::string message = e.what();
    if (message.rfind("fuzz: ", 0) != 0) broken("message does not start with the origin");
    if (!printable_utf8(message)) broken("message with a control byte or invalid UTF-8");
    return 0;
  }
  check_loaded(scene);
  return 0;
}
