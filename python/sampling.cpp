// The techniques themselves: the table, a strategy's draw from given numbers
// and its pdf on numpy arrays, and the chi-square check at a point.
#include "python/bindings.h"

#include "renderer/error.h"
#include "renderer/metrics/chi_square.h"
#include "renderer/metrics/probe.h"
#include "renderer/metrics/weight_paths.h"
#include "renderer/sampling/strategy.h"

#include <pybind11/stl.h>

#include <array>
#include <cmath>

namespace pdflab::python {

namespace {

using FloatArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A scene for the techniques that need none (the cosine lobe, the uniform
// ones): nothing to aim at, so a light technique is refused with the
// sampling plan's own message.
const Scene& empty_scene() {
  static const Scene scene = [] {
    Scene s;
    s.name = "no scene";
    s.prepare();
    return s;
  }();
  return scene;
}

// Rows of three: (3,) is one row for all, (N, 3) one per item.
struct Rows3 {
  const double* data = nullptr;
  py::ssize_t rows = 0;
  Vec3 at(py::ssize_t i) const {
    const double* p = data + 3 * (rows == 1 ? 0 : i);
    return {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
  }
};

Rows3 rows3(const FloatArray& a, const char* name, py::ssize_t n) {
  Rows3 r{a.data(), 0};
  if (a.ndim() == 1 && a.shape(0) == 3) r.rows = 1;
  else if (a.ndim() == 2 && a.shape(1) == 3) r.rows = a.shape(0);
  else throw InputError(std::string(name) + " must be of shape (3,) or (N, 3)");
  if (r.rows != 1 && n >= 0 && r.rows != n)
    throw InputError(std::string(name) + " has " + std::to_string(r.rows) + " rows, not " + std::to_string(n));
  return r;
}

Vec3 unit(const Vec3& v, const char* name, py::ssize_t i) {
  const float len = length(v);
  if (!(std::fabs(len - 1.0f) <= 1e-3f))
    throw InputError(std::string(name) + " " + std::to_string(i) + " is not a unit vector (length " +
                     std::to_string(len) + ")");
  return v;
}

struct Plan {
  std::shared_ptr<const Scene> keep;  // the scene the plan points into
  SamplingPlan plan;
};

Plan plan_for(const std::string& strategy, const py::object& scene) {
  Plan p;
  const Scene* s = &empty_scene();
  if (!scene.is_none()) {
    p.keep = scene.cast<const SceneHandle&>().scene;
    s = p.keep.get();
  }
  p.plan = SamplingPlan::make(Strategy::parse(strategy), *s);
  return p;
}

std::uint32_t bits_of(double u) { return static_cast<std::uint32_t>(std::min(4294967295.0, std::floor(u * 4294967296.0))); }

}  // namespace

void bind_sampling(py::module_& m) {
  m.def(
      "techniques",
      [] {
        py::list rows;
        for (int i = 0; i < kTechniqueCount; ++i) {
          const Technique t = static_cast<Technique>(i);
          const TechniqueInfo& info = technique_info(t);
          py::dict row;
          row["name"] = std::string(info.name);
          row["draws"] = std::string(info.draws);
          row["pdf"] = std::string(info.pdf);
          // Whether the technique alone is unbiased, as the strategy decides it.
          row["unbiased_alone"] = Strategy::single(t).is_unbiased();
          row["parameter"] = info.parameter.empty() ? py::object(py::none()) : py::cast(std::string(info.parameter));
          if (!info.parameter.empty()) {
            row["parameter_default"] = info.parameter_default;
            row["parameter_min"] = info.parameter_min;
            row["parameter_max"] = info.parameter_max;
          }
          row["colour"] = py::make_tuple(info.colour[0] / 255.0, info.colour[1] / 255.0, info.colour[2] / 255.0);
          rows.append(row);
        }
        return rows;
      },
      "The technique table: one dict per technique (name, what it draws, its pdf, whether it is unbiased alone, "
      "its parameter, its colour in the viewer's probe).");

  m.def("strategy_help", &strategy_help, "The strategy grammar and the techniques, as `pdflab render --help` ends.");

  m.def(
      "strategy",
      [](const std::string& text) {
        const Strategy s = Strategy::parse(text);
        py::dict d;
        d["canonical"] = s.to_string();
        d["unbiased"] = s.is_unbiased();
        d["nee_mis"] = s.nee_mis;
        d["sobol"] = s.sobol;
        d["roulette_depth"] = s.roulette_depth;
        d["guided_roulette"] = s.guided_roulette;
        py::dict weights;
        for (const auto& [name, w] : mixture_terms(s)) weights[py::str(name)] = w;
        d["weights"] = weights;
        return d;
      },
      py::arg("text"), "A strategy as pdflab reads it: its canonical text, whether it is unbiased, its weights.");

  m.def(
      "sample",
      [](const std::string& technique, const FloatArray& normal, const FloatArray& u, const FloatArray& origin,
         const py::object& scene) {
        if (u.ndim() != 2 || u.shape(1) < 2 || u.shape(1) > 4)
          throw InputError("u must be of shape (N, 2), (N, 3) or (N, 4): u1, u2 for the direction, then a number "
                           "for the target and one for the technique");
        const py::ssize_t n = u.shape(0), k = u.shape(1);
        const Rows3 normals = rows3(normal, "normal", n), origins = rows3(origin, "origin", n);
        const Plan p = plan_for(technique, scene);
        py::array_t<float> directions({n, py::ssize_t{3}});
        py::array_t<float> pdfs(n);
        py::array_t<std::int32_t> chosen(n);
        const double* uu = u.data();
        for (py::ssize_t i = 0; i < n; ++i)
          for (py::ssize_t j = 0; j < k; ++j)
            if (!(uu[i * k + j] >= 0.0 && uu[i * k + j] < 1.0))
              throw InputError("u[" + std::to_string(i) + ", " + std::to_string(j) + "] is not in [0, 1)");
        float* d = directions.mutable_data();
        float* pdf = pdfs.mutable_data();
        std::int32_t* which = chosen.mutable_data();
        for (py::ssize_t i = 0; i < n; ++i) {
          const double* row = uu + i * k;
          int t = -1;
          const DirectionSample s =
              p.plan.sample_at(origins.at(i), unit(normals.at(i), "normal", i), static_cast<float>(row[0]),
                               static_cast<float>(row[1]), k > 3 ? bits_of(row[3]) : 0u, k > 2 ? bits_of(row[2]) : 0u, &t);
          d[3 * i] = s.none ? 0.0f : s.direction.x;
          d[3 * i + 1] = s.none ? 0.0f : s.direction.y;
          d[3 * i + 2] = s.none ? 0.0f : s.direction.z;
          pdf[i] = s.none ? 0.0f : s.pdf;
          which[i] = s.none ? -1 : t;
        }
        return py::make_tuple(directions, pdfs, chosen);
      },
      py::arg("technique"), py::arg("normal"), py::arg("u"), py::arg("origin") = std::vector<double>{0.0, 0.0, 0.0},
      py::arg("scene") = py::none(),
      R"(Draws directions as pdflab does, from given numbers.

technique: a technique or any strategy's mixture ('cosine', 'cosine-power:8',
'mix:cosine=0.5,light=0.5'); normal: (3,) or (N, 3) unit vectors; u: (N, 2)
to (N, 4) numbers in [0, 1): u1, u2 for the direction, then one for the
target (light techniques) and one for the technique of a mixture; origin:
the shading point (light techniques aim from it), scene: what they aim at.
Returns (directions (N, 3) float32, the mixture's pdf (N,) float32, the
technique index that drew each (N,) int32, -1 where it had no direction:
then the direction and pdf are 0).)");

  m.def(
      "pdf",
      [](const std::string& technique, const FloatArray& normal, const FloatArray& direction, const FloatArray& origin,
         const py::object& scene) {
        const Rows3 directions = rows3(direction, "direction", -1);
        const py::ssize_t n = directions.rows;
        const Rows3 normals = rows3(normal, "normal", n), origins = rows3(origin, "origin", n);
        const Plan p = plan_for(technique, scene);
        py::array_t<float> out(n);
        float* o = out.mutable_data();
        for (py::ssize_t i = 0; i < n; ++i)
          o[i] = p.plan.pdf(origins.at(i), unit(normals.at(i), "normal", i), unit(directions.at(i), "direction", i));
        return out;
      },
      py::arg("technique"), py::arg("normal"), py::arg("direction"),
      py::arg("origin") = std::vector<double>{0.0, 0.0, 0.0}, py::arg("scene") = py::none(),
      "The solid-angle pdf of a technique (or a mixture) for unit directions (3,) or (N, 3), about unit normals.");

  m.def(
      "chi_square",
      [](const std::string& strategy, const std::vector<double>& point, const py::object& scene,
         const std::optional<std::vector<double>>& normal, int samples, std::uint64_t seed, int z_cells, int phi_cells,
         double alpha) {
        if (samples < 1000 || samples > 100000000) throw InputError("samples must be in 1000..100000000");
        if (z_cells < 2 || z_cells > 1000 || phi_cells < 2 || phi_cells > 1000)
          throw InputError("z_cells and phi_cells must be in 2..1000");
        const Plan p = plan_for(strategy, scene);
        if (p.plan.nee_mis)
          throw InputError("chi_square: '" + strategy + "' draws two directions at a vertex (a light sample and a "
                           "continuation); check its continuation's mixture instead");
        ProbePoint at;
        if (point.size() == 2) {
          if (scene.is_none()) throw InputError("chi_square: a pixel (x, y) needs the scene");
          const Scene& s = *p.keep;
          const int x = static_cast<int>(point[0]), y = static_cast<int>(point[1]);
          if (x < 0 || y < 0 || x >= s.camera.width || y >= s.camera.height)
            throw InputError("chi_square: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                             ") is outside the " + std::to_string(s.camera.width) + "x" +
                             std::to_string(s.camera.height) + " image");
          at = first_diffuse_hit(s, x, y);
          if (!at.found)
            throw InputError("chi_square: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                             ") sees no diffuse surface (it sees a light or leaves the scene)");
        } else if (point.size() == 3) {
          if (!normal) throw InputError("chi_square: a point (x, y, z) needs its normal");
          if (normal->size() != 3) throw InputError("chi_square: the normal must have 3 components");
          at.found = true;
          // In the scene file's coordinates: into the rendering space (Scene::origin).
          const std::array<double, 3> origin = p.keep ? p.keep->origin : std::array<double, 3>{};
          at.point = Vec3(static_cast<float>(point[0] - origin[0]), static_cast<float>(point[1] - origin[1]),
                          static_cast<float>(point[2] - origin[2]));
          at.normal = unit(Vec3(static_cast<float>((*normal)[0]), static_cast<float>((*normal)[1]),
                                static_cast<float>((*normal)[2])),
                           "normal", 0);
        } else {
          throw InputError("chi_square: point must be a pixel (x, y) of the scene or a point (x, y, z) with a normal");
        }
        std::vector<chi_square::Outcome> both;
        {
          py::gil_scoped_release release;
          both = chi_square::check_plan(p.plan, at.point, at.normal,
                                        {chi_square::Sampler::Packet, chi_square::Sampler::OnePath}, samples, seed,
                                        chi_square::Grid{z_cells, phi_cells});
        }
        const chi_square::Outcome& packet = both[0];
        const chi_square::Outcome& one_path = both[1];
        py::dict d;
        d["passed"] = packet.passed(alpha) && one_path.passed(alpha);
        d["p_value"] = packet.chi.p_value;
        d["statistic"] = packet.chi.statistic;
        d["dof"] = packet.chi.dof;
        d["one_path_p_value"] = one_path.chi.p_value;
        d["alpha"] = alpha;
        d["samples"] = samples;
        d["integral"] = packet.integral;
        d["empty_samples"] = packet.empty_samples;
        d["bad_pdf"] = packet.bad_pdf + one_path.bad_pdf;
        d["zero_cell_hits"] = packet.chi.zero_cell_hits + one_path.chi.zero_cell_hits;
        if (p.keep) {
          const auto in_file = file_point(*p.keep, at.point);
          d["point"] = std::vector<double>{in_file[0], in_file[1], in_file[2]};
        } else {
          d["point"] = std::vector<double>{at.point.x, at.point.y, at.point.z};
        }
        d["normal"] = std::vector<double>{at.normal.x, at.normal.y, at.normal.z};
        const auto rows = static_cast<py::ssize_t>(z_cells), cols = static_cast<py::ssize_t>(phi_cells);
        py::array_t<std::uint64_t> observed({rows, cols});
        py::array_t<double> expected({rows, cols});
        std::copy(packet.observed.begin(), packet.observed.end(), observed.mutable_data());
        std::copy(packet.expected.begin(), packet.expected.end(), expected.mutable_data());
        d["observed"] = observed;
        d["expected"] = expected;
        return d;
      },
      py::arg("strategy"), py::arg("point"), py::arg("scene") = py::none(), py::arg("normal") = py::none(),
      py::arg("samples") = 200000, py::arg("seed") = 1, py::arg("z_cells") = 16, py::arg("phi_cells") = 32,
      py::arg("alpha") = 0.01,
      R"(The chi-square check of a strategy's sampler against its pdf (the viewer's probe, C).

point: a pixel (x, y) of `scene` (its first diffuse surface, past glass and
metal) or a point (x, y, z) with its `normal`. Both samplers are checked (the
packet tracer's and the one-path tracer's); passed when both are, at `alpha`.
observed and expected are z_cells x phi_cells counts over the sphere about the
normal (rows of equal cos(theta) from +1 down to -1, columns of azimuth).)");
}

}  // namespace pdflab::python
