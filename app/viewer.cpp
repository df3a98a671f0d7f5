#include "app/viewer.h"

#include "app/assets.h"
#include "app/teaching.h"
#include "app/viewer_references.h"
#include "app/viewer_weights.h"
#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/film/film_file.h"
#include "renderer/hash.h"
#include "renderer/metrics/probe.h"
#include "renderer/session/session.h"
#include "ui/camera_control.h"
#include "ui/display.h"
#include "ui/figure_export.h"
#include "ui/image_view.h"
#include "ui/layout_report.h"
#include "ui/measure_panel.h"
#include "ui/panels.h"
#include "ui/preferences.h"
#include "ui/screenshot.h"
#include "ui/view_texture.h"

// glad before GLFW: glad provides the GL declarations, GLFW must not.
#include <glad/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <imgui_internal.h>  // ClosePopupToLevel: Esc closes a drop-down; the active text field

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <future>
#include <optional>
#include <stdexcept>
#include <utility>

#include <time.h>

#ifndef PDFLAB_VERSION
#define PDFLAB_VERSION "unknown"
#endif

namespace pdflab {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kFramePeriod = 1.0 / 60.0;  // while something changes on screen
constexpr double kIdlePeriod = 0.25;         // paused or done: wake on input or now and then
constexpr const char* kUiFont = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

std::vector<std::string> list_scene_files() {
  std::vector<std::string> files;
  std::error_code ec;
  const fs::path dir = fs::path(asset_dir()) / "scenes";
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file(ec) && entry.path().extension() == ".json") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

bool all_zero(const Strategy& s) {
  return std::all_of(s.weights.begin(), s.weights.end(), [](float w) { return !(w > 0.0f); });
}

void glfw_error(int code, const char* message) { std::fprintf(stderr, "pdflab: GLFW error %d: %s\n", code, message); }

// The screenshot folder: $PDFLAB_SCREENSHOT_DIR, else ./screenshots, shown in
// the panel as an absolute path so that a user knows where the files go.
std::string default_screenshot_dir() {
  const char* env = std::getenv("PDFLAB_SCREENSHOT_DIR");
  const std::filesystem::path dir = env && *env ? env : "screenshots";
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(dir, ec);
  return (ec ? dir : absolute).string();
}

// A text field is being edited: keys are text then, never shortcuts. Asked
// after the frame's widgets, so a click that started the edit in this very
// frame counts (the IO's WantTextInput is the frame before's).
bool editing_text() {
  const ImGuiContext& g = *GImGui;
  return ImGui::GetIO().WantTextInput || (g.ActiveId != 0 && g.ActiveId == g.InputTextState.ID);
}

// The scene's content hash for a camera moved in the viewer: the scene file's
// hash and the camera's placement, so a reference of one view (the cache's
// key, a film's scene) is never taken for another's.
std::string view_hash(const std::string& scene_hash, const Camera& c) {
  char text[256];
  std::snprintf(text, sizeof text, "%s|%.9g %.9g %.9g|%.9g %.9g %.9g|%.9g %.9g %.9g|%.9g", scene_hash.c_str(),
                static_cast<double>(c.lookfrom.x), static_cast<double>(c.lookfrom.y), static_cast<double>(c.lookfrom.z),
                static_cast<double>(c.lookat.x), static_cast<double>(c.lookat.y), static_cast<double>(c.lookat.z),
                static_cast<double>(c.vup.x), static_cast<double>(c.vup.y), static_cast<double>(c.vup.z),
                static_cast<double>(c.vfov_degrees));
  return fnv1a_hex(text, std::strlen(text));
}

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

}  // namespace

struct Viewer::Impl {
  ViewerOptions options;
  GLFWwindow* window = nullptr;
  bool imgui_ready = false;
  std::unique_ptr<ui::ImageDisplay> display;
  std::unique_ptr<ui::ViewTexture> view_texture;
  ui::MeasureState measure;
  std::unique_ptr<RenderSession> session;
  std::unique_ptr<TeachingViews> teaching;
  std::unique_ptr<ViewerReferences> references;
  std::unique_ptr<WeightLab> weight_lab;
  // Auto weight: the chooser of this run, the spp of the next pass boundary,
  // the weights so far, and where the current weight's samples begin.
  struct AutoRun {
    bool on = false;
    AutoWeight chooser;
    std::uint32_t next_spp = 16;
    std::vector<float> history;
    std::uint64_t generation = ~std::uint64_t{0};
    std::uint32_t spp_before = 0;  // in the film from earlier weights
    double seconds_before = 0.0;   // their rendering time (the film's clock runs on)
  } auto_run;
  bool main_rests_for_reference = false;  // paused while a reference takes every thread

  std::shared_ptr<const Scene> base_scene;  // as loaded
  std::string scene_path;
  std::shared_ptr<const Scene> render_scene;  // with depth and resolution applied
  int render_scene_depth = -1;
  float render_scene_scale = -1.0f;
  bool render_scene_override = false;  // rendered at the reference's size

  ui::ViewerSettings settings;
  ui::ViewerSettings applied;  // what the session renders now
  ui::PanelState panel;
  ui::UiStatus status;

  std::vector<float> image;
  ImageInfo image_info;
  std::uint64_t image_version = 0;
  bool texture_stale = false;

  struct KeyPress {
    int key = 0, mods = 0;
  };
  std::vector<KeyPress> keys;  // pressed since the last frame, from the GLFW callback
  // Keys are acted on after the frame's widgets (see editing_text); until then here.
  std::vector<KeyPress> pending_keys;
  GLFWkeyfun imgui_key_callback = nullptr;  // ImGui's, which calls ours first
  struct Release {
    int key = 0, scancode = 0, mods = 0;
    bool seen = false;  // ImGui's NewFrame has seen the key down since
  };
  std::vector<int> pressed_this_frame;  // pressed since ImGui's last NewFrame
  std::vector<Release> deferred_releases;
  // Redrawing costs CPU time the render threads could use (and llvmpipe draws
  // on the CPU), so a frame is drawn only when something on it can change.
  std::uint64_t input_events = 0, seen_input_events = 0;
  int settle_frames = 2;  // ImGui needs a frame or two after input to settle hover and layout
  Clock::time_point last_draw{};

  bool screenshot_wanted = false;
  // Quitting: Ctrl+Q or the window's close button; asks first when a render
  // would be lost (see ui::unsaved_seconds).
  ui::SaveMark last_save;  // the last saved image's generation and seconds
  bool quit_asking = false;
  bool quit_after_save = false;
  bool close_popups = false;  // Esc with a drop-down open

  // Looking closely: zoom and pan (framebuffer pixels), the pixel under the cursor.
  ui::ImageView view;
  // Camera mode (O): the mouse moves the camera instead of the image.
  bool camera_mode = false;
  std::optional<Camera> camera;  // moved; none: the scene's own
  ui::Viewport last_area{};
  int pan_button = -1;  // the mouse button dragging the image, -1 none
  std::optional<ui::PixelReadout> inspected;
  std::future<ui::SavedScreenshot> save_job;
  ui::ScreenshotData saving;  // kept until the job reports, for a retry after failure
  std::optional<ui::ScreenshotData> failed_save;

  bool fonts_dirty = true;
  float content_scale = 1.0f;
  float ui_scale = 1.0f;  // the fonts' (settings.ui_scale is the wish)
  float scale() const { return content_scale * ui_scale; }
  // Presentation mode's full screen; the window's place to go back to.
  bool fullscreen = false;
  int windowed_x = 0, windowed_y = 0, windowed_w = 0, windowed_h = 0;
  double presentation_since = -1.0;
  float framebuffer_scale = 1.0f;

  // Remembered between runs (ui/preferences.h), when options.remember.
  std::string preferences_file;
  std::string layout_written;  // the layout report last written (--layout-json)

  FrameReport report;
  int exit_status = 0;
  bool cli_done = false;
  Clock::time_point started = Clock::now();

  double now() const { return std::chrono::duration<double>(Clock::now() - started).count(); }
  bool cli_mode() const { return !options.screenshot.empty(); }

  void open(const ViewerOptions& o);
  void close();
  void open_window(int image_width, int image_height);
  void rebuild_fonts();
  void on_key(int key, int mods);
  void handle_keys();
  void on_escape();
  void set_presentation(bool on);
  void reset_camera() {
    camera.reset();
    apply_render_settings();
  }
  bool move_camera(const ui::Viewport& area, bool over);
  void navigate(const ui::Viewport& area, int framebuffer_height);
  void inspect(const ui::ImageRect& image_rect, const ui::ImageRect& area_rect);
  void request_quit();
  double unsaved_seconds() const;
  bool apply_render_settings();
  void load_scene(const std::string& path);
  void pull_image();
  void service_screenshots();
  void start_save(ui::ScreenshotData data);
  ui::ScreenshotData capture() const;
  void notice(std::string text, bool error) {
    status.notice = {std::move(text), error, now()};
    settle_frames = 2;
  }
  void fill_status();
  std::vector<ui::PanelMessage> messages() const;
  void export_view();
  void export_curve();
  void export_convergence();
  void write_layout_report(int fb_w, int fb_h);
  void remember_preferences();
  void continue_film(const std::string& path);
  void save_film();
  std::uint32_t film_first_sample = 0;  // of the accumulation shown (0 unless a film was continued)
  void load_reference(const std::string& path);
  void after_reference_changed();
  void service_references();
  void handle_measure_requests(const ui::MeasureRequests& r);
  void service_weights();
  void service_auto_weight();
  void service_guiding_tree();
  // What the guiding-tree view's map was made from, and the job making one
  // (a ray per pixel: off the UI thread, whatever the resolution).
  std::shared_ptr<const GuidingDistribution> leaf_map_guide;
  std::shared_ptr<const Scene> leaf_map_scene;
  bool leaf_map_made = false;
  std::future<ui::GuidingLeafMap> leaf_map_job;

