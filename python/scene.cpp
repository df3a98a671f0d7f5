// pdflab.Scene and its Camera.
#include "python/bindings.h"

#include "app/assets.h"
#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/scene/scene_loader.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace pdflab::python {

namespace {

namespace fs = std::filesystem;

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The camera's keys a Python user may set, as the scene format names them.
const char* const kCameraKeys[] = {"lookfrom", "lookat", "vup", "vfov", "width", "height"};

py::list vec3(const Vec3& v) {
  py::list l;
  l.append(static_cast<double>(v.x));
  l.append(static_cast<double>(v.y));
  l.append(static_cast<double>(v.z));
  return l;
}

// A view of one scene's camera: reading gives the scene's values, setting one
// changes the scene (Scene.camera, below).
struct CameraView {
  std::shared_ptr<SceneHandle> scene;
  const Camera& camera() const { return scene->scene->camera; }
};

nlohmann::json to_json(const py::handle& value) {
  return nlohmann::json::parse(py::module_::import("json").attr("dumps")(value).cast<std::string>());
}

void set_camera_key(CameraView& c, const char* key, const py::object& value) {
  nlohmann::json changes;
  changes[key] = to_json(value);
  c.scene->set_camera(changes);
}

}  // namespace

// The document as edited and loaded again: an environment map's relative path
// made absolute (it started from the file's folder, and an edited document is
// written elsewhere for the commands: file_for_commands).
std::string SceneHandle::reload(nlohmann::json doc) {
  if (from_file && doc.contains("environment") && doc["environment"].is_object() &&
      doc["environment"].contains("file") && doc["environment"]["file"].is_string()) {
    const fs::path file = doc["environment"]["file"].get<std::string>();
    if (file.is_relative()) doc["environment"]["file"] = fs::absolute(fs::path(origin).parent_path() / file).string();
  }
  std::string edited_text = doc.dump(2);
  scene = std::make_shared<const Scene>(load_scene_text(edited_text, origin));
  return edited_text;
}

std::shared_ptr<SceneHandle> SceneHandle::load(const std::string& path) {
  auto h = std::make_shared<SceneHandle>();
  h->scene = std::make_shared<const Scene>(load_scene_file(path));  // the command line's checks and messages
  h->origin = path;
  h->from_file = true;
  h->text = read_text(path);
  return h;
}

std::shared_ptr<SceneHandle> SceneHandle::from_text(const std::string& text, const std::string& origin) {
  auto h = std::make_shared<SceneHandle>();
  h->scene = std::make_shared<const Scene>(load_scene_text(text, origin));
  h->origin = origin;
  h->text = text;
  return h;
}

void SceneHandle::set_camera(const nlohmann::json& changes) {
  nlohmann::json doc = nlohmann::json::parse(text);
  for (auto it = changes.begin(); it != changes.end(); ++it) {
    if (std::find_if(std::begin(kCameraKeys), std::end(kCameraKeys), [&](const char* k) { return it.key() == k; }) ==
        std::end(kCameraKeys))
      throw InputError("camera: unknown key '" + it.key() + "' (lookfrom, lookat, vup, vfov, width, height)");
    doc["camera"][it.key()] = it.value();
  }
  text = reload(std::move(doc));
  edited = true;
}

