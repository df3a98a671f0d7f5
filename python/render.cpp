// Rendering: the handle that pdflab.render waits on, and pdflab.Film.
#include "python/bindings.h"

#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/metrics/metrics.h"
#include "renderer/sampling/strategy.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

namespace pdflab::python {

namespace {

Transfer parse_transfer(const std::string& text) {
  if (text == "gamma2") return Transfer::Gamma2;
  if (text == "srgb") return Transfer::Srgb;
  throw InputError("--transfer must be 'gamma2' or 'srgb', not '" + text + "'");
}

bool is_film_file(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".film";
}

py::dict drops_dict(const DropCounts& dropped) {
  py::dict d;
  d["total"] = dropped.total();
  for (int r = 0; r < kDropReasonCount; ++r)
    d[py::str(std::string(drop_reason_name(static_cast<DropReason>(r))))] = dropped.by_reason[static_cast<std::size_t>(r)];
  return d;
}

// pdflab.render's checks, in the command line's order and with its messages
// where it has one (the flags it names are the keyword arguments here).
void check_count(const char* name, std::int64_t value, std::int64_t lo, std::int64_t hi) {
  if (value < lo || value > hi)
    throw InputError(std::string(name) + " must be in " + std::to_string(lo) + ".." + std::to_string(hi) + ", not " +
                     std::to_string(value));
}

// A render in progress: a session with the command line's settings for a
// headless render, which pdflab.render polls (the GIL released meanwhile)
// until the target spp or the time limit, or until Ctrl+C stops it between
// passes.
class RenderHandle {
 public:
  RenderHandle(const SceneHandle& scene_handle, const std::string& strategy_text, std::optional<std::int64_t> spp,
               std::optional<double> seconds, std::uint64_t seed, std::optional<int> width, std::optional<int> height,
               int threads, std::int64_t first_sample, int roulette_depth) {
    if (!spp && !seconds) throw InputError("give spp, seconds or both");
    if (spp) check_count("spp", *spp, 1, std::int64_t{1} << 30);
    if (seconds && !(std::isfinite(*seconds) && *seconds > 0.0))
      throw InputError("seconds must be a positive number of seconds");
    check_count("first_sample", first_sample, 0, std::numeric_limits<std::uint32_t>::max());
    if (width) check_count("width", *width, 1, kMaxImageSide);
    if (height) check_count("height", *height, 1, kMaxImageSide);
    if (threads < 0 || threads > 1024) throw InputError("threads must be in 0..1024 (0: all cores)");
    if (roulette_depth != 0) check_count("rr", roulette_depth, 1, kMaxRouletteDepth);

    auto scene = std::make_shared<Scene>(*scene_handle.scene);
    if (width) scene->camera.width = *width;
    if (height) scene->camera.height = *height;
    if (width || height) check_image_size(scene->camera.width, scene->camera.height, "--width/--height");
    scene->prepare();
    strategy_ = for_scene(with_roulette(Strategy::parse(strategy_text), roulette_depth), *scene);
    (void)SamplingPlan::make(strategy_, *scene);  // strategy/scene mismatch is bad input too

    target_spp_ = spp ? static_cast<std::uint32_t>(*spp) : 0;
    seconds_limit_ = seconds ? *seconds : 0.0;
    seed_ = seed;
    first_sample_ = static_cast<std::uint32_t>(first_sample);
    if (std::uint64_t{first_sample_} + target_spp_ > std::numeric_limits<std::uint32_t>::max())
      throw InputError("--first-sample " + std::to_string(first_sample_) + " plus --spp " + std::to_string(target_spp_) +
                       " passes the last sample index (" +
                       std::to_string(std::numeric_limits<std::uint32_t>::max()) + ")");

    info_.scene_hash = film_scene_hash(*scene);
    info_.scene_file = scene_handle.origin;
    info_.width = scene->camera.width;
    info_.height = scene->camera.height;
    info_.max_depth = scene->max_depth;
    info_.strategy = strategy_.to_string();
    scene_ = scene;

    SessionOptions options;
    options.threads = threads;
    options.publish_images = false;  // the film is read once, at the end
    session_ = std::make_unique<RenderSession>(options);
    RenderSettings settings;
    settings.scene = scene_;
    settings.strategy = strategy_;
    settings.seed = seed_;
    settings.target_spp = target_spp_;
    settings.first_sample = first_sample_;
    session_->set_settings(settings);
  }

