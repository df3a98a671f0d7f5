#pragma once
// Screenshots: the image at its own resolution as PNG (as displayed: exposure
// and transfer), the linear mean as PFM, and a JSON sidecar describing how it
// was made. No UI code, so tests and the --screenshot mode share it.
#include "renderer/film/image_io.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"
#include "ui/measure.h"

#include <array>
#include <cstdint>
#include <ctime>
#include <string>
#include <vector>

namespace pdflab::ui {

struct ScreenshotData {
  std::vector<float> rgb;  // linear mean radiance, row 0 at the top
  int width = 0, height = 0;
  Transfer transfer = Transfer::Gamma2;
  float exposure_ev = 0.0f;
  // Sidecar facts.
  std::string scene_name, scene_file;
  Strategy strategy;
  std::uint32_t spp = 0;
  double seconds = 0.0;
  std::uint64_t seed = 1;
  int max_depth = 0;
  std::string version;
  std::uint64_t generation = 0;  // not in the sidecar: which render the viewer saved
  Camera camera;                 // as rendered, in the rendering space
  std::array<double, 3> origin{};  // Scene::origin: the sidecar gives the camera in the file's coordinates
  bool camera_moved = false;     // moved in the viewer, not the scene file's
  std::string scene_hash;        // of the view rendered (the camera too when moved): a reference's identity
  // The figures shown for the image, and what they were measured against.
  Figures figures;
  struct ReferenceFacts {
    bool loaded = false;
    bool from_cache = false;
    std::string path, strategy, scene_hash;
    int width = 0, height = 0, max_depth = 0;
    std::uint32_t spp = 0;
    double seconds = 0.0;
    std::string mismatch;  // why it does not measure the image (empty: it does)
  } reference;
};

struct SavedScreenshot {
  std::string png, pfm, json;
};

// The JSON sidecar's text.
std::string screenshot_sidecar(const ScreenshotData& data, const SavedScreenshot& paths);

// Saves into `folder` (created if missing) as pdflab-YYYYMMDD-HHMMSS-N.{png,pfm,json}
// with the smallest N whose three files are all new; the name is reserved
// atomically, so two savers never pick the same one and no earlier file is
// overwritten. Throws IoError (or InputError for a bad folder); nothing is
// left behind on failure.
SavedScreenshot save_screenshot_in(const std::string& folder, const ScreenshotData& data, std::time_t when);

// Saves to exactly `png_path`, with the PFM and JSON beside it (same stem).
SavedScreenshot save_screenshot_as(const std::string& png_path, const ScreenshotData& data);

}  // namespace pdflab::ui
