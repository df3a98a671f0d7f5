#pragma once
// Strategies taken from the technique table for the image-level suites (the
// packet tracer against the one-path tracer, the analytic scenes, the white
// furnace, the convergence of every unbiased strategy to one image): a
// technique added to the table (docs/adding_a_technique.md) enters each of
// them with no edit.
#include "renderer/sampling/strategy.h"

#include <algorithm>
#include <string>
#include <vector>

namespace pdflab::testing {

struct TableStrategy {
  std::string text;
  Technique technique;  // the table's technique it is made of
  // Unbiased, with finite variance on a diffuse surface: an image the
  // statistical suites can compare within standard errors.
  bool unbiased;
  bool aims;  // it draws targets (the techniques that draw one: light, light-sa, ...)
  // It draws from the scene's environment map (`environment`): in a scene
  // without one it has no weight, and a mixture with cosine is cosine again,
  // so the suites whose scenes have no map leave it out and test it on their
  // own scenes with a map (test_analytic's EnvironmentFloor, test_convergence's SunAndSky).
  bool needs_environment;
};

// Each technique alone, at its parameter's default and, where the technique is
// biased or heavy-tailed there (TechniqueInfo::bias, heavy_tail) but not at an
// end of its parameter's range, also at that end; then each technique mixed
// half and half with cosine.
inline std::vector<TableStrategy> table_strategies() {
  std::vector<TableStrategy> out;
  auto add = [&](const std::string& text, Technique t, float p) {
    const Strategy s = Strategy::parse(text);
    const bool alone = text.rfind("mix:", 0) != 0;
    const bool tame = !alone || technique_info(t).heavy_tail_alone(p).empty();
    out.push_back({text, t, s.is_unbiased() && tame, technique_info(t).draws_target, t == Technique::EnvironmentMap});
  };
  for (int i = 0; i < kTechniqueCount; ++i) {
    const auto t = static_cast<Technique>(i);
    const TechniqueInfo& info = technique_info(t);
    const std::string name(info.name);
    add(name, t, info.parameter_default);
    if (!info.parameter.empty() && !out.back().unbiased)
      for (const float end : {info.parameter_min, info.parameter_max}) {
        char text[64];
        std::snprintf(text, sizeof text, "%s:%g", name.c_str(), static_cast<double>(end));
        if (Strategy::parse(text).is_unbiased() && info.heavy_tail_alone(end).empty()) {
          add(text, t, end);
          break;
        }
      }
  }
  for (int i = 0; i < kTechniqueCount; ++i) {
    const auto t = static_cast<Technique>(i);
    if (t != Technique::Cosine)
      add("mix:cosine=0.5," + std::string(technique_info(t).name) + "=0.5", t, technique_info(t).parameter_default);
  }
  return out;
}

// `listed` followed by the table's strategies that `keep` accepts and that
// `listed` does not already hold.
template <class Keep>
std::vector<std::string> with_table_strategies(std::vector<std::string> listed, Keep keep) {
  for (const TableStrategy& s : table_strategies())
    if (keep(s) && std::find(listed.begin(), listed.end(), s.text) == listed.end()) listed.push_back(s.text);
  return listed;
}

// A strategy's text as a test name: letters and digits, the rest '_'.
inline std::string test_name(std::string text) {
  for (char& c : text)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return text;
}

}  // namespace pdflab::testing