  // Waits up to `timeout` seconds; true once the render is over (its spp
  // reached, or its time: then it is paused after the pass in flight).
  bool wait(double timeout) {
    py::gil_scoped_release release;
    auto ms = std::chrono::milliseconds(std::max<std::int64_t>(1, std::llround(timeout * 1e3)));
    if (seconds_limit_ > 0.0) {
      const double left = seconds_limit_ - session_->stats().seconds;
      ms = std::min(ms, std::chrono::milliseconds(std::max<std::int64_t>(1, std::llround(left * 1e3))));
    }
    if (session_->wait_until_done(ms)) return true;
    if (seconds_limit_ > 0.0 && session_->stats().seconds >= seconds_limit_) {
      session_->set_paused(true);
      time_up_ = true;
      return true;
    }
    return false;
  }

  py::dict stats() const {
    const SessionStats st = session_->stats();
    py::dict d;
    d["spp"] = st.spp;
    d["target_spp"] = target_spp_;
    d["seconds"] = st.seconds;
    d["seconds_limit"] = seconds_limit_;
    d["samples"] = st.samples;
    d["samples_per_second"] = st.samples_per_second;
    double progress = st.progress;
    if (seconds_limit_ > 0.0) progress = std::max(progress, std::min(1.0, st.seconds / seconds_limit_));
    d["progress"] = progress;
    d["threads"] = session_->thread_count();
    return d;
  }

  bool unbiased() const { return strategy_.is_unbiased(); }
  std::string strategy() const { return strategy_.to_string(); }

  // The film of the complete passes: a render stopped early (Ctrl+C) is
  // paused first, and keeps every pass that had ended.
  FilmHandle finish(bool interrupted) {
    FilmHandle f;
    {
      py::gil_scoped_release release;
      session_->set_paused(true);
      f.film = session_->take_film();  // waits for the pass in flight
    }
    const SessionStats st = session_->stats();
    f.info = info_;
    f.info.ranges = {SampleRange{seed_, first_sample_, first_sample_ + st.spp}};
    f.info.dropped = st.dropped;
    f.info.seconds = st.seconds;
    f.scene = scene_;
    f.seconds = st.seconds;
    f.samples = st.samples;
    f.samples_per_second = st.samples_per_second;
    f.threads = session_->thread_count();
    f.target_spp = target_spp_;
    f.interrupted = interrupted;
    f.time_up = time_up_;
    session_.reset();  // the workers go now, not when Python collects the handle
    return f;
  }

