#include "ui/screenshot.h"

#include "renderer/error.h"
#include "renderer/metrics/reference.h"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fcntl.h>
#include <unistd.h>

namespace pdflab::ui {

namespace fs = std::filesystem;

namespace {

void write_text(const std::string& path, const std::string& text) {
  write_file_atomic(path, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
}

void write_all(const ScreenshotData& d, const SavedScreenshot& paths) {
  const float exposure = std::exp2(d.exposure_ev);
  write_file_atomic(paths.png, encode_png(d.rgb, d.width, d.height, d.transfer, exposure));
  write_file_atomic(paths.pfm, encode_pfm(d.rgb, d.width, d.height));
  write_text(paths.json, screenshot_sidecar(d, paths));
}

void remove_quietly(const std::string& path) {
  std::error_code ec;
  fs::remove(path, ec);
}

}  // namespace

std::string screenshot_sidecar(const ScreenshotData& d, const SavedScreenshot& paths) {
  nlohmann::json j;
  put_render_facts(j, {d.scene_name, d.scene_file, d.strategy.to_string(), d.width, d.height, d.max_depth, d.seed,
                      d.spp, d.seconds, d.version});
  j["unbiased"] = d.strategy.is_unbiased();
  j["russian_roulette_depth"] = d.strategy.roulette_depth;  // 0: off
  j["sampler"] = d.strategy.sobol ? "sobol" : "independent";  // +sobol
  if (d.strategy.fastest) j["expanded_from"] = "fastest";
  double total = 0.0;
  for (float w : d.strategy.weights) total += w;
  nlohmann::json weights = nlohmann::json::object();
  for (int i = 0; i < kTechniqueCount; ++i)
    if (d.strategy.weights[i] > 0.0f)
      weights[std::string(technique_name(static_cast<Technique>(i)))] = d.strategy.weights[i] / total;
  j["weights"] = weights;
  const auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  const auto in_file = [&](const Vec3& v) {
    return nlohmann::json::array({static_cast<double>(v.x) + d.origin[0], static_cast<double>(v.y) + d.origin[1],
                                  static_cast<double>(v.z) + d.origin[2]});
  };
  j["camera"] = {{"lookfrom", in_file(d.camera.lookfrom)},
                 {"lookat", in_file(d.camera.lookat)},
                 {"vup", vec(d.camera.vup)},
                 {"vfov", d.camera.vfov_degrees},
                 {"moved", d.camera_moved}};
  if (!d.scene_hash.empty()) j["scene_hash"] = d.scene_hash;
  // The figures the viewer showed, and the reference behind them: a report
  // quotes them with what they were measured against.
  const Figures& f = d.figures;
  nlohmann::json figures;
  figures["source"] = !f.valid ? "none" : (f.against_reference ? (f.rough_reference ? "rough" : "measured") : "estimated");
  if (f.valid) {
    if (!f.estimate_why.empty()) figures["why_estimated"] = f.estimate_why;
    figures["spp"] = f.spp;
    figures["seconds"] = f.seconds;
    if (f.against_reference) {
      figures["relmse"] = f.relmse;
      figures["relmse_interval"] = f.relmse_interval;
      figures["relmse_raw"] = f.relmse_raw;
      if (f.reference_corrected) figures["reference_share"] = f.reference_share;
      figures["efficiency"] = f.efficiency;
      figures["rmse"] = f.rmse;
    }
    figures["estimated_relmse"] = f.estimated_relmse;
    if (f.unbiased) figures["estimated_efficiency"] = f.estimated_efficiency;
    figures["mean_relative_standard_error"] = f.mean_relative_standard_error;
    figures["estimate_unreliable"] = f.estimate_unreliable;
  }
  j["figures"] = figures;
  if (d.reference.loaded) {
    const ScreenshotData::ReferenceFacts& r = d.reference;
    j["reference"] = {{"path", r.path},       {"from_cache", r.from_cache}, {"strategy", r.strategy},
                      {"scene_hash", r.scene_hash}, {"width", r.width},   {"height", r.height},
                      {"max_depth", r.max_depth}, {"spp", r.spp},         {"seconds", r.seconds},
                      {"matches", r.mismatch.empty()}};
    if (!r.mismatch.empty()) j["reference"]["why_not"] = r.mismatch;
  } else {
    j["reference"] = nullptr;
  }
  j["exposure_ev"] = d.exposure_ev;
  j["transfer"] = d.transfer == Transfer::Gamma2 ? "gamma2" : "srgb";
  j["png"] = fs::path(paths.png).filename().string();
  j["pfm"] = fs::path(paths.pfm).filename().string();
  return j.dump(2) + "\n";
}

SavedScreenshot save_screenshot_in(const std::string& folder, const ScreenshotData& data, std::time_t when) {
  if (folder.empty()) throw InputError("the screenshot folder is empty");
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw IoError("cannot create screenshot folder '" + folder + "': " + ec.message());

  char stamp[32];
  std::tm local{};
  localtime_r(&when, &local);
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);

  for (int n = 1; n < 100000; ++n) {
    const std::string stem = (fs::path(folder) / ("pdflab-" + std::string(stamp) + "-" + std::to_string(n))).string();
    SavedScreenshot paths{stem + ".png", stem + ".pfm", stem + ".json"};
    if (fs::exists(paths.png, ec) || fs::exists(paths.pfm, ec)) continue;
    // O_EXCL makes the JSON name a lock: whoever creates it owns the stem.
    const int fd = ::open(paths.json.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) {
      if (errno == EEXIST) continue;
      throw IoError("cannot save a screenshot in '" + folder + "': " + std::strerror(errno));
    }
    ::close(fd);
    try {
      write_all(data, paths);
    } catch (...) {
      remove_quietly(paths.png);
      remove_quietly(paths.pfm);
      remove_quietly(paths.json);
      throw;
    }
    return paths;
  }
  throw IoError("no free screenshot name in '" + folder + "'");
}

SavedScreenshot save_screenshot_as(const std::string& png_path, const ScreenshotData& data) {
  fs::path stem = png_path;
  stem.replace_extension();
  SavedScreenshot paths{png_path, stem.string() + ".pfm", stem.string() + ".json"};
  write_all(data, paths);
  return paths;
}

}  // namespace pdflab::ui
