#pragma once
// The Python module's C++ side (_pdflab): thin handles over the renderer
// library and the headless commands. The package pdflab (python/pdflab/)
// wraps them with what is Python's business: the loop that waits for a render
// with its progress display and Ctrl+C, keyword arguments, and table types.
#include "renderer/film/film.h"
#include "renderer/film/film_file.h"
#include "renderer/metrics/reference.h"
#include "renderer/scene/scene.h"
#include "renderer/session/session.h"

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#ifndef PDFLAB_VERSION
#define PDFLAB_VERSION "unknown"
#endif

namespace pdflab::python {

namespace py = pybind11;

// A scene and the JSON document it was read from. Changing the camera or the
// size edits the document and loads it again, so the loader checks the new
// values with its own messages and the content hash (the reference cache's
// key) follows the camera.
struct SceneHandle {
  std::string origin;     // the file it was read from, or "<dict>"
  bool from_file = false;
  bool edited = false;    // changed since it was read: the file no longer describes it
  std::string text;       // the document
  std::shared_ptr<const Scene> scene;

  static std::shared_ptr<SceneHandle> load(const std::string& path);
  static std::shared_ptr<SceneHandle> from_text(const std::string& text, const std::string& origin);
  // Sets each key of `changes` in the document's "camera" and loads it again.
  void set_camera(const nlohmann::json& changes);
  // Loads the edited document `doc` into `scene` and returns its text.
  std::string reload(nlohmann::json doc);
  // A file holding this scene for the commands that read one (sweep): the
  // file it came from while unchanged, else the document in `folder`.
  std::string file_for_commands(const std::string& folder) const;
};

// A finished (or stopped) render's accumulation with what it is an estimate of.
struct FilmHandle {
  Film film;
  FilmInfo info;
  std::shared_ptr<const Scene> scene;  // null for a film read from a file
  double seconds = 0.0;
  std::uint64_t samples = 0;
  double samples_per_second = 0.0;
  int threads = 0;
  std::uint32_t target_spp = 0;  // 0: none (a time limit, or a film read from a file)
  bool interrupted = false;      // stopped by Ctrl+C between passes
  bool time_up = false;          // stopped by its time limit
  // Computed on first use and kept, so that the arrays handed out stay valid.
  std::vector<float> mean;
  std::vector<double> variance;
  const std::vector<float>& mean_rgb();
};

// Arrays over memory that `owner` (a Python object) keeps alive: no copy.
template <class T>
py::array_t<T> view(const T* data, std::vector<py::ssize_t> shape, const py::object& owner) {
  py::array_t<T> a(std::move(shape), data, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

void bind_scene(py::module_& m);
void bind_render(py::module_& m);
void bind_measuring(py::module_& m);
void bind_sampling(py::module_& m);
void bind_lab(py::module_& m);

}  // namespace pdflab::python
