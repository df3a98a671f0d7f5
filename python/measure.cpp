// Measuring: references and their cache, relMSE against one, the weight sweep
// and the weight prediction.
#include "python/bindings.h"

#include "app/bench_command.h"
#include "app/measured_run.h"
#include "app/reference_command.h"
#include "app/sweep_command.h"
#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/metrics/metrics.h"
#include "renderer/metrics/weight_paths.h"
#include "renderer/metrics/weight_prediction.h"
#include "renderer/session/reference_build.h"

#include <pybind11/stl.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace pdflab::python {

namespace {

namespace fs = std::filesystem;

struct ReferenceHandle {
  Reference reference;
};

ReferenceHandle& reference_of(const py::object& self) { return self.cast<ReferenceHandle&>(); }

// A folder of its own under the system's temporary folder, removed with it.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "pdflab-py-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw IoError("cannot make a temporary folder in " + fs::temp_directory_path().string());
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// What the command writes on standard output while `run` runs, captured into
// a string (the sweep's table), so that a notebook shows it only when asked.
template <class F>
std::string capture_stdout(const std::string& folder, F&& run) {
  const std::string path = (fs::path(folder) / "stdout.txt").string();
  std::fflush(stdout);
  const int saved = ::dup(STDOUT_FILENO);
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  if (saved < 0 || fd < 0) {
    if (saved >= 0) ::close(saved);
    if (fd >= 0) ::close(fd);
    run();
    return {};
  }
  ::dup2(fd, STDOUT_FILENO);
  ::close(fd);
  const auto restore = [&] {
    std::fflush(stdout);
    ::dup2(saved, STDOUT_FILENO);
    ::close(saved);
  };
  try {
    run();
  } catch (...) {
    restore();
    throw;
  }
  restore();
  return read_text(path);
}

// A sweep's or a prediction's runs, stopped by Ctrl+C: each run's poll takes
// the GIL for a moment to run Python's signal handlers, and a KeyboardInterrupt
// they raise stops the run in flight and is raised here (with the GIL held
// again). The stdout capture and the temporary folder are undone on the way.
template <typename F>
auto interruptible(F&& run) {
  const ScopedRunInterrupt scope([] {
    py::gil_scoped_acquire gil;
    return PyErr_CheckSignals() != 0;
  });
  try {
    return run();
  } catch (const RunInterrupted&) {
    throw py::error_already_set();
  }
}

// A scene at the size (and depth) a reference is wanted for, as `pdflab
// reference` sizes it.
std::shared_ptr<Scene> sized_scene(const SceneHandle& handle, std::optional<int> width, std::optional<int> height,
                                   std::optional<int> max_depth) {
  auto scene = std::make_shared<Scene>(*handle.scene);
  if (width) scene->camera.width = *width;
  if (height) scene->camera.height = *height;
  if (max_depth) scene->max_depth = *max_depth;
  check_image_size(scene->camera.width, scene->camera.height, "--width/--height");
  scene->prepare();
  return scene;
}

// `pdflab reference`'s render, polled by pdflab.reference (nothing here blocks
// but finish()).
class ReferenceBuildHandle {
 public:
  ReferenceBuildHandle(const SceneHandle& handle, std::optional<std::int64_t> spp, std::optional<double> seconds,
                       std::optional<double> target_relmse, const std::string& strategy, std::int64_t seed_stream,
                       std::optional<int> width, std::optional<int> height, std::optional<int> max_depth, int threads,
                       const std::string& cache_dir, const std::string& out, int roulette_depth)
      : cache_dir_(reference_cache_dir(cache_dir)), out_(out) {
    if ((spp.has_value()) + (seconds.has_value()) + (target_relmse.has_value()) != 1)
      throw InputError("give exactly one of --spp, --seconds and --target-relmse");
    if (spp && (*spp < 1 || *spp > (std::int64_t{1} << 30))) throw InputError("spp must be in 1..1073741824");
    if (seconds && !(std::isfinite(*seconds) && *seconds > 0.0)) throw InputError("--seconds must be a positive number");
    if (target_relmse && !(std::isfinite(*target_relmse) && *target_relmse > 0.0))
      throw InputError("--target-relmse must be a positive number");
    if (seed_stream < 0 || seed_stream > (1 << 30)) throw InputError("seed_stream must be in 0..1073741824");
    if (threads < 0 || threads > 1024) throw InputError("threads must be in 0..1024 (0: all cores)");
    if (!out_.empty()) {
      if (image_format_for(out_) != ImageFormat::Pfm)
        throw InputError("--out '" + out_ + "' must name a .pfm file (the variance and the sidecar go beside it)");
      check_output_path(out_);
    }
    auto scene = sized_scene(handle, width, height, max_depth);
    ReferenceJob job;
    job.scene = scene;
    job.scene_file = handle.origin;
    job.strategy = reference_strategy(strategy, roulette_depth, *scene);
    job.seed_stream = static_cast<std::uint32_t>(seed_stream);
    job.goal = {spp ? static_cast<std::uint32_t>(*spp) : 0u, seconds.value_or(0.0), target_relmse.value_or(0.0)};
    job.threads = threads;
    job.version = PDFLAB_VERSION;
    key_ = reference_key(*scene);
    build_ = std::make_unique<ReferenceBuild>(job);
  }