  // The steps of a frame, in order (see Viewer::frame).
  struct FrameLayout;
  void handle_input();
  void service_background();
  bool wants_draw(Clock::time_point t0, bool force_draw);
  void upload_textures();
  FrameLayout lay_out(int fb_w, int fb_h);
  void draw_panel(const FrameLayout& l, ui::UiRequests& requests);
  void draw_overlays(const FrameLayout& l, ui::UiRequests& requests);
  void draw_quit_question();
  float panel_width_now(float display_width) const;
  void apply_requests(const ui::UiRequests& requests);
  void draw_gl(const FrameLayout& l);
  void record_frame(Clock::time_point t0, double cpu0);
  void pace(Clock::time_point t0);
};

void Viewer::Impl::open(const ViewerOptions& o) {
  options = o;
  // Everything the user typed is checked before a window appears.
  Scene scene = load_scene_file(o.scene);
  const Strategy strategy = Strategy::parse(o.strategy);
  (void)SamplingPlan::make(strategy, scene);
  if (cli_mode()) {
    if (image_format_for(o.screenshot) != ImageFormat::Png)
      throw InputError("--screenshot '" + o.screenshot + "' must name a .png file (the .pfm and .json go beside it)");
    check_output_path(o.screenshot);
    if (options.spp == 0) options.spp = 64;
  }

  if (o.remember && !cli_mode()) {
    preferences_file = ui::preferences_path();
    std::string warning;
    const ui::Preferences p = ui::load_preferences(preferences_file, warning);
    if (!warning.empty()) std::fprintf(stderr, "note: %s\n", warning.c_str());
    if (options.window_width <= 0 || options.window_height <= 0) {
      options.window_width = p.window_width;
      options.window_height = p.window_height;
    }
    settings.panel_width = p.panel_width;
    settings.panel_hidden = p.panel_hidden;
    settings.caption = p.caption;
    panel.open = p.open;
  }
  settings.sampling = ui::SamplingSettings::from(strategy);
  settings.max_depth = scene.max_depth;
  settings.stop_spp = cli_mode() ? options.spp : o.spp;
  settings.screenshot_dir = default_screenshot_dir();
  if (!(o.ui_scale >= ui::kMinUiScale && o.ui_scale <= ui::kMaxUiScale))
    throw InputError("--ui-scale " + std::to_string(o.ui_scale) + " is outside 0.5..4");
  settings.ui_scale = o.ui_scale;
  settings.auto_weight = o.auto_weight;
  if (!o.view.empty()) settings.measure.view_mode = ui::parse_view_mode(o.view);
  if (o.make_reference_seconds > 0.0) settings.measure.make_seconds = static_cast<float>(o.make_reference_seconds);
  if (!o.reference.empty()) {
    measure.set_reference(ui::load_reference(o.reference));  // a bad file is bad input, before any window
    settings.measure.reference_field = o.reference;
  }
  scene_path = o.scene;
  base_scene = std::make_shared<const Scene>(std::move(scene));
  status.scene_files = list_scene_files();

  open_window(base_scene->camera.width, base_scene->camera.height);

  SessionOptions so;
  so.background_priority = true;
  so.preview = true;
  // A new image ends the wait between frames at once instead of at the next tick.
  so.on_image = [] { glfwPostEmptyEvent(); };
  session = std::make_unique<RenderSession>(so);
  teaching = std::make_unique<TeachingViews>(so.on_image);
  teaching->set_shared_reference(measure.matching_reference());
  references = std::make_unique<ViewerReferences>();
  weight_lab = std::make_unique<WeightLab>();
  if (!apply_render_settings()) throw InputError(status.settings_error);
  if (!o.resume.empty()) continue_film(o.resume);
  if (o.presentation && !cli_mode()) set_presentation(true);
}

// The film's settings are applied, then its accumulation replaces the empty
// one: the viewer goes on where the saved render stopped. Bad input (another
// scene or strategy, a damaged film) throws InputError before a frame is shown.
void Viewer::Impl::continue_film(const std::string& path) {
  FilmFile file = read_film_file(path);
  const FilmInfo& f = file.info;
  if (f.ranges.size() != 1)
    throw InputError("--resume: film '" + path + "' is a merge of " + std::to_string(f.ranges.size()) +
                     " renders; only one render's film can be continued");
  const std::string given =
      (base_scene ? for_scene(settings.sampling.strategy(), *base_scene) : settings.sampling.strategy()).to_string();
  if (f.strategy != given)
    throw InputError("--resume: film '" + path + "' was rendered with strategy '" + f.strategy + "', not '" + given +
                     "'");
  settings.seed = f.ranges.front().seed;
  settings.max_depth = f.max_depth;
  settings.width_override = f.width;
  settings.height_override = f.height;
  if (!apply_render_settings()) throw InputError(status.settings_error);
  if (film_scene_hash(*render_scene) != f.scene_hash)
    throw InputError("--resume: film '" + path + "' was rendered from another scene than '" + scene_path + "'");
  if (applied.seed != f.ranges.front().seed)
    throw InputError("--resume: film '" + path + "' has the reference's seed; load another reference");
  RenderSettings rs = session->settings();
  rs.first_sample = f.ranges.front().first;
  const auto spp = static_cast<std::uint32_t>(f.spp());
  if (rs.target_spp != 0 && rs.target_spp < spp) rs.target_spp = spp;
  // The film's own rendering time and samples go on: its figures describe the whole film.
  session->resume(rs, FilmStart{std::move(file.film), spp, f.dropped, f.seconds});
  film_first_sample = rs.first_sample;
}

// Ctrl+S: the accumulation as a film file in the screenshot folder, to
// continue later with `pdflab --resume FILE` (or merge with other renders).
void Viewer::Impl::save_film() {
  const bool was_paused = settings.paused;
  session->set_paused(true);  // the film is read between two passes
  const RenderSettings rs = session->settings();
  const SessionStats st = session->stats();  // not inside read_film: it holds the session's lock
  const double seconds = st.seconds;
  try {
    std::error_code ec;
    std::filesystem::create_directories(settings.screenshot_dir, ec);
    char stamp[32];
    const std::time_t t = std::time(nullptr);
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&t));
    std::string saved;
    session->read_film([&](const Film& film, std::uint32_t spp, const DropCounts& dropped) {
      if (spp == 0) throw InputError("no complete pass to save yet");
      FilmInfo info;
      info.scene_hash = film_scene_hash(*rs.scene);
      info.scene_file = scene_path;
      info.width = film.width();
      info.height = film.height();
      info.max_depth = rs.scene->max_depth;
      info.strategy = rs.strategy.to_string();
      info.ranges = {SampleRange{rs.seed, rs.first_sample, rs.first_sample + spp}};
      info.dropped = dropped;
      info.seconds = seconds;
      const std::string path = (std::filesystem::path(settings.screenshot_dir) /
                                ("pdflab-" + std::string(stamp) + "-" + std::to_string(spp) + "spp.film")).string();
      write_film_file(path, info, film);
      saved = path;
    });
    notice("Film saved: " + std::filesystem::absolute(saved).string() + " (continue with pdflab --resume)", false);
    // A saved film keeps the render as a screenshot does: quitting loses nothing then.
    last_save = {st.generation, seconds};
  } catch (const std::exception& e) {
    notice(std::string("Film not saved: ") + e.what(), true);
  }
  if (!was_paused) session->set_paused(false);
}

