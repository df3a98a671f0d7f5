#include "ui/preferences.h"

#include "renderer/error.h"
#include "renderer/film/image_io.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace pdflab::ui {

namespace fs = std::filesystem;

std::string preferences_path() {
  const auto env = [](const char* name) {
    const char* v = std::getenv(name);
    return v && *v ? std::string(v) : std::string();
  };
  if (const std::string dir = env("PDFLAB_CONFIG_DIR"); !dir.empty()) return (fs::path(dir) / "viewer.json").string();
  if (const std::string dir = env("XDG_CONFIG_HOME"); !dir.empty())
    return (fs::path(dir) / "pdflab" / "viewer.json").string();
  if (const std::string home = env("HOME"); !home.empty())
    return (fs::path(home) / ".config" / "pdflab" / "viewer.json").string();
  return {};
}

Preferences load_preferences(const std::string& path, std::string& warning) {
  Preferences p;
  warning.clear();
  std::error_code ec;
  if (path.empty() || !fs::exists(path, ec)) return p;
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
  if (!in || j.is_discarded() || !j.is_object()) {
    warning = "the viewer's settings '" + path + "' are damaged and were ignored (defaults used)";
    return p;
  }
  try {
    p.window_width = std::clamp(j.value("window_width", 0), 0, 16384);
    p.window_height = std::clamp(j.value("window_height", 0), 0, 16384);
    p.panel_width = std::clamp(j.value("panel_width", kDefaultPanelWidth), kMinPanelWidth, 4000.0f);
    p.panel_hidden = j.value("panel_hidden", false);
    p.caption = j.value("caption", false);
    if (j.contains("open_sections") && j["open_sections"].is_object()) {
      const nlohmann::json& open = j["open_sections"];
      for (int i = 0; i < kPanelSectionCount; ++i)
        p.open[static_cast<std::size_t>(i)] = open.value(kPanelSections[static_cast<std::size_t>(i)],
                                                         kPanelSectionsOpen[static_cast<std::size_t>(i)]);
    }
  } catch (const nlohmann::json::exception&) {
    warning = "the viewer's settings '" + path + "' have a field of the wrong type and were ignored (defaults used)";
    return Preferences{};
  }
  return p;
}

void save_preferences(const std::string& path, const Preferences& p) {
  if (path.empty()) return;
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  if (ec) throw IoError("cannot create the folder of '" + path + "': " + ec.message());
  nlohmann::json j;
  j["window_width"] = p.window_width;
  j["window_height"] = p.window_height;
  j["panel_width"] = p.panel_width;
  j["panel_hidden"] = p.panel_hidden;
  j["caption"] = p.caption;
  nlohmann::json open = nlohmann::json::object();
  for (int i = 0; i < kPanelSectionCount; ++i)
    open[kPanelSections[static_cast<std::size_t>(i)]] = p.open[static_cast<std::size_t>(i)];
  j["open_sections"] = open;
  const std::string text = j.dump(2) + "\n";
  write_file_atomic(path, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
}

}  // namespace pdflab::ui