  py::dict poll() {
    const ReferenceProgress p = build_->poll();
    const SessionStats st = build_->stats();
    py::dict d;
    d["fraction"] = p.fraction;
    d["seconds_left"] = p.seconds_left;
    d["reached"] = p.reached;
    d["spp"] = st.spp;
    d["seconds"] = st.seconds;
    d["samples_per_second"] = st.samples_per_second;
    return d;
  }

  // Into the cache (and `out`), as `pdflab reference` stores it.
  ReferenceHandle finish() {
    py::gil_scoped_release release;
    ReferenceHandle r{build_->finish()};
    r.reference.path = store_cached_reference(cache_dir_, key_, r.reference);
    if (!out_.empty()) save_reference(out_, r.reference);
    build_.reset();
    return r;
  }

 private:
  std::string cache_dir_, out_;
  ReferenceKey key_;
  std::unique_ptr<ReferenceBuild> build_;
};

py::dict relmse_dict(const RelMseMeasure& m, double seconds) {
  py::dict d;
  d["value"] = m.corrected;
  d["interval"] = m.interval;
  d["raw"] = m.raw;
  d["reference_noise"] = m.reference_noise;
  d["reference_share"] = m.reference_share();
  d["reference_corrected"] = m.reference_corrected;
  d["seconds"] = seconds;
  d["efficiency"] = efficiency(m.corrected, seconds);
  return d;
}

// `--reference FILE|auto` for a film: a Reference (not copied), a file, or
// the cache's entry for the film's scene at its size and depth.
struct ReferenceFor {
  Reference loaded;
  const Reference* reference = nullptr;
};
void reference_for(const py::object& ref, const FilmHandle& film, const std::string& cache_dir, ReferenceFor& out) {
  if (py::isinstance<ReferenceHandle>(ref)) {
    out.reference = &ref.cast<const ReferenceHandle&>().reference;
    return;
  }
  const std::string option = py::str(ref).cast<std::string>();
  if (option == "auto" && !film.scene)
    throw InputError("reference 'auto' needs the film's scene: this film was read from a file; give the reference");
  out.loaded = option == "auto" ? resolve_reference(option, *film.scene, film.info.scene_file, cache_dir, true, true)
                                : load_reference(option);
  out.reference = &out.loaded;
}

}  // namespace