void Viewer::Impl::open_window(int image_width, int image_height) {
  glfwSetErrorCallback(glfw_error);
  // Under Mesa's software rasteriser (llvmpipe: Xvfb, VMs, remote desktops) its
  // own rasteriser threads would fight the render workers for every core and
  // hand each frame across threads; drawing on the UI thread halves the frame
  // time there (bench_viewer). Ignored by hardware drivers; a user's value wins.
  ::setenv("LP_NUM_THREADS", "0", 0);
  if (!glfwInit()) throw std::runtime_error("cannot open a window (no display? try xvfb-run, or `pdflab render`)");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  // Presentation mode's full screen stays up when another window takes the focus.
  glfwWindowHint(GLFW_AUTO_ICONIFY, GLFW_FALSE);

  float xs = 1.0f, ys = 1.0f;
  GLFWmonitor* monitor = glfwGetPrimaryMonitor();
  if (monitor) glfwGetMonitorContentScale(monitor, &xs, &ys);
  const float scale = std::clamp(std::max(xs, ys), 0.5f, 4.0f);
  int width = options.window_width, height = options.window_height;
  if (width <= 0 || height <= 0) {
    // The image at one image pixel per screen pixel (per `scale` on HiDPI
    // screens, like everything else), within reason, plus the panel.
    const int image_w = static_cast<int>(static_cast<float>(std::clamp(image_width, 320, 1000)) * scale);
    const int image_h = static_cast<int>(static_cast<float>(std::clamp(image_height, 320, 1000)) * scale);
    // Wide enough that the panel keeps its width within its share of the window.
    const float panel_w = std::max(settings.panel_width, ui::kMinPanelWidth) * scale * options.ui_scale;
    width = std::max(image_w + static_cast<int>(panel_w), static_cast<int>(panel_w / ui::kMaxPanelShare) + 1);
    height = std::max(image_h, static_cast<int>(800.0f * scale));
    if (const GLFWvidmode* mode = monitor ? glfwGetVideoMode(monitor) : nullptr) {
      width = std::min(width, mode->width * 19 / 20);
      height = std::min(height, mode->height * 19 / 20);
    }
  }
  const std::string title = "pdflab - " + base_scene->name;
  window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window) throw std::runtime_error("cannot create an OpenGL 3.3 core window");
  glfwMakeContextCurrent(window);
  if (gladLoadGL(glfwGetProcAddress) == 0) throw std::runtime_error("cannot load OpenGL 3.3 functions");
  // Pacing is ours (see frame()): a blocking swap would hide the frame's real cost.
  glfwSwapInterval(0);

  glfwSetWindowUserPointer(window, this);
  // Installed before ImGui's, which then chains to them.
  static constexpr auto self = [](GLFWwindow* w) { return static_cast<Impl*>(glfwGetWindowUserPointer(w)); };
  glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int mods) {
    ++self(w)->input_events;
    if (action == GLFW_PRESS) self(w)->keys.push_back({key, mods});
  });
  // The close button asks like Ctrl+Q does.
  glfwSetWindowCloseCallback(window, [](GLFWwindow* w) {
    ++self(w)->input_events;
    self(w)->request_quit();
  });
  glfwSetCharCallback(window, [](GLFWwindow* w, unsigned int) { ++self(w)->input_events; });
  glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int, int, int) { ++self(w)->input_events; });
  glfwSetScrollCallback(window, [](GLFWwindow* w, double, double) { ++self(w)->input_events; });
  glfwSetCursorPosCallback(window, [](GLFWwindow* w, double, double) { ++self(w)->input_events; });
  glfwSetWindowRefreshCallback(window, [](GLFWwindow* w) { ++self(w)->input_events; });
  glfwSetWindowFocusCallback(window, [](GLFWwindow* w, int) { ++self(w)->input_events; });
  glfwSetWindowContentScaleCallback(
      window, [](GLFWwindow* w, float, float) { static_cast<Impl*>(glfwGetWindowUserPointer(w))->fonts_dirty = true; });
  glfwSetFramebufferSizeCallback(window, [](GLFWwindow* w, int, int) {
    self(w)->fonts_dirty = true;
    ++self(w)->input_events;
  });

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  // ImGui 1.86 reads keys as held or not at each frame: a key pressed and
  // released between two frames (xdotool, a fast typist, a busy frame) would
  // never be seen, so Enter in a field or Ctrl+A could be lost. Releases of keys
  // pressed since the last frame reach ImGui one frame late instead.
  imgui_key_callback = glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int scancode, int action, int mods) {
    Impl& v = *self(w);
    // Tab hides the panel; ImGui would also move the keyboard focus into the
    // panel's first text field with it. Inside a text field it stays ImGui's.
    if (key == GLFW_KEY_TAB && !ImGui::GetIO().WantTextInput) {
      ++v.input_events;
      if (action == GLFW_PRESS) v.keys.push_back({key, mods});
      return;
    }
    if (action == GLFW_RELEASE &&
        std::find(v.pressed_this_frame.begin(), v.pressed_this_frame.end(), key) != v.pressed_this_frame.end()) {
      v.deferred_releases.push_back({key, scancode, mods});
      return;
    }
    if (action == GLFW_PRESS) v.pressed_this_frame.push_back(key);
    if (v.imgui_key_callback) v.imgui_key_callback(w, key, scancode, action, mods);
  });
  ImGui_ImplOpenGL3_Init("#version 330 core");
  imgui_ready = true;

  display = std::make_unique<ui::ImageDisplay>();
  view_texture = std::make_unique<ui::ViewTexture>();
  std::string error;
  if (!display->init(error)) throw std::runtime_error("display shaders: " + error);
}

void Viewer::Impl::rebuild_fonts() {
  fonts_dirty = false;
  float xs = 1.0f, ys = 1.0f;
  glfwGetWindowContentScale(window, &xs, &ys);
  int ww = 0, wh = 0, fw = 0, fh = 0;
  glfwGetWindowSize(window, &ww, &wh);
  glfwGetFramebufferSize(window, &fw, &fh);
  const float new_content = std::clamp(std::max(xs, ys), 0.5f, 4.0f);
  // Where window coordinates are points (macOS, Wayland), the framebuffer is
  // larger than the window; ImGui works in window coordinates.
  const float new_fb = ww > 0 && fw > 0 ? static_cast<float>(fw) / static_cast<float>(ww) : framebuffer_scale;
  ImGuiIO& io = ImGui::GetIO();
  if (new_content == content_scale && new_fb == framebuffer_scale && settings.ui_scale == ui_scale &&
      io.Fonts->Fonts.Size > 0)
    return;
  content_scale = new_content;
  framebuffer_scale = new_fb;
  ui_scale = settings.ui_scale;

  io.Fonts->Clear();
  const float pixels = 15.0f * scale();  // rasterised at the real pixel size, so text stays sharp
  std::error_code ec;
  if (fs::exists(kUiFont, ec)) {
    io.Fonts->AddFontFromFileTTF(kUiFont, pixels);
  } else {
    ImFontConfig cfg;
    cfg.SizePixels = 13.0f * scale();
    io.Fonts->AddFontDefault(&cfg);
  }
  io.FontGlobalScale = 1.0f / framebuffer_scale;
  ImGui_ImplOpenGL3_DestroyFontsTexture();
  ImGui_ImplOpenGL3_CreateFontsTexture();

  ImGuiStyle& style = ImGui::GetStyle();
  style = ImGuiStyle();
  ImGui::StyleColorsDark(&style);
  style.WindowRounding = 0.0f;
  style.FrameRounding = 3.0f;
  style.GrabRounding = 3.0f;
  style.WindowBorderSize = 0.0f;
  style.ScaleAllSizes(scale() / framebuffer_scale);
}

void Viewer::Impl::remember_preferences() {
  if (preferences_file.empty() || !window) return;
  ui::Preferences p;
  int w = 0, h = 0;
  glfwGetWindowSize(window, &w, &h);
  // The windowed size, not presentation mode's full screen.
  p.window_width = fullscreen ? windowed_w : w;
  p.window_height = fullscreen ? windowed_h : h;
  p.panel_width = settings.panel_width;
  p.panel_hidden = settings.panel_hidden;
  p.open = panel.open;
  p.caption = settings.caption;
  try {
    ui::save_preferences(preferences_file, p);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "note: the viewer's settings were not saved: %s\n", e.what());
  }
}

void Viewer::Impl::close() {
  remember_preferences();
  teaching.reset();
  references.reset();  // a reference in the making stops with the viewer
  weight_lab.reset();  // waits for a replay in flight
  session.reset();  // workers stop first: nothing renders into a closing viewer
  if (save_job.valid()) save_job.wait();
  display.reset();
  view_texture.reset();
  if (imgui_ready) {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    imgui_ready = false;
  }
  if (window) glfwDestroyWindow(window);
  window = nullptr;
  glfwTerminate();
}

bool Viewer::Impl::apply_render_settings() {
  // `fastest` on a scene whose light is hard to find runs as path guiding
  // (for_scene): the panel then shows, and the sidecars record, what runs.
  if (settings.sampling.fastest && base_scene && base_scene->fastest_uses_guiding) {
    settings.sampling = ui::SamplingSettings::from(for_scene(settings.sampling.strategy(), *base_scene));
    settings.sampling.fastest = false;
  }
  const Strategy strategy = settings.sampling.strategy();
  if (!strategy.nee_mis && all_zero(strategy)) {
    status.settings_error = "Every mixture weight is 0; still showing the last valid strategy.";
    return false;
  }
  const bool overridden = settings.width_override > 0 && settings.height_override > 0;
  if (!render_scene || render_scene_depth != settings.max_depth || render_scene_scale != settings.resolution_scale ||
      render_scene_override != overridden ||
      (overridden && (render_scene->camera.width != settings.width_override ||
                      render_scene->camera.height != settings.height_override)) ||
      !ui::same_placement(render_scene->camera, camera ? *camera : base_scene->camera) ||
      render_scene.get() == base_scene.get()) {
    auto scene = std::make_shared<Scene>(*base_scene);
    scene->max_depth = settings.max_depth;
    Camera& cam = scene->camera;
    const auto scaled = [&](int size) {
      return std::clamp(static_cast<int>(std::lround(static_cast<double>(size) * settings.resolution_scale)), 1, 16384);
    };
    cam.width = scaled(base_scene->camera.width);
    cam.height = scaled(base_scene->camera.height);
    if (overridden) {
      cam.width = settings.width_override;
      cam.height = settings.height_override;
    }
    if (camera) {
      cam.lookfrom = camera->lookfrom;
      cam.lookat = camera->lookat;
      cam.vup = camera->vup;
      cam.vfov_degrees = camera->vfov_degrees;
    }
    cam.prepare();
    if (camera && !ui::same_placement(*camera, base_scene->camera)) scene->content_hash = view_hash(base_scene->content_hash, *camera);
    render_scene = std::move(scene);
    render_scene_depth = settings.max_depth;
    render_scene_scale = settings.resolution_scale;
    render_scene_override = overridden;
  }
  // Never the reference's random numbers: a seed it was rendered with is changed.
  std::string seed_note;
  if (const auto other = decorrelated_seed(measure.reference, settings.seed, strategy, seed_note)) {
    settings.seed = *other;
    measure.reference_note = seed_note;
  }
  RenderSettings rs;
  rs.scene = render_scene;
  rs.strategy = strategy;
  rs.seed = settings.seed;
  rs.target_spp = settings.stop_spp;
  rs.target_seconds = settings.stop_seconds;
  try {
    session->set_settings(rs);
  } catch (const InputError& e) {
    status.settings_error = e.what();
    return false;
  }
  status.settings_error.clear();
  applied = settings;
  // What the figures are measured against from now on must show this.
  ui::ImageIdentity id;
  id.view_hash = render_scene->content_hash;
  id.scene_hash = base_scene->content_hash;
  id.width = render_scene->camera.width;
  id.height = render_scene->camera.height;
  id.max_depth = render_scene->max_depth;
  measure.set_render_identity(id);
  if (references && references->follow_scene(*render_scene, measure)) after_reference_changed();
  return true;
}