std::string SceneHandle::file_for_commands(const std::string& folder) const {
  if (from_file && !edited) return origin;
  const std::string path = (fs::path(folder) / "scene.json").string();
  write_file_atomic(path, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
  return path;
}

void bind_scene(py::module_& m) {
  py::class_<CameraView>(m, "Camera",
                         "A scene's camera. Setting a value changes the scene (and so its reference cache key).")
      .def_property(
          "lookfrom", [](const CameraView& c) { return vec3(c.camera().lookfrom); },
          [](CameraView& c, const py::object& v) { set_camera_key(c, "lookfrom", v); })
      .def_property(
          "lookat", [](const CameraView& c) { return vec3(c.camera().lookat); },
          [](CameraView& c, const py::object& v) { set_camera_key(c, "lookat", v); })
      .def_property(
          "vup", [](const CameraView& c) { return vec3(c.camera().vup); },
          [](CameraView& c, const py::object& v) { set_camera_key(c, "vup", v); })
      .def_property(
          "vfov", [](const CameraView& c) { return static_cast<double>(c.camera().vfov_degrees); },
          [](CameraView& c, const py::object& v) { set_camera_key(c, "vfov", v); })
      .def_property(
          "width", [](const CameraView& c) { return c.camera().width; },
          [](CameraView& c, const py::object& v) { set_camera_key(c, "width", v); })
      .def_property(
          "height", [](const CameraView& c) { return c.camera().height; },
          [](CameraView& c, const py::object& v) { set_camera_key(c, "height", v); })
      .def("to_dict",
           [](const CameraView& c) {
             py::dict d;
             for (const char* key : kCameraKeys) d[key] = py::cast(c).attr(key);
             return d;
           })
      .def("__repr__", [](const CameraView& c) {
        const Camera& cam = c.camera();
        std::ostringstream s;
        s << "Camera(lookfrom=[" << cam.lookfrom.x << ", " << cam.lookfrom.y << ", " << cam.lookfrom.z << "], lookat=["
          << cam.lookat.x << ", " << cam.lookat.y << ", " << cam.lookat.z << "], vfov=" << cam.vfov_degrees
          << ", width=" << cam.width << ", height=" << cam.height << ")";
        return s.str();
      });

  py::class_<SceneHandle, std::shared_ptr<SceneHandle>>(m, "Scene", R"(A scene (docs/scene_format.md).

Scene.load(path) reads a scene file, Scene.from_dict(d) takes the same JSON as
a dict. width, height, max_depth and camera are properties; setting one edits
the scene's document and loads it again, so bad values get the scene loader's
messages (ValueError).)")
      .def_static("load", &SceneHandle::load, py::arg("path"), "Reads a scene file (JSON).")
      .def_static(
          "from_dict",
          [](const py::dict& d, const std::string& origin) {
            return SceneHandle::from_text(py::module_::import("json").attr("dumps")(d, py::arg("indent") = 2).cast<std::string>(),
                                          origin);
          },
          py::arg("d"), py::arg("origin") = "<dict>", "A scene from the scene file's JSON as a dict.")
      .def_static("from_json", &SceneHandle::from_text, py::arg("text"), py::arg("origin") = "<string>",
                  "A scene from the scene file's JSON text.")
      .def_property_readonly("name", [](const SceneHandle& s) { return s.scene->name; })
      .def_property_readonly(
          "path", [](const SceneHandle& s) -> py::object { return s.from_file ? py::cast(s.origin) : py::none(); },
          "The file the scene was read from (None for a dict).")
      .def_property_readonly("edited", [](const SceneHandle& s) { return s.edited; },
                             "Whether the camera, size or depth was changed since the scene was read.")
      .def_property_readonly("content_hash", [](const SceneHandle& s) { return s.scene->content_hash; },
                             "The reference cache's key for the scene's content (without size and depth).")
      .def_property(
          "width", [](const SceneHandle& s) { return s.scene->camera.width; },
          [](SceneHandle& s, int w) { s.set_camera({{"width", w}}); })
      .def_property(
          "height", [](const SceneHandle& s) { return s.scene->camera.height; },
          [](SceneHandle& s, int h) { s.set_camera({{"height", h}}); })
      .def_property(
          "size", [](const SceneHandle& s) { return py::make_tuple(s.scene->camera.width, s.scene->camera.height); },
          [](SceneHandle& s, const std::pair<int, int>& wh) { s.set_camera({{"width", wh.first}, {"height", wh.second}}); },
          "(width, height) in pixels.")
      .def_property(
          "max_depth", [](const SceneHandle& s) { return s.scene->max_depth; },
          [](SceneHandle& s, int depth) {
            nlohmann::json doc = nlohmann::json::parse(s.text);
            doc["camera"]["max_depth"] = depth;
            s.text = s.reload(std::move(doc));
            s.edited = true;
          })
      .def_property(
          "camera", [](const std::shared_ptr<SceneHandle>& s) { return CameraView{s}; },
          [](SceneHandle& s, const py::object& value) {
            const py::object d = py::isinstance<CameraView>(value) ? value.attr("to_dict")() : value;
            if (!py::isinstance<py::dict>(d)) throw py::type_error("camera: give a dict or a Camera");
            s.set_camera(to_json(d));
          },
          "The camera; assign a dict (or another scene's Camera) to change several values at once.")
      .def("to_dict", [](const SceneHandle& s) { return py::module_::import("json").attr("loads")(s.text); },
           "The scene's JSON document as a dict.")
      .def("copy",
           [](const SceneHandle& s) { return std::make_shared<SceneHandle>(s); },
           "An independent copy (changing one leaves the other alone).")
      .def("__repr__", [](const SceneHandle& s) {
        const Camera& c = s.scene->camera;
        return "Scene('" + s.scene->name + "', " + std::to_string(c.width) + "x" + std::to_string(c.height) +
               ", depth " + std::to_string(s.scene->max_depth) + (s.from_file ? ", from '" + s.origin + "'" : "") + ")";
      });

  m.def("asset_dir", &asset_dir, "The folder of the shipped files (scenes/).");
  m.def(
      "scene_path",
      [](const std::string& name) {
        const fs::path p = fs::path(asset_dir()) / "scenes" / (name + ".json");
        std::error_code ec;
        if (!fs::is_regular_file(p, ec))
          throw InputError("no shipped scene '" + name + "' in '" + (fs::path(asset_dir()) / "scenes").string() + "'");
        return p.string();
      },
      py::arg("name"), "The path of a shipped scene, e.g. scene_path('cornell_book').");
  m.def("scenes", [] {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fs::path(asset_dir()) / "scenes", ec))
      if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
    std::sort(names.begin(), names.end());
    return names;
  }, "The names of the shipped scenes.");
}

}  // namespace pdflab::python
