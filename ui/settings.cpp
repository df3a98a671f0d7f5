#include "ui/settings.h"

#include <algorithm>

namespace pdflab::ui {

Strategy SamplingSettings::strategy() const {
  Strategy s = mixture ? Strategy{} : Strategy::single(single);
  if (mixture) s.weights = weights;
  if (nee_mis) {
    s = Strategy::nee(heuristic);
    s.weights = continuation;
    s.light_choice = light_choice;
  }
  s.parameters = parameters;
  s.roulette_depth = roulette_depth;
  s.guided_roulette = guided_roulette_holds(s, guided_roulette);
  s.sobol = sobol;
  s.fastest = fastest && s == fastest_sampling().strategy_without_name();
  return s;
}

Strategy SamplingSettings::strategy_without_name() const {
  SamplingSettings plain = *this;
  plain.fastest = false;
  return plain.strategy();
}

SamplingSettings fastest_sampling() {
  SamplingSettings s = SamplingSettings::from(Strategy::parse("fastest"));
  s.fastest = true;
  return s;
}

SamplingSettings SamplingSettings::from(const Strategy& strategy) {
  SamplingSettings out;
  out.parameters = strategy.parameters;
  out.roulette_depth = strategy.roulette_depth;
  out.guided_roulette = strategy.guided_roulette;
  out.sobol = strategy.sobol;
  out.fastest = strategy.fastest;
  out.light_choice = strategy.light_choice;
  if (strategy.nee_mis) {
    out.nee_mis = true;
    out.heuristic = strategy.heuristic;
    out.continuation = strategy.weights;
    // What the mixture sliders show if the user leaves nee-mis: the book's 50/50.
    out.weights[static_cast<int>(Technique::Cosine)] = 0.5f;
    out.weights[static_cast<int>(Technique::Light)] = 0.5f;
    return out;
  }
  int used = 0;
  for (int i = 0; i < kTechniqueCount; ++i)
    if (strategy.weights[i] > 0.0f) {
      ++used;
      out.single = static_cast<Technique>(i);
    }
  out.mixture = used != 1;
  out.weights = strategy.weights;
  if (!out.mixture) out.weights[static_cast<int>(out.single)] = 1.0f;
  return out;
}

std::array<float, kTechniqueCount> SamplingSettings::normalised() const {
  const std::array<float, kTechniqueCount> w = strategy().weights;
  double total = 0.0;
  for (float x : w) total += x;
  std::array<float, kTechniqueCount> out{};
  if (!(total > 0.0)) return out;
  for (int i = 0; i < kTechniqueCount; ++i) out[i] = static_cast<float>(w[i] / total);
  return out;
}

std::array<int, 2> two_technique_pair(const SamplingSettings& s, std::array<int, 2> remembered) {
  if (s.nee_mis || !s.mixture) return {-1, -1};
  std::array<int, 2> positive{-1, -1};
  int count = 0;
  for (int i = 0; i < kTechniqueCount; ++i)
    if (s.weights[i] > 0.0f && count++ < 2) positive[static_cast<std::size_t>(count - 1)] = i;
  if (count == 2) return positive;
  if (remembered[0] < 0 || remembered[1] < 0 || remembered[0] == remembered[1]) return {-1, -1};
  for (int i = 0; i < kTechniqueCount; ++i)
    if (i != remembered[0] && i != remembered[1] && s.weights[i] > 0.0f) return {-1, -1};
  return remembered;
}

double unsaved_seconds(const SaveMark& saved, std::uint64_t generation, double seconds) {
  if (saved.generation != generation) return seconds;
  return std::max(0.0, seconds - saved.seconds);
}

const char* preset_label(Preset p) {
  switch (p) {
    case Preset::CosineOnly: return "cosine only";
    case Preset::LightOnly: return "light only";
    case Preset::Book5050: return "book 50/50";
  }
  return "?";
}

SamplingSettings preset_by_key(int key) {
  if (key == 4) return SamplingSettings::from(Strategy::nee());
  if (key == 5) return fastest_sampling();
  return preset_sampling(static_cast<Preset>(std::clamp(key, 1, kPresetCount)));
}

const char* preset_key_label(int key) {
  if (key == 4) return "nee-mis";
  if (key == 5) return "fastest";
  return preset_label(static_cast<Preset>(std::clamp(key, 1, kPresetCount)));
}

int preset_key_of(const SamplingSettings& s) {
  const Strategy strategy = s.strategy();
  for (int key = kPresetKeyCount; key >= 1; --key)
    if (preset_by_key(key).strategy() == strategy) return key;
  return 0;
}

float panel_width_for(float wish, float scale, float window_width) {
  const float most = kMaxPanelShare * window_width;
  return std::max(0.0f, std::min(std::max(wish, kMinPanelWidth) * scale, most));
}

SamplingSettings preset_sampling(Preset p) {
  switch (p) {
    case Preset::CosineOnly: return SamplingSettings::from(Strategy::single(Technique::Cosine));
    case Preset::LightOnly: return SamplingSettings::from(Strategy::single(Technique::Light));
    case Preset::Book5050: break;
  }
  // The book's final image: half cosine, half towards the importance targets.
  SamplingSettings s;
  s.mixture = true;
  s.weights[static_cast<int>(Technique::Cosine)] = 0.5f;
  s.weights[static_cast<int>(Technique::Light)] = 0.5f;
  return s;
}

}  // namespace pdflab::ui