void Viewer::Impl::after_reference_changed() {
  std::string note;
  if (decorrelated_seed(measure.reference, applied.seed, applied.sampling.strategy(), note)) apply_render_settings();
}

void Viewer::Impl::service_references() {
  if (references->service(measure)) after_reference_changed();
  // At 100% of the threads the main render rests until the reference is done.
  const bool rest = references->wants_main_paused();
  if (rest != main_rests_for_reference) {
    main_rests_for_reference = rest;
    session->set_paused(rest || settings.paused);
  }
}

void Viewer::Impl::load_scene(const std::string& path) {
  Scene loaded;
  try {
    loaded = load_scene_file(path);
  } catch (const std::exception& e) {
    status.scene_error = e.what();  // the current scene stays
    return;
  }
  auto previous_scene = base_scene;
  auto previous_render = render_scene;
  const int previous_depth = settings.max_depth;
  const std::string previous_path = scene_path;
  const std::optional<Camera> previous_camera = camera;
  camera.reset();  // the new scene's own
  base_scene = std::make_shared<const Scene>(std::move(loaded));
  render_scene.reset();
  settings.max_depth = base_scene->max_depth;
  scene_path = path;
  if (!apply_render_settings()) {
    status.scene_error = "Not loaded: " + status.settings_error;
    status.settings_error.clear();
    base_scene = previous_scene;
    render_scene = previous_render;
    settings.max_depth = previous_depth;
    scene_path = previous_path;
    camera = previous_camera;
    return;
  }
  status.scene_error.clear();
  glfwSetWindowTitle(window, ("pdflab - " + base_scene->name).c_str());
  status.scene_files = list_scene_files();
}

double Viewer::Impl::unsaved_seconds() const {
  const SessionStats st = session->stats();
  double seconds = ui::unsaved_seconds(last_save, st.generation, st.seconds);
  // In the split the main session rests; the two sides' rendering is at stake.
  if (teaching->split_active()) seconds = std::max(seconds, teaching->split_seconds());
  return seconds;
}

void Viewer::Impl::request_quit() {
  if (cli_mode() || quit_asking || unsaved_seconds() <= ui::kUnsavedAskSeconds) {
    glfwSetWindowShouldClose(window, GLFW_TRUE);
    return;
  }
  glfwSetWindowShouldClose(window, GLFW_FALSE);
  quit_asking = true;
  settle_frames = 3;
}

void Viewer::Impl::on_escape() {
  // Esc closes or cancels, innermost first, and never quits. ImGui itself closes
  // an open drop-down and cancels a text edit (the key is then ignored here).
  if (quit_asking) {
    quit_asking = quit_after_save = false;
    return;
  }
  if (ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId)) {
    close_popups = true;  // in the next frame (ImGui closes popups on Esc only with keyboard navigation on)
    return;
  }
  if (settings.presentation) {
    set_presentation(false);
    return;
  }
  if (camera_mode) {
    camera_mode = false;
    return;
  }
  if (teaching->on_escape()) return;
  if (panel.show_help) panel.show_help = false;
}

void Viewer::Impl::on_key(int key, int mods) {
  if (key == GLFW_KEY_Q && (mods & GLFW_MOD_CONTROL)) {
    request_quit();  // while asking, Ctrl+Q again is "quit anyway"
    return;
  }
  if (key == GLFW_KEY_ESCAPE) {
    // A text field being edited takes Esc as "cancel": nothing else happens.
    if (!editing_text()) on_escape();
    return;
  }
  if (quit_asking) return;
  // Typing a path or a strategy must not pause the render, restart it or
  // switch views: while a text field is edited, keys are text.
  if (editing_text() && key != GLFW_KEY_F12) return;
  if (key == GLFW_KEY_S && (mods & GLFW_MOD_CONTROL)) {
    save_film();
    return;
  }
  if (key == GLFW_KEY_E && (mods & GLFW_MOD_CONTROL)) {
    export_view();
    return;
  }
  if (key == GLFW_KEY_C && (mods & GLFW_MOD_CONTROL)) {
    // What the inspector shows, as text: for notes, and for tests to compare with the PFM.
    if (inspected) glfwSetClipboardString(window, inspected->text().c_str());
    return;
  }
  const int w = image_info.width, h = image_info.height;
  const double cx = last_area.x + last_area.width * 0.5, cy = last_area.y + last_area.height * 0.5;
  switch (key) {
    case GLFW_KEY_F11: set_presentation(!settings.presentation); return;
    case GLFW_KEY_TAB:
      settings.panel_hidden = !settings.panel_hidden;
      view.fit = true;
      return;
    case GLFW_KEY_O:
      camera_mode = !camera_mode;
      if (camera_mode) teaching->leave_probe_mode();  // one thing for a left drag to mean
      return;
    case GLFW_KEY_HOME: reset_camera(); return;
    case GLFW_KEY_P: camera_mode = false; break;
    case GLFW_KEY_F: view.fit = true; return;
    case GLFW_KEY_Z: view.actual_size(last_area, w, h); return;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD: view.zoom_about(last_area, w, h, 2.0, cx, cy); return;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: view.zoom_about(last_area, w, h, 0.5, cx, cy); return;
    default: break;
  }
  if (teaching->on_key(key, *session, settings.paused)) return;
  switch (key) {
    case GLFW_KEY_SPACE:
      settings.paused = !settings.paused;
      session->set_paused(settings.paused);
      break;
    case GLFW_KEY_R: apply_render_settings(); break;
    case GLFW_KEY_F12: screenshot_wanted = true; break;
    case GLFW_KEY_1:
    case GLFW_KEY_2:
    case GLFW_KEY_3:
    case GLFW_KEY_4:
    case GLFW_KEY_5:
      settings.sampling = ui::preset_by_key(key - GLFW_KEY_0);
      apply_render_settings();
      break;
    case GLFW_KEY_V: settings.measure.view_mode = ui::next_view_mode(settings.measure.view_mode); break;
    case GLFW_KEY_E: settings.measure.step_metric(mods & GLFW_MOD_SHIFT ? -1 : 1); break;
    case GLFW_KEY_G: settings.measure.show_plot = !settings.measure.show_plot; break;
    case GLFW_KEY_M:  // make a reference, as the Measure section's button; again: cancel
      if (references->running()) references->cancel(measure);
      else if (render_scene) references->start(*render_scene, scene_path, settings.measure, measure);
      break;
    case GLFW_KEY_K: measure.curves.pin(); break;  // keep
    case GLFW_KEY_H:
    case GLFW_KEY_F1: panel.show_help = !panel.show_help; break;
    default: break;
  }
}

void Viewer::Impl::set_presentation(bool on) {
  settings.presentation = on;
  presentation_since = on ? now() : -1.0;
  settle_frames = 3;
  GLFWmonitor* monitor = glfwGetPrimaryMonitor();
  const GLFWvidmode* mode = monitor ? glfwGetVideoMode(monitor) : nullptr;
  if (on && !fullscreen && mode) {
    glfwGetWindowPos(window, &windowed_x, &windowed_y);
    glfwGetWindowSize(window, &windowed_w, &windowed_h);
    glfwSetWindowMonitor(window, monitor, 0, 0, mode->width, mode->height, mode->refreshRate);
    fullscreen = true;
  } else if (!on && fullscreen) {
    glfwSetWindowMonitor(window, nullptr, windowed_x, windowed_y, windowed_w, windowed_h, 0);
    fullscreen = false;
  }
  view.fit = true;  // the new area, the whole picture
}

void Viewer::Impl::navigate(const ui::Viewport& area, int framebuffer_height) {
  // Mouse over the image area and not over a window: the wheel zooms about the
  // cursor; dragging pans (right or middle button always, left unless a click
  // means something else there: probe mode, the split's divider).
  last_area = area;
  const ImGuiIO& io = ImGui::GetIO();
  const double fbs = framebuffer_scale;
  const double mx = io.MousePos.x * fbs, my = framebuffer_height - io.MousePos.y * fbs;
  const bool over = !io.WantCaptureMouse && mx >= area.x && mx < area.x + area.width && my >= area.y &&
                    my < area.y + area.height;
  const int w = image_info.width, h = image_info.height;
  if (camera_mode) {
    if (move_camera(area, over)) apply_render_settings();
    return;
  }
  if (over && io.MouseWheel != 0.0f) view.zoom_about(area, w, h, std::pow(1.25, io.MouseWheel), mx, my);
  if (pan_button >= 0 && !ImGui::IsMouseDown(pan_button)) pan_button = -1;
  if (pan_button < 0 && over) {
    for (int b : {ImGuiMouseButton_Right, ImGuiMouseButton_Middle, ImGuiMouseButton_Left}) {
      if (b == ImGuiMouseButton_Left && teaching->takes_left_clicks()) continue;
      if (ImGui::IsMouseClicked(b)) pan_button = b;
    }
  }
  // A left click that does not move is no pan (nothing else happens either).
  if (pan_button >= 0 && (pan_button != ImGuiMouseButton_Left || ImGui::IsMouseDragging(pan_button)))
    view.pan(area, w, h, io.MouseDelta.x * fbs, -io.MouseDelta.y * fbs);
}