 private:
  std::shared_ptr<const Scene> scene_;
  Strategy strategy_;
  FilmInfo info_;
  std::uint64_t seed_ = 1;
  std::uint32_t first_sample_ = 0, target_spp_ = 0;
  double seconds_limit_ = 0.0;
  bool time_up_ = false;
  std::unique_ptr<RenderSession> session_;
};

FilmHandle& film_of(const py::object& self) { return self.cast<FilmHandle&>(); }

}  // namespace

const std::vector<float>& FilmHandle::mean_rgb() {
  if (mean.empty() && film.pixel_count() > 0) film.mean_rgb(mean);
  return mean;
}

void bind_render(py::module_& m) {
  py::class_<RenderHandle>(m, "_Render")
      .def(py::init<const SceneHandle&, const std::string&, std::optional<std::int64_t>, std::optional<double>,
                    std::uint64_t, std::optional<int>, std::optional<int>, int, std::int64_t, int>(),
           py::arg("scene"), py::arg("strategy"), py::arg("spp"), py::arg("seconds"), py::arg("seed"), py::arg("width"),
           py::arg("height"), py::arg("threads"), py::arg("first_sample"), py::arg("rr"))
      .def("wait", &RenderHandle::wait, py::arg("timeout"))
      .def("stats", &RenderHandle::stats)
      .def_property_readonly("unbiased", &RenderHandle::unbiased)
      .def_property_readonly("strategy", &RenderHandle::strategy)
      .def("finish", &RenderHandle::finish, py::arg("interrupted"));

  py::class_<FilmHandle>(m, "Film", R"(A render's accumulation (pdflab.render, or Film.load of a film file).

mean, variance (of the mean) and count are numpy arrays of H x W x 3 (float32,
float64) and H x W (uint32); count, sums and squares are views of the film
itself, mean and variance are computed once and kept. save(path) writes .png,
.pfm, .hdr, .exr (as `pdflab render --out`) or .film (as --film-out).)")
      .def_static(
          "load",
          [](const std::string& path) {
            FilmFile file = read_film_file(path);
            FilmHandle f;
            f.film = std::move(file.film);
            f.info = std::move(file.info);
            f.seconds = f.info.seconds;
            f.samples = f.info.spp() * f.film.pixel_count();
            f.samples_per_second = f.seconds > 0.0 ? static_cast<double>(f.samples) / f.seconds : 0.0;
            return f;
          },
          py::arg("path"), "Reads a film file (render --film-out, merge, the viewer's Ctrl+S).")
      .def_property_readonly("width", [](const FilmHandle& f) { return f.film.width(); })
      .def_property_readonly("height", [](const FilmHandle& f) { return f.film.height(); })
      .def_property_readonly("spp", [](const FilmHandle& f) { return f.info.spp(); },
                             "Samples per pixel in the film (complete passes).")
      .def_property_readonly("target_spp", [](const FilmHandle& f) { return f.target_spp; })
      .def_property_readonly("seconds", [](const FilmHandle& f) { return f.seconds; }, "Rendering time.")
      .def_property_readonly("samples", [](const FilmHandle& f) { return f.samples; })
      .def_property_readonly("samples_per_second", [](const FilmHandle& f) { return f.samples_per_second; })
      .def_property_readonly("threads", [](const FilmHandle& f) { return f.threads; })
      .def_property_readonly("dropped", [](const FilmHandle& f) { return drops_dict(f.info.dropped); },
                             "Samples dropped as invalid, by reason, and their total.")
      .def_property_readonly("strategy", [](const FilmHandle& f) { return f.info.strategy; })
      .def_property_readonly("unbiased", [](const FilmHandle& f) { return Strategy::parse(f.info.strategy).is_unbiased(); })
      .def_property_readonly(
          "seed",
          [](const FilmHandle& f) -> py::object {
            return f.info.ranges.size() == 1 ? py::cast(f.info.ranges.front().seed) : py::none();
          })
      .def_property_readonly(
          "first_sample",
          [](const FilmHandle& f) -> py::object {
            return f.info.ranges.size() == 1 ? py::cast(f.info.ranges.front().first) : py::none();
          })
      .def_property_readonly("samples_text", [](const FilmHandle& f) { return f.info.ranges_text(); })
      .def_property_readonly("scene_file", [](const FilmHandle& f) { return f.info.scene_file; })
      .def_property_readonly("max_depth", [](const FilmHandle& f) { return f.info.max_depth; })
      .def_property_readonly("interrupted", [](const FilmHandle& f) { return f.interrupted; },
                             "Stopped by Ctrl+C (or the kernel's stop) before its spp: it holds the passes that ended.")
      .def_property_readonly("time_up", [](const FilmHandle& f) { return f.time_up; },
                             "Stopped by its time limit (seconds=).")
      .def_property_readonly("estimated_relmse", [](const FilmHandle& f) { return estimated_relmse(f.film); },
                             "The film's own relMSE estimate: a lower bound, blind to light its samples never found.")
      .def_property_readonly(
          "mean",
          [](const py::object& self) {
            FilmHandle& f = film_of(self);
            const std::vector<float>& rgb = f.mean_rgb();
            return view<float>(rgb.data(), {f.film.height(), f.film.width(), 3}, self);
          },
          "Mean radiance, H x W x 3 float32: the very values `render --out x.pfm` writes (row 0 at the top).")
      .def_property_readonly(
          "variance",
          [](const py::object& self) {
            FilmHandle& f = film_of(self);
            if (f.variance.empty() && f.film.pixel_count() > 0) {
              f.variance.resize(3 * f.film.pixel_count());
              for (std::size_t p = 0; p < f.film.pixel_count(); ++p) f.film.variance_of_mean(p, &f.variance[3 * p]);
            }
            return view<double>(f.variance.data(), {f.film.height(), f.film.width(), 3}, self);
          },
          "Variance of the mean per pixel and channel, H x W x 3 float64 (EXR's variance layers).")
      .def_property_readonly(
          "count",
          [](const py::object& self) {
            FilmHandle& f = film_of(self);
            return view<std::uint32_t>(f.film.counts().data(), {f.film.height(), f.film.width()}, self);
          },
          "Samples per pixel, H x W uint32 (a view of the film).")
      .def_property_readonly(
          "sums",
          [](const py::object& self) {
            FilmHandle& f = film_of(self);
            return view<double>(f.film.sums().data(), {f.film.height(), f.film.width(), 3}, self);
          },
          "Sum of the samples per pixel and channel, H x W x 3 float64 (a view of the film).")
      .def_property_readonly(
          "squares",
          [](const py::object& self) {
            FilmHandle& f = film_of(self);
            return view<double>(f.film.squares().data(), {f.film.height(), f.film.width(), 3}, self);
          },
          "Sum of the squared samples, H x W x 3 float64 (a view of the film).")
      .def_property_readonly(
          "drop_mask",
          [](const py::object& self) {
            FilmHandle& f = film_of(self);
            return view<std::uint8_t>(f.film.drop_masks().data(), {f.film.height(), f.film.width()}, self);
          },
          "Which drop reasons occurred per pixel (bit r for reason r), H x W uint8.")
      .def(
          "save",
          [](FilmHandle& f, const std::string& path, const std::string& transfer) {
            if (is_film_file(path)) {
              check_output_path(path);
              py::gil_scoped_release release;
              write_film_file(path, f.info, f.film);
              return;
            }
            (void)image_format_for(path);
            check_output_path(path);
            const Transfer t = parse_transfer(transfer);
            py::gil_scoped_release release;
            write_film_image(path, f.film, t, film_image_attributes(f.info, PDFLAB_VERSION));
          },
          py::arg("path"), py::arg("transfer") = "gamma2",
          "Writes .png (tone-mapped), .pfm (the linear mean), .hdr, .exr (mean, variance and count layers) as "
          "`render --out` does, or a .film file as `--film-out` does (for --resume and merge). Atomic.")
      .def("__repr__", [](const FilmHandle& f) {
        char text[256];
        std::snprintf(text, sizeof text, "Film('%s', %dx%d, %llu spp, %.3g s%s%s)", f.info.strategy.c_str(),
                      f.film.width(), f.film.height(), static_cast<unsigned long long>(f.info.spp()), f.seconds,
                      f.interrupted ? ", interrupted" : "", f.time_up ? ", time up" : "");
        return std::string(text);
      });

  m.def(
      "tonemap",
      [](const py::array_t<float, py::array::c_style | py::array::forcecast>& rgb, const std::string& transfer,
         double exposure) {
        const Transfer t = parse_transfer(transfer);
        if (rgb.ndim() < 1 || rgb.shape(rgb.ndim() - 1) != 3) throw InputError("tonemap: the last axis must be RGB (3)");
        std::vector<py::ssize_t> shape(rgb.shape(), rgb.shape() + rgb.ndim());
        py::array_t<std::uint8_t> out(shape);
        const float* in = rgb.data();
        std::uint8_t* o = out.mutable_data();
        const auto n = static_cast<std::size_t>(rgb.size());
        const auto e = static_cast<float>(exposure);
        for (std::size_t i = 0; i < n; ++i) o[i] = tone_map_channel(in[i], t, e);
        return out;
      },
      py::arg("rgb"), py::arg("transfer") = "gamma2", py::arg("exposure") = 1.0,
      "Linear RGB (... x 3) to 8-bit as the PNG writer maps it (gamma2: the book's square root, or srgb).");
}

}  // namespace pdflab::python
