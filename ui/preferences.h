#pragma once
// What the viewer remembers between runs: the window's size, the side panel's
// width and whether it is hidden, which of its sections are open, and the
// presentation caption. A small JSON file; a missing or damaged one gives the
// defaults (a damaged one with a warning), never an error.
#include "ui/settings.h"

#include <string>

namespace pdflab::ui {

struct Preferences {
  int window_width = 0, window_height = 0;  // screen coordinates; 0: fit the image
  float panel_width = kDefaultPanelWidth;   // at UI scale 1
  bool panel_hidden = false;
  std::array<bool, kPanelSectionCount> open = kPanelSectionsOpen;
  bool caption = false;
  bool operator==(const Preferences&) const = default;
};

// $PDFLAB_CONFIG_DIR/viewer.json, else $XDG_CONFIG_HOME/pdflab/viewer.json,
// else $HOME/.config/pdflab/viewer.json (empty when none of them is set).
std::string preferences_path();

// The file's preferences; the defaults when it is missing, and also when it is
// damaged (then `warning` says so). Out-of-range values are brought in range.
Preferences load_preferences(const std::string& path, std::string& warning);
// Writes the file (its folder created) to a temporary name and renames it.
// Throws IoError when that fails.
void save_preferences(const std::string& path, const Preferences& preferences);

}  // namespace pdflab::ui