bool Viewer::Impl::move_camera(const ui::Viewport& area, bool over) {
  // Left drag orbits, right (or middle) drag pans, the wheel dollies.
  const ImGuiIO& io = ImGui::GetIO();
  if (pan_button >= 0 && !ImGui::IsMouseDown(pan_button)) pan_button = -1;
  if (pan_button < 0 && over)
    for (int b : {ImGuiMouseButton_Left, ImGuiMouseButton_Right, ImGuiMouseButton_Middle})
      if (ImGui::IsMouseClicked(b)) pan_button = b;
  const Camera now_at = camera ? *camera : base_scene->camera;
  Camera moved = now_at;
  const double fbs = framebuffer_scale;
  const double dx = io.MouseDelta.x * fbs, dy = io.MouseDelta.y * fbs;
  const double span = std::max(1, area.height);
  if (pan_button == ImGuiMouseButton_Left && (dx != 0.0 || dy != 0.0))
    moved = ui::orbit(moved, -dx / span * 3.0, dy / span * 3.0);
  else if (pan_button > 0 && (dx != 0.0 || dy != 0.0))
    moved = ui::pan(moved, -dx / span, dy / span);
  if (over && io.MouseWheel != 0.0f) moved = ui::dolly(moved, std::pow(0.9, io.MouseWheel));
  if (ui::same_placement(moved, now_at)) return false;
  camera = moved;
  return true;
}

void Viewer::Impl::inspect(const ui::ImageRect& image_rect, const ui::ImageRect& area_rect) {
  // The pixel under the cursor, read from the image on screen (not in the split:
  // its sides are other images).
  inspected.reset();
  const ImGuiIO& io = ImGui::GetIO();
  if (io.WantCaptureMouse || teaching->split_active() || settings.measure.view_mode != ui::ViewMode::Image) return;
  const float mx = io.MousePos.x, my = io.MousePos.y;
  if (mx < area_rect.x || my < area_rect.y || mx >= area_rect.x + area_rect.width || my >= area_rect.y + area_rect.height)
    return;
  const auto hit = ui::pixel_at(mx, my, image_rect.x, image_rect.y, image_rect.width, image_rect.height,
                                image_info.width, image_info.height);
  if (!hit) return;
  // The reference's value only where it shows this render (not another view, size or depth).
  inspected = ui::read_pixel(measure.published, measure.matching_reference(), hit->x, hit->y);
  if (!inspected) return;
  const std::string text = inspected->text();
  ui::layout::Overlay o;
  o.corner = ui::Corner::BottomRight;
  o.width = ImGui::CalcTextSize(text.c_str()).x + 2.0f * ImGui::GetStyle().WindowPadding.x;
  o.height = ui::layout::text_height(static_cast<int>(std::count(text.begin(), text.end(), '\n')) + 2);
  o.min_width = 10.0f;
  o.min_lines = 4.0f;
  float wrap = 0.0f;
  if (!ui::layout::place_next_window("##inspector", o, &wrap)) return;
  ImGui::SetNextWindowBgAlpha(0.85f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs;
  if (ImGui::Begin("##inspector", nullptr, flags)) {
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + wrap);
    ImGui::TextUnformatted(text.c_str());
    ImGui::TextColored(ImVec4(0.65f, 0.65f, 0.68f, 1.0f), "Ctrl+C copies. Wheel: zoom, drag: pan, Z: 1:1, F: fit");
    ImGui::PopTextWrapPos();
  }
  ImGui::End();
}

void Viewer::Impl::pull_image() {
  // Never waits for a worker: copy_image only takes the image lock for a copy.
  if (session->copy_published(measure.published, image_version)) {
    image = measure.published.rgb;
    image_info = measure.published.info;
    texture_stale = true;
    report.new_image = true;
    measure.on_image(session->generation(), applied.sampling.strategy().to_string());
  }
}

ui::ScreenshotData Viewer::Impl::capture() const {
  ui::ScreenshotData d;
  d.rgb = image;
  d.width = image_info.width;
  d.height = image_info.height;
  d.transfer = settings.srgb ? Transfer::Srgb : Transfer::Gamma2;
  d.exposure_ev = settings.exposure_ev;
  d.scene_name = base_scene->name;
  d.scene_file = scene_path;
  d.strategy = applied.sampling.strategy();
  d.spp = image_info.spp;
  d.seconds = image_info.seconds;
  d.seed = applied.seed;
  d.max_depth = applied.max_depth;
  d.version = PDFLAB_VERSION;
  d.generation = image_info.generation;
  if (render_scene) {
    d.camera = render_scene->camera;
    d.origin = render_scene->origin;
    d.scene_hash = render_scene->content_hash;
  }
  d.camera_moved = camera.has_value();
  // The figures of this very image, and the reference they were measured against (or why not).
  d.figures = measure.figures;
  if (measure.reference.loaded()) {
    const Reference& r = measure.reference;
    d.reference.loaded = true;
    d.reference.from_cache = measure.reference_from_cache;
    d.reference.path = r.path;
    d.reference.strategy = r.info.strategy;
    d.reference.scene_hash = measure.reference_identity.view_hash;
    d.reference.width = r.width;
    d.reference.height = r.height;
    d.reference.max_depth = measure.reference_identity.max_depth;
    d.reference.spp = r.info.spp;
    d.reference.seconds = r.info.seconds;
    d.reference.mismatch = measure.reference_mismatch();
  }
  return d;
}

void Viewer::Impl::start_save(ui::ScreenshotData data) {
  saving = std::move(data);
  // Encoding a PNG takes tens of milliseconds: off the UI thread. The job reads
  // `saving` only; the UI thread leaves it alone until the job reports.
  save_job = std::async(std::launch::async, [this, folder = settings.screenshot_dir] {
    return ui::save_screenshot_in(folder, saving, std::time(nullptr));
  });
}

void Viewer::Impl::service_screenshots() {
  const bool current = !image.empty() && image_info.generation == session->generation() && !image_info.preview;

  if (cli_mode() && !cli_done && current && image_info.spp >= options.spp) {
    cli_done = true;
    try {
      const ui::SavedScreenshot files = ui::save_screenshot_as(options.screenshot, capture());
      std::printf("%u spp, %dx%d, %.2f s -> %s (+ %s, %s)\n", image_info.spp, image_info.width, image_info.height,
                  image_info.seconds, files.png.c_str(), files.pfm.c_str(), files.json.c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "pdflab: error: screenshot not saved: %s\n", e.what());
      exit_status = 1;
    }
    glfwSetWindowShouldClose(window, GLFW_TRUE);
  }

  if (save_job.valid() && save_job.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    try {
      const ui::SavedScreenshot files = save_job.get();
      std::error_code ec;
      const fs::path png = fs::absolute(files.png, ec);
      notice("Saved " + (ec ? files.png : png.string()) + "\n  + " + fs::path(files.pfm).filename().string() + ", " +
                 fs::path(files.json).filename().string(),
             false);
      failed_save.reset();
      last_save = {saving.generation, saving.seconds};
      if (quit_after_save) glfwSetWindowShouldClose(window, GLFW_TRUE);
    } catch (const std::exception& e) {
      notice(std::string("Screenshot NOT saved: ") + e.what() +
                 "\nThe image is kept: choose another folder and press Retry.",
             true);
      failed_save = std::move(saving);
      quit_after_save = false;  // the question stays open, with the reason beside it
    }
  }
  if (save_job.valid()) return;

  if (screenshot_wanted && current) {
    screenshot_wanted = false;
    start_save(capture());
  }
}

void Viewer::Impl::fill_status() {
  status.stats = session->stats();
  status.threads = session->thread_count();
  status.scene_name = base_scene->name;
  status.scene_path = scene_path;
  status.scene_light_choice = base_scene->light_choice;
  status.base_width = base_scene->camera.width;
  status.base_height = base_scene->camera.height;
  status.width = render_scene ? render_scene->camera.width : 0;
  status.height = render_scene ? render_scene->camera.height : 0;
  status.showing_preview = image_info.preview;
  status.shown_spp = image_info.spp;
  status.screenshot_pending = screenshot_wanted || save_job.valid();
  status.can_retry_screenshot = failed_save.has_value() && !save_job.valid();
  status.camera_mode = camera_mode;
  status.camera_moved = camera.has_value();
  status.now = now();
  status.frame_ms = report.work_ms;
  status.measure = &measure;
  status.split = teaching->split_state();
  status.weights = weight_lab->curve();
  if (auto_run.on) status.weights.history = auto_run.history;
  status.scale = scale();
  status.max_depth = applied.max_depth;
  status.messages = messages();
  const ui::ViewMode mode = settings.measure.view_mode;
  status.can_export_view =
      ui::view_mode_exports(mode) && measure.layer_ok && measure.layer_mode == mode && !teaching->split_active();
  status.can_export_curve = !status.weights.weight.empty() && status.weights.active;
  status.can_export_convergence = !measure.curves.live().points.empty() || !measure.curves.pins().empty();
}

// The panel's message line: errors first, then warnings, then notes, newest
// first within each; a save's notice is a note for a while.
std::vector<ui::PanelMessage> Viewer::Impl::messages() const {
  std::vector<ui::PanelMessage> m;
  using K = ui::PanelMessage;
  const bool recent = !status.notice.text.empty() && now() - status.notice.shown_at < 30.0;
  if (recent && status.notice.error) m.push_back({K::Error, status.notice.text});
  if (!status.settings_error.empty()) m.push_back({K::Error, status.settings_error});
  if (!status.scene_error.empty()) m.push_back({K::Error, status.scene_error});
  if (!measure.reference_error.empty()) m.push_back({K::Error, measure.reference_error});
  if (measure.figures.valid && !measure.figures.estimate_why.empty()) m.push_back({K::Warning, measure.figures.estimate_why});
  if (measure.figures.valid && measure.figures.rough_reference)
    m.push_back({K::Warning, "The reference is rough: its own noise is more than a quarter of the error. Make a better one."});
  if (!measure.reference_note.empty() && measure.reference_note_warns) m.push_back({K::Warning, measure.reference_note});
  if (recent && !status.notice.error) m.push_back({K::Note, status.notice.text});
  if (!measure.reference_note.empty() && !measure.reference_note_warns) m.push_back({K::Note, measure.reference_note});
  return m;
}