void bind_measuring(py::module_& m) {
  py::class_<ReferenceHandle>(m, "Reference", R"(A reference image: the mean and its own variance (H x W x 3 float32).

pdflab.reference(scene, ...) renders one into the cache as `pdflab reference`
does, or finds the cached one; Reference.load(path) reads a .pfm (with its
.var.pfm and .json beside it) or an EXR.)")
      .def_static("load", [](const std::string& path) { return ReferenceHandle{load_reference(path)}; }, py::arg("path"))
      .def_property_readonly("path", [](const ReferenceHandle& r) { return r.reference.path; })
      .def_property_readonly("width", [](const ReferenceHandle& r) { return r.reference.width; })
      .def_property_readonly("height", [](const ReferenceHandle& r) { return r.reference.height; })
      .def_property_readonly("spp", [](const ReferenceHandle& r) { return r.reference.info.spp; })
      .def_property_readonly("seconds", [](const ReferenceHandle& r) { return r.reference.info.seconds; })
      .def_property_readonly("strategy", [](const ReferenceHandle& r) { return r.reference.info.strategy; })
      .def_property_readonly(
          "seed",
          [](const ReferenceHandle& r) -> py::object {
            return r.reference.info.seed_known ? py::cast(r.reference.info.seed) : py::none();
          })
      .def_property_readonly("estimated_relmse", [](const ReferenceHandle& r) { return r.reference.info.estimated_relmse; },
                             "The reference's own noise as relMSE.")
      .def_property_readonly("has_variance", [](const ReferenceHandle& r) { return r.reference.has_variance(); })
      .def_property_readonly(
          "mean",
          [](const py::object& self) {
            const Reference& r = reference_of(self).reference;
            return view<float>(r.rgb.data(), {r.height, r.width, 3}, self);
          })
      .def_property_readonly(
          "variance",
          [](const py::object& self) -> py::object {
            const Reference& r = reference_of(self).reference;
            if (!r.has_variance()) return py::none();
            return view<float>(r.variance.data(), {r.height, r.width, 3}, self);
          })
      .def(
          "save", [](const ReferenceHandle& r, const std::string& path) { save_reference(path, r.reference); },
          py::arg("path"), "Writes PATH.pfm with its .var.pfm and .json beside it.")
      .def("__repr__", [](const ReferenceHandle& r) {
        char text[512];
        std::snprintf(text, sizeof text, "Reference('%s', %dx%d, %u spp, est. relMSE %.3g)", r.reference.path.c_str(),
                      r.reference.width, r.reference.height, r.reference.info.spp, r.reference.info.estimated_relmse);
        return std::string(text);
      });

  py::class_<ReferenceBuildHandle>(m, "_ReferenceBuild")
      .def(py::init<const SceneHandle&, std::optional<std::int64_t>, std::optional<double>, std::optional<double>,
                    const std::string&, std::int64_t, std::optional<int>, std::optional<int>, std::optional<int>, int,
                    const std::string&, const std::string&, int>(),
           py::arg("scene"), py::arg("spp"), py::arg("seconds"), py::arg("target_relmse"), py::arg("strategy"),
           py::arg("seed_stream"), py::arg("width"), py::arg("height"), py::arg("max_depth"), py::arg("threads"),
           py::arg("cache_dir"), py::arg("out"), py::arg("rr"))
      .def("poll", &ReferenceBuildHandle::poll)
      .def("finish", &ReferenceBuildHandle::finish);

  m.def(
      "_cached_reference",
      [](const SceneHandle& handle, std::optional<int> width, std::optional<int> height, std::optional<int> max_depth,
         const std::string& cache_dir) {
        const auto scene = sized_scene(handle, width, height, max_depth);
        return ReferenceHandle{resolve_reference("auto", *scene, handle.origin, cache_dir, true, true)};
      },
      py::arg("scene"), py::arg("width"), py::arg("height"), py::arg("max_depth"), py::arg("cache_dir"));

  m.def("reference_cache_dir", [](const std::string& option) { return reference_cache_dir(option); },
        py::arg("cache_dir") = "", "Where references are cached ($PDFLAB_REFERENCE_CACHE, else the user's cache).");

  m.def(
      "_relmse",
      [](const py::object& film_object, const py::object& ref, const std::string& cache_dir) {
        FilmHandle& film = film_object.cast<FilmHandle&>();
        ReferenceFor found;
        reference_for(ref, film, cache_dir, found);
        const Reference& reference = *found.reference;
        if (reference.width != film.film.width() || reference.height != film.film.height())
          throw InputError("reference '" + reference.path + "' is " + std::to_string(reference.width) + "x" +
                           std::to_string(reference.height) + " but the render is " + std::to_string(film.film.width()) +
                           "x" + std::to_string(film.film.height()) + " (use --width/--height)");
        const Strategy strategy = Strategy::parse(film.info.strategy);
        for (const SampleRange& range : film.info.ranges)
          if (const std::string shared = shared_random_numbers(reference.info, range.seed, strategy); !shared.empty())
            throw InputError("reference '" + reference.path + "': " + shared + "; choose another --seed");
        const std::vector<float>& mean = film.mean_rgb();
        RelMseMeasure measure;
        {
          py::gil_scoped_release release;
          measure = measure_relmse(mean, reference.rgb, reference.variance);
        }
        py::dict d = relmse_dict(measure, film.seconds);
        d["reference"] = reference.path;
        return d;
      },
      py::arg("film"), py::arg("reference"), py::arg("cache_dir"));

  m.def(
      "_sweep",
      [](const SceneHandle& handle, const std::string& vary, const std::string& weights, const std::string& strategy,
         std::optional<double> seconds, std::optional<std::int64_t> spp, const std::string& reference,
         std::optional<int> width, std::optional<int> height, const std::string& cache_dir, int seeds,
         std::uint64_t seed, int threads, int roulette_depth, bool auto_weight, bool cpu_time, const std::string& plot,
         const std::string& map, bool quiet) {
        if (spp && (*spp < 1 || *spp > (std::int64_t{1} << 30))) throw InputError("spp must be in 1..1073741824");
        if (roulette_depth != 0 && (roulette_depth < 1 || roulette_depth > kMaxRouletteDepth))
          throw InputError("rr must be in 1.." + std::to_string(kMaxRouletteDepth));
        if (width && (*width < 1 || *width > kMaxImageSide)) throw InputError("width must be in 1..16384");
        if (height && (*height < 1 || *height > kMaxImageSide)) throw InputError("height must be in 1..16384");
        const TempDir temp;
        SweepOptions o;
        o.scene = handle.file_for_commands(temp.path());
        o.vary = vary;
        o.weights = weights;
        o.strategy = strategy;
        o.roulette_depth = roulette_depth;
        o.seconds = seconds.value_or(0.0);
        o.spp = spp ? static_cast<std::uint32_t>(*spp) : 0u;
        o.reference = reference;
        o.width = width.value_or(0);
        o.height = height.value_or(0);
        o.cache_dir = cache_dir;
        o.seeds = seeds;
        o.seed = seed;
        o.csv = (fs::path(temp.path()) / "sweep.csv").string();
        o.plot = plot;
        o.map = map;
        o.threads = threads;
        o.quiet = quiet;
        o.auto_weight = auto_weight;
        o.cpu_time = cpu_time;
        const std::string table = interruptible([&] {
          py::gil_scoped_release release;
          return capture_stdout(temp.path(), [&] { (void)run_sweep(o); });
        });
        return py::make_tuple(read_text(o.csv), table);
      },
      py::arg("scene"), py::arg("vary"), py::arg("weights"), py::arg("strategy"), py::arg("seconds"), py::arg("spp"),
      py::arg("reference"), py::arg("width"), py::arg("height"), py::arg("cache_dir"), py::arg("seeds"), py::arg("seed"),
      py::arg("threads"), py::arg("rr"), py::arg("auto"), py::arg("cpu_time"), py::arg("plot"), py::arg("map"),
      py::arg("quiet"));

  m.def(
      "_predict_weights",
      [](const SceneHandle& handle, const std::string& vary, const std::string& base, double weight, std::int64_t spp,
         std::uint64_t seed, const std::string& reference_option, std::optional<int> width, std::optional<int> height,
         const std::string& cache_dir, int grid_points, int threads, int roulette_depth) {
        if (spp < 1 || spp > (std::int64_t{1} << 30)) throw InputError("spp must be in 1..1073741824");
        if (grid_points < 2 || grid_points > 10001) throw InputError("grid must be in 2..10001 points");
        if (threads < 0 || threads > 1024) throw InputError("threads must be in 0..1024 (0: all cores)");
        if (roulette_depth != 0 && (roulette_depth < 1 || roulette_depth > kMaxRouletteDepth))
          throw InputError("rr must be in 1.." + std::to_string(kMaxRouletteDepth));
        const TechniquePair pair = parse_technique_pair(vary, base, roulette_depth);
        if (!(weight >= 0.0 && weight <= 1.0) || defended_weight(weight) != weight) {
          char range[64];
          std::snprintf(range, sizeof range, "[%.2g, %.2g]", kDefensiveFloor, 1.0 - kDefensiveFloor);
          throw InputError("weight " + std::to_string(weight) + ": the paths must be drawn at a share of " + pair.a +
                           " inside " + range + " to predict the whole range from");
        }
        const Strategy pilot = pair.at(weight);
        auto scene = std::make_shared<Scene>(*handle.scene);
        (void)SamplingPlan::make(pilot, *scene);
        const Reference reference = comparison_reference(
            *scene, {reference_option, handle.origin, cache_dir, width.value_or(0), height.value_or(0)}, {pilot},
            {seed}, true);
        std::vector<double> grid = weight_grid(grid_points);
        grid.push_back(weight);
        std::sort(grid.begin(), grid.end());
        grid.erase(std::unique(grid.begin(), grid.end()), grid.end());

        WeightPrediction p;
        double seconds_per_sample = 0.0;
        std::uint32_t pilot_spp = 0;
        CostModel model;
        interruptible([&] {
          py::gil_scoped_release release;
          // The pilot's time per sample from a render of its paths (the packet
          // tracer, as any render); then the same samples replayed for their
          // vertices, as `bench --predict` does.
          const MeasuredRun run =
              render_measured(scene, pilot, seed, {0.0, static_cast<std::uint32_t>(spp), threads, 0}, "", false);
          pilot_spp = run.stats.spp;
          seconds_per_sample = run.stats.seconds / std::max<std::uint32_t>(1, run.stats.spp);
          WeightPathOptions po;
          po.seed = seed;
          po.samples = std::min<std::uint32_t>(run.stats.spp, 256);
          po.threads = threads;
          const WeightPredictor predictor = record_weight_paths(*scene, pair.mixture_family(), pilot, weight, grid, po);
          p = predictor.predict(reference.rgb, seconds_per_sample, kRelMseEpsilon);
          // One pilot's timing cannot tell a fixed cost per sample from a
          // cost per ray: its time is split with the prior fixed cost, as auto
          // weight's first pass is.
          model = anchored_cost_model(p.sampling_cost, seconds_per_sample, AutoWeight::kPriorOffset);
          if (model.per_ray > 0.0) apply_cost_model(p, model);
        });
        py::dict d;
        d["weight"] = p.weight;
        std::vector<std::string> strategies;
        for (double w : p.weight) strategies.push_back(pair.at(w).to_string());
        d["strategy"] = strategies;
        d["relative_variance"] = p.relative_variance;
        d["rays_per_sample"] = p.cost;
        d["efficiency"] = p.efficiency;
        d["largest_share"] = p.largest_share;
        d["best_weight"] = p.best_weight();
        d["paths"] = p.paths;
        d["pilot_weight"] = weight;
        d["pilot_strategy"] = pilot.to_string();
        d["pilot_spp"] = pilot_spp;
        d["seconds_per_sample"] = seconds_per_sample;
        d["cost_per_sample"] = model.per_sample;
        d["cost_per_ray"] = model.per_ray;
        d["technique_a"] = pair.a;
        d["technique_b"] = pair.b;
        d["reference"] = reference.path;
        return d;
      },
      py::arg("scene"), py::arg("vary"), py::arg("strategy"), py::arg("weight"), py::arg("spp"), py::arg("seed"),
      py::arg("reference"), py::arg("width"), py::arg("height"), py::arg("cache_dir"), py::arg("grid"),
      py::arg("threads"), py::arg("rr"));
}

}  // namespace pdflab::python