void Viewer::Impl::load_reference(const std::string& path) {
  try {
    measure.set_reference(ui::load_reference(path));
    measure.reference_from_cache = false;
    measure.reference_note.clear();
  } catch (const std::exception& e) {
    measure.reference_error = e.what();  // the previous reference stays
    return;
  }
  after_reference_changed();
}

void Viewer::Impl::handle_measure_requests(const ui::MeasureRequests& r) {
  if (!r.load_reference.empty()) load_reference(r.load_reference);
  if (r.clear_reference) {
    measure.set_reference({});
    measure.reference_from_cache = false;
    measure.reference_note.clear();
  }
  if (r.make_reference && render_scene) references->start(*render_scene, scene_path, settings.measure, measure);
  if (r.cancel_reference) references->cancel(measure);
  if (r.render_at_reference_size && measure.reference.loaded()) {
    settings.width_override = measure.reference.width;
    settings.height_override = measure.reference.height;
    apply_render_settings();
  }
  if (r.pin_curve) measure.curves.pin();
  if (r.clear_pins) measure.curves.clear_pins();
}

namespace {

std::string seconds_text(double s) {
  char text[32];
  std::snprintf(text, sizeof text, s < 120.0 ? "%.1f s" : "%.0f s", s);
  return text;
}

// "Saved a.png (+ b.csv)" with the first path absolute, as the screenshot notice has it.
std::string saved_text(const std::string& what, const std::vector<std::string>& paths) {
  std::error_code ec;
  std::string text = what + " saved: " + fs::absolute(paths.front(), ec).string();
  for (std::size_t i = 1; i < paths.size(); ++i) text += (i == 1 ? "\n  + " : ", ") + fs::path(paths[i]).filename().string();
  return text;
}

}  // namespace

// The false-colour view on screen as a PNG with its legend and a caption
// (what is shown, of which render, measured how).
void Viewer::Impl::export_view() {
  const ui::ViewMode mode = settings.measure.view_mode;
  if (!ui::view_mode_exports(mode) || !measure.layer_ok || measure.layer_mode != mode) {
    notice("Nothing to export: V picks a heat map, difference, best-weight or technique-share view to export.", true);
    return;
  }
  ui::FigureCaption caption;
  const bool metric_view = mode == ui::ViewMode::RelativeError || mode == ui::ViewMode::Difference;
  caption.title = std::string(mode == ui::ViewMode::RelativeError ? "noise heat map" : ui::view_mode_label(mode)) +
                  (metric_view ? std::string(": ") + ui::error_metric_label(mode, settings.measure.layer_options(mode).metric)
                               : std::string());
  const ui::Figures& f = measure.figures;
  caption.lines.push_back(base_scene->name + ", " + std::to_string(measure.published.info.width) + "x" +
                          std::to_string(measure.published.info.height) + (camera ? ", camera moved" : "") +
                          ", max depth " + std::to_string(applied.max_depth) + ", seed " + std::to_string(applied.seed));
  caption.lines.push_back(applied.sampling.strategy().to_string());
  caption.lines.push_back(std::to_string(measure.published.info.spp) + " spp, " +
                          seconds_text(measure.published.info.seconds) + " of rendering");
  char line[200];
  if (f.valid && f.against_reference) {
    const Reference& r = measure.reference;
    const std::string against = r.info.spp > 0 ? "a " + std::to_string(r.info.spp) + "-spp reference"
                                               : "the reference " + fs::path(r.path).filename().string();
    std::snprintf(line, sizeof line, "relMSE %.4g +- %.2g %s against %s, efficiency %.4g", f.relmse, f.relmse_interval,
                  f.rough_reference ? "(ROUGH: the reference is noisy)" : "measured", against.c_str(), f.efficiency);
  }
  else if (f.valid)
    std::snprintf(line, sizeof line, "relMSE %.4g estimated from the film's variance (a lower bound)", f.estimated_relmse);
  else
    std::snprintf(line, sizeof line, "no figures yet");
  caption.lines.push_back(line);
  if (mode == ui::ViewMode::BestWeight || mode == ui::ViewMode::TechniqueShare)
    caption.lines.push_back("from " + std::to_string(measure.weight_maps.paths) + " paths traced for the prediction, per " +
                            std::to_string(measure.weight_maps.block) + "x" + std::to_string(measure.weight_maps.block) +
                            " block");
  caption.lines.push_back(std::string("pdflab ") + PDFLAB_VERSION);
  static constexpr const char* kKinds[] = {"image", "heatmap", "difference", "drops", "best-weight", "technique-share"};
  try {
    const std::vector<std::uint8_t> png = ui::view_figure_png(mode, measure.layer, caption);
    const auto paths = ui::save_figure_files(settings.screenshot_dir, kKinds[static_cast<int>(mode)], {{"png", png}},
                                             std::time(nullptr));
    notice(saved_text("Figure", paths), false);
  } catch (const std::exception& e) {
    notice(std::string("Figure NOT saved: ") + e.what(), true);
  }
}

void Viewer::Impl::export_curve() {
  const ui::WeightCurveStatus& c = weight_lab->curve();
  const std::array<int, 2> pair = ui::two_technique_pair(applied.sampling, panel.w_pair);
  if (!c.active || c.weight.empty() || pair[0] < 0) {
    notice("Nothing to export: the predicted curve shows for a mixture of two techniques once paths are traced.", true);
    return;
  }
  const std::string a(technique_name(static_cast<Technique>(pair[0]))), b(technique_name(static_cast<Technique>(pair[1])));
  char title[200];
  std::snprintf(title, sizeof title, "Predicted efficiency against w, %s, %u spp (%llu paths)", base_scene->name.c_str(),
                image_info.spp, static_cast<unsigned long long>(c.paths));
  const std::string svg = ui::weight_curve_svg(c, a, b, title), csv = ui::weight_curve_csv(c);
  try {
    const auto paths = ui::save_figure_files(settings.screenshot_dir, "curve",
                                             {{"svg", {svg.begin(), svg.end()}}, {"csv", {csv.begin(), csv.end()}}},
                                             std::time(nullptr));
    notice(saved_text("Curve", paths), false);
  } catch (const std::exception& e) {
    notice(std::string("Curve NOT saved: ") + e.what(), true);
  }
}

void Viewer::Impl::export_convergence() {
  if (measure.curves.live().points.empty() && measure.curves.pins().empty()) {
    notice("Nothing to export: the convergence plot has no points yet.", true);
    return;
  }
  const std::string title = "Convergence, " + base_scene->name;
  const std::string svg = ui::convergence_svg(measure.curves, settings.measure.plot_against_spp, title);
  const std::string csv = ui::convergence_csv(measure.curves);
  try {
    const auto paths = ui::save_figure_files(settings.screenshot_dir, "convergence",
                                             {{"svg", {svg.begin(), svg.end()}}, {"csv", {csv.begin(), csv.end()}}},
                                             std::time(nullptr));
    notice(saved_text("Convergence plot", paths), false);
  } catch (const std::exception& e) {
    notice(std::string("Convergence plot NOT saved: ") + e.what(), true);
  }
}

Viewer::Viewer(const ViewerOptions& options) : impl_(std::make_unique<Impl>()) {
  try {
    impl_->open(options);
  } catch (...) {
    impl_->close();
    throw;
  }
}

Viewer::~Viewer() { impl_->close(); }

// The frame's place on screen: the panel on the right (none while presenting),
// the image area left of it, and the image within the area (zoom and pan).
struct Viewer::Impl::FrameLayout {
  int fb_w = 0, fb_h = 0;      // the framebuffer
  float panel_width = 0.0f;    // ImGui coordinates
  int panel_px = 0;            // framebuffer pixels
  ui::Viewport area;           // the image area, framebuffer pixels (origin bottom left)
  ui::Viewport image_fb;       // the image, framebuffer pixels
  ui::ImageRect image_rect;    // the image, ImGui coordinates, for what is drawn over it
  ui::ImageRect area_rect;     // the image area, ImGui coordinates
};

// The prediction beside the w slider and the two weight views (viewer_weights.h).
void Viewer::Impl::service_weights() {
  const std::array<int, 2> pair = ui::two_technique_pair(applied.sampling, panel.w_pair);
  const bool mixture = applied.sampling.mixture && !applied.sampling.nee_mis;
  WeightLab::Input in;
  in.scene = render_scene;
  in.strategy = applied.sampling.strategy();
  in.seed = applied.seed;
  in.spp_before = auto_run.on ? auto_run.spp_before : 0;
  in.seconds_before = auto_run.on ? auto_run.seconds_before : 0.0;
  in.first_sample = film_first_sample + in.spp_before;
  in.generation = session->generation();
  in.a = mixture ? pair[0] : -1;
  in.b = mixture ? pair[1] : -1;
  in.image = &measure.published;
  in.pricing = auto_run.on ? &auto_run.chooser : nullptr;
  if (in.strategy.uses(Technique::Guided)) {
    in.guiding = session->guiding();
    const SessionStats st = session->stats();  // after the distribution: its passes are at least as many
    in.guiding_trained = st.guiding_pass >= st.guiding_passes;
  }
  if (weight_lab->update(in)) {
    measure.set_weight_maps(weight_lab->maps());
    settle_frames = std::max(settle_frames, 1);
  }
}

// The guiding-tree view: while it is on, its map follows the session's
// distribution (a new one at the end of each training pass).
void Viewer::Impl::service_guiding_tree() {
  if (leaf_map_job.valid()) {
    if (leaf_map_job.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    // Of leaf_map_guide: no other job starts while one runs.
    measure.set_guiding_leaves(leaf_map_job.get());
    settle_frames = std::max(settle_frames, 1);
  }
  if (settings.measure.view_mode != ui::ViewMode::GuidingTree) return;
  std::shared_ptr<const GuidingDistribution> guide = session->guiding();
  if (leaf_map_made && guide == leaf_map_guide && render_scene == leaf_map_scene) return;
  const int pass = session->stats().guiding_pass;  // read after the distribution: it cannot be older
  leaf_map_made = true;
  leaf_map_guide = guide;
  leaf_map_scene = render_scene;
  if (!guide) {
    measure.set_guiding_leaves(ui::GuidingLeafMap{});  // no map: the layer says why
    settle_frames = std::max(settle_frames, 1);
    return;
  }
  leaf_map_job = std::async(std::launch::async, [guide, scene = render_scene, pass] {
    ui::GuidingLeafMap map;
    map.width = scene->camera.width;
    map.height = scene->camera.height;
    map.leaf = guiding_leaf_map(*scene, *guide);
    map.leaves = guide->leaves();
    map.pass = pass;
    std::vector<char> seen(static_cast<std::size_t>(map.leaves), 0);
    for (const std::int32_t l : map.leaf)
      if (l >= 0 && !std::exchange(seen[static_cast<std::size_t>(l)], 1)) ++map.on_screen;
    return map;
  });
}

// Auto weight: at 16, 32, 64, ... spp the weight moves to the best that the
// passes so far predict, and the accumulation goes on (the film continues,
// with the next sample indices). Each pass's weight is fixed before the pass
// starts and depends only on earlier passes' samples, so every pass is an
// unbiased render and so is the film that sums them (docs/measuring.md).
void Viewer::Impl::service_auto_weight() {
  const std::array<int, 2> pair = ui::two_technique_pair(applied.sampling, panel.w_pair);
  const bool usable = settings.auto_weight && applied.sampling.mixture && !applied.sampling.nee_mis && pair[0] >= 0;
  if (!usable) {
    auto_run.on = false;
    return;
  }
  const int a = pair[0], b = pair[1];
  const float sum = applied.sampling.weights[a] + applied.sampling.weights[b];
  const double current = sum > 0.0f ? applied.sampling.weights[a] / sum : 0.5;
  const std::uint64_t generation = session->generation();
  if (!auto_run.on || generation != auto_run.generation) {
    // Turned on, or something else changed and restarted the render: a new run.
    auto_run = AutoRun();
    auto_run.on = true;
    auto_run.chooser = AutoWeight(current);
    auto_run.history = {static_cast<float>(auto_run.chooser.weight())};
    auto_run.generation = generation;
  }
  const std::optional<WeightPrediction>& p = weight_lab->prediction();
  if (!p || weight_lab->generation() != generation || image_info.generation != generation || image_info.preview ||
      image_info.spp < auto_run.next_spp)
    return;
  // At the stop (or past it) there is no next pass to choose a weight for.
  if (settings.stop_spp != 0 && image_info.spp >= settings.stop_spp) return;
  auto_run.chooser.add_pass(*p, weight_lab->seconds_per_sample());
  while (auto_run.next_spp <= image_info.spp) auto_run.next_spp *= 2;
  const double w = auto_run.chooser.weight();
  auto_run.history.push_back(static_cast<float>(w));
  if (std::fabs(w - current) < 1e-6) return;
  // Continue the film at the new weight.
  session->set_paused(true);
  Film film = session->copy_film();
  const SessionStats st = session->stats();
  if (settings.stop_spp != 0 && st.spp >= settings.stop_spp) {
    // The film reached its stop while the image shown lagged a pass behind: no
    // pass is left to take the new weight, and the film stays as it is.
    auto_run.history.pop_back();
    session->set_paused(settings.paused || main_rests_for_reference);
    return;
  }
  RenderSettings rs = session->settings();
  settings.sampling.weights[a] = static_cast<float>(w);
  settings.sampling.weights[b] = static_cast<float>(1.0 - w);
  rs.strategy = settings.sampling.strategy();
  // With guided, every later pass draws from the distribution the first one learned.
  rs.guiding = rs.strategy.uses(Technique::Guided) ? session->guiding() : nullptr;
  try {
    session->resume(rs, FilmStart{std::move(film), st.spp, st.dropped, st.seconds});
  } catch (const InputError& e) {
    status.settings_error = e.what();
  }
  session->set_paused(settings.paused || main_rests_for_reference);
  applied.sampling = settings.sampling;
  auto_run.spp_before = st.spp;
  auto_run.seconds_before = st.seconds;
  auto_run.generation = session->generation();
}

void Viewer::Impl::handle_input() {
  // Quick releases whose press a frame has seen first (see open_window), then
  // the new events. A press and release both taken while the last frame waited
  // (pace) are not seen yet: replayed now, ImGui would never see the key down.
  std::vector<Release> unseen;
  for (const Release& r : std::exchange(deferred_releases, {})) {
    if (!r.seen) unseen.push_back(r);
    else if (imgui_key_callback) imgui_key_callback(window, r.key, r.scancode, GLFW_RELEASE, r.mods);
  }
  deferred_releases = std::move(unseen);
  glfwPollEvents();
  pending_keys.insert(pending_keys.end(), keys.begin(), keys.end());
  keys.clear();
}

// The keys of this frame, after its widgets: whether a text field took them is known then.
void Viewer::Impl::handle_keys() {
  for (const KeyPress& k : std::exchange(pending_keys, {})) on_key(k.key, k.mods);
}

void Viewer::Impl::service_background() {
  pull_image();
  // The split measures against the Measure section's reference only where it shows this render.
  teaching->set_shared_reference(measure.matching_reference());
  service_auto_weight();
  service_weights();
  service_guiding_tree();
  service_references();
  teaching->update(*session, settings.paused);
  service_screenshots();
}

bool Viewer::Impl::wants_draw(Clock::time_point t0, bool force_draw) {
  if (input_events != seen_input_events) {
    seen_input_events = input_events;
    settle_frames = 3;
  }
  // Elapsed time and samples/s tick between images: a few redraws a second show that.
  return force_draw || texture_stale || teaching->wants_frames() || settle_frames > 0 || fonts_dirty ||
         ImGui::IsAnyItemActive() || t0 - last_draw > std::chrono::milliseconds(250);
}

void Viewer::Impl::upload_textures() {
  if (settings.ui_scale != ui_scale) fonts_dirty = true;
  if (fonts_dirty) rebuild_fonts();
  if (texture_stale) {
    display->upload(image.data(), image_info.data_width, image_info.data_height);
    texture_stale = false;
  }
  if (measure.refresh_layer(settings.measure))
    view_texture->upload(measure.layer.rgba.data(), measure.layer.width, measure.layer.height);
}

float Viewer::Impl::panel_width_now(float display_width) const {
  if (settings.presentation || settings.panel_hidden) return 0.0f;
  return ui::panel_width_for(settings.panel_width, scale() / framebuffer_scale, display_width);
}

Viewer::Impl::FrameLayout Viewer::Impl::lay_out(int fb_w, int fb_h) {
  const ImGuiIO& io = ImGui::GetIO();
  FrameLayout l;
  l.fb_w = fb_w;
  l.fb_h = fb_h;
  l.panel_width = panel_width_now(io.DisplaySize.x);
  const float fbs = framebuffer_scale;
  l.panel_px = static_cast<int>(l.panel_width * fbs);
  l.area = {0, 0, std::max(0, fb_w - l.panel_px), fb_h};
  navigate(l.area, fb_h);  // zoom and pan move the image within its area
  l.image_fb = view.place(l.area, image_info.width, image_info.height);
  l.image_rect = {static_cast<float>(l.image_fb.x) / fbs,
                  static_cast<float>(fb_h - l.image_fb.y - l.image_fb.height) / fbs,
                  static_cast<float>(l.image_fb.width) / fbs, static_cast<float>(l.image_fb.height) / fbs};
  l.area_rect = {0.0f, 0.0f, io.DisplaySize.x - l.panel_width, io.DisplaySize.y};
  // The overlays of this frame go around the image's middle (ui/layout_report).
  ui::layout::begin_frame({l.area_rect.x, l.area_rect.y, l.area_rect.width, l.area_rect.height},
                          {l.image_rect.x, l.image_rect.y, l.image_rect.width, l.image_rect.height}, ImGui::GetFontSize());
  return l;
}

void Viewer::Impl::draw_panel(const FrameLayout& l, ui::UiRequests& requests) {
  const ImGuiIO& io = ImGui::GetIO();
  if (!settings.presentation) {
    if (l.panel_width > 0.0f) {
      const ui::Box box{io.DisplaySize.x - l.panel_width, 0.0f, l.panel_width, io.DisplaySize.y};
      ui::draw_side_panel(box, settings, panel, status, requests);
      ui::draw_panel_edge(box, scale() / framebuffer_scale, io.DisplaySize.x, settings);
    } else {
      ui::draw_panel_tab(requests);
    }
    ui::draw_image_badges(settings, status);
  } else if (now() - presentation_since < 3.0) {
    ui::draw_hint("Presentation mode: F11 or Esc leaves");
  }
  if (camera_mode) ui::draw_hint("Camera: drag orbits, right-drag pans, wheel dollies; Home resets, O or Esc leaves");
  if (settings.presentation && settings.caption) ui::draw_caption(settings, status);
  ui::draw_help_overlay(panel, io.DisplaySize.x - l.panel_width, io.DisplaySize.y);
  if (!status.notice.text.empty() && now() - status.notice.shown_at < 6.0) ui::draw_notice_toast(status.notice);
}

void Viewer::Impl::draw_overlays(const FrameLayout& l, ui::UiRequests& requests) {
  // Layers, the divider, the probe's cross: never over the panel, however far the image reaches.
  const ui::ImageRect& a = l.area_rect;
  ImGui::GetBackgroundDrawList()->PushClipRect(ImVec2(a.x, a.y), ImVec2(a.x + a.width, a.y + a.height));
  if (!teaching->split_active()) ui::draw_image_overlays(l.image_rect, settings, measure, view_texture->id(), requests);
  teaching->draw_ui(*session, l.image_fb, l.fb_h, framebuffer_scale, a.width, a.height);
  if (!settings.presentation) inspect(l.image_rect, a);
  else inspected.reset();
  ImGui::GetBackgroundDrawList()->PopClipRect();
}

void Viewer::Impl::draw_quit_question() {
  switch (ui::draw_quit_dialog(quit_asking, unsaved_seconds(), quit_after_save || save_job.valid(), status.notice)) {
    case ui::QuitChoice::SaveAndQuit:
      quit_after_save = true;
      screenshot_wanted = true;
      break;
    case ui::QuitChoice::Quit: glfwSetWindowShouldClose(window, GLFW_TRUE); break;
    case ui::QuitChoice::Cancel: quit_asking = quit_after_save = false; break;
    case ui::QuitChoice::None: break;
  }
}

// What the panel's and the overlays' widgets asked for this frame, after the
// UI is built: a restart, a new scene, pause, the stop, saves, modes.
void Viewer::Impl::apply_requests(const ui::UiRequests& requests) {
  if (!requests.load_scene.empty()) load_scene(requests.load_scene);
  else if (requests.restart_render) apply_render_settings();
  if (requests.pause_changed) session->set_paused(settings.paused);
  if (requests.stop_changed) {
    session->set_target_spp(settings.stop_spp);
    session->set_target_seconds(settings.stop_seconds);
    applied.stop_spp = settings.stop_spp;
    applied.stop_seconds = settings.stop_seconds;
  }
  if (requests.save_film) save_film();
  if (requests.export_view) export_view();
  if (requests.export_curve) export_curve();
  if (requests.export_convergence) export_convergence();
  if (requests.toggle_panel) {
    settings.panel_hidden = !settings.panel_hidden;
    view.fit = true;
  }
  if (requests.screenshot) screenshot_wanted = true;
  if (requests.toggle_presentation) set_presentation(!settings.presentation);
  if (requests.toggle_camera_mode) {
    camera_mode = !camera_mode;
    if (camera_mode) teaching->leave_probe_mode();
  }
  if (requests.reset_camera) reset_camera();
  handle_measure_requests(requests.measure);
  if (requests.retry_screenshot && failed_save) {
    ui::ScreenshotData data = std::move(*failed_save);
    failed_save.reset();
    start_save(std::move(data));
  }
}

// --layout-json: the frame's layout, written when it changed (to a temporary
// name, then renamed, so a reader never sees half a file).
void Viewer::Impl::write_layout_report(int fb_w, int fb_h) {
  if (options.layout_json.empty()) return;
  (void)fb_w;
  (void)fb_h;
  int ww = 0, wh = 0;
  glfwGetWindowSize(window, &ww, &wh);
  const ui::Figures& f = measure.figures;
  nlohmann::json extra;
  extra["panel_hidden"] = settings.panel_hidden;
  extra["presentation"] = settings.presentation;
  extra["split"] = teaching->split_active();
  if (const ui::Lab2dState* l = teaching->lab2d(); l && l->lab) {
    const stats::ChiSquareResult chi = l->lab->chi_square();
    extra["lab2d"] = {{"map", l->lab->name()},           {"width", l->lab->map().width},
                      {"height", l->lab->map().height}, {"row", l->picked_row()},
                      {"samples", l->lab->count()},     {"chi_square_p", chi.p_value},
                      {"zero_cell_hits", chi.zero_cell_hits}, {"log_bars", l->log_bars}};
  }
  extra["quit_asking"] = quit_asking;
  extra["view"] = ui::view_mode_label(settings.measure.view_mode);
  extra["done"] = status.stats.done;
  extra["figures"] = {{"source", !f.valid ? "none" : (f.against_reference ? (f.rough_reference ? "rough" : "measured") : "estimated")},
                      {"why_estimated", f.estimate_why},
                      {"estimate_unreliable", f.estimate_unreliable},
                      {"spp", f.spp}};
  extra["messages"] = nlohmann::json::array();
  for (const ui::PanelMessage& m : status.messages) extra["messages"].push_back(m.text);
  const std::string text = ui::layout::report_json(ww, wh, settings.ui_scale, extra.dump());
  if (text == layout_written) return;
  try {
    write_file_atomic(options.layout_json, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    layout_written = text;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pdflab: layout report not written: %s\n", e.what());
  }
}

void Viewer::Impl::draw_gl(const FrameLayout& l) {
  glViewport(0, 0, l.fb_w, l.fb_h);
  glClearColor(0.05f, 0.05f, 0.055f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  if (teaching->split_active())
    teaching->draw_split_image(l.image_fb, settings.exposure_ev, settings.srgb);
  else
    display->draw(l.image_fb, settings.exposure_ev, settings.srgb);
  glViewport(0, 0, l.fb_w, l.fb_h);
  // The panel's background after the image: a zoomed image reaching past its area is cut there.
  if (l.panel_px > 0) {
    glEnable(GL_SCISSOR_TEST);
    glScissor(l.fb_w - l.panel_px, 0, l.panel_px, l.fb_h);
    glClearColor(ui::kPanelBackground[0], ui::kPanelBackground[1], ui::kPanelBackground[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glDisable(GL_SCISSOR_TEST);
  }
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  glfwSwapBuffers(window);
}

void Viewer::Impl::record_frame(Clock::time_point t0, double cpu0) {
  report.work_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  report.cpu_ms = thread_cpu_ms() - cpu0;
  report.drawn = true;
  report.shown_generation = image_info.generation;
  report.shown_preview = image_info.preview;
  report.shown_spp = image_info.spp;
}

void Viewer::Impl::pace(Clock::time_point t0) {
  // Events wake the wait early, so input is never delayed by the pacing.
  const SessionStats& st = status.stats;
  const bool busy = !(st.done || st.paused) || save_job.valid() || screenshot_wanted || references->running() ||
                    ImGui::IsAnyItemActive() || status.now - status.notice.shown_at < 0.5 || teaching->wants_frames();
  const double period = busy ? kFramePeriod : kIdlePeriod;
  const double spent = std::chrono::duration<double>(Clock::now() - t0).count();
  if (spent < period) glfwWaitEventsTimeout(period - spent);
}

bool Viewer::frame(bool paced, bool force_draw) {
  Impl& v = *impl_;
  if (glfwWindowShouldClose(v.window)) return false;
  const auto t0 = Clock::now();
  const double cpu0 = thread_cpu_ms();
  v.report.new_image = false;
  v.report.drawn = false;
  v.handle_input();
  v.service_background();

  int fb_w = 0, fb_h = 0;
  glfwGetFramebufferSize(v.window, &fb_w, &fb_h);
  if (fb_w <= 0 || fb_h <= 0 || glfwGetWindowAttrib(v.window, GLFW_ICONIFIED)) {
    // Minimised: nothing to draw. Sleep until an event (restore) or a timeout
    // that keeps the --screenshot mode and save notices going.
    glfwWaitEventsTimeout(0.1);
    return !glfwWindowShouldClose(v.window);
  }
  if (!v.wants_draw(t0, force_draw)) {
    if (paced) glfwWaitEventsTimeout(kFramePeriod);
    return !glfwWindowShouldClose(v.window);
  }
  if (v.settle_frames > 0) --v.settle_frames;
  v.last_draw = t0;

  v.upload_textures();
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  // The keys down now have been seen: their releases may follow next frame.
  v.pressed_this_frame.clear();
  for (Impl::Release& r : v.deferred_releases) r.seen = true;
  if (v.close_popups) ImGui::ClosePopupToLevel(0, true);
  v.close_popups = false;
  v.fill_status();
  const Impl::FrameLayout layout = v.lay_out(fb_w, fb_h);
  ui::UiRequests requests;
  v.draw_panel(layout, requests);
  v.draw_overlays(layout, requests);
  v.draw_quit_question();
  v.handle_keys();
  ImGui::Render();
  v.write_layout_report(fb_w, fb_h);

  v.apply_requests(requests);
  v.draw_gl(layout);
  v.record_frame(t0, cpu0);
  if (paced) v.pace(t0);
  return !glfwWindowShouldClose(v.window);
}

int Viewer::run() {
  while (frame()) {
  }
  Impl& v = *impl_;
  if (v.cli_mode() && !v.cli_done) {
    // Closed before the image was complete: say so, and don't report success.
    std::fprintf(stderr, "pdflab: error: the window was closed before %u spp; %s was not written\n", v.options.spp,
                 v.options.screenshot.c_str());
    return 1;
  }
  return v.exit_status;
}

const Viewer::FrameReport& Viewer::last_frame() const { return impl_->report; }
ui::ViewerSettings& Viewer::settings() { return impl_->settings; }
void Viewer::request_restart() { impl_->apply_render_settings(); }
std::uint64_t Viewer::session_generation() const { return impl_->session->generation(); }
int Viewer::exit_status() const { return impl_->exit_status; }

int run_viewer(const ViewerOptions& options) {
  Viewer viewer(options);
  return viewer.run();
}

}  // namespace pdflab
