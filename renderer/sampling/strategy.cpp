#include "renderer/sampling/strategy.h"

#include "renderer/sampling/mixture.h"

#include "renderer/error.h"

#include <charconv>
#include <numbers>
#include <cstdio>

namespace pdflab {

namespace {

constexpr std::array<TechniqueInfo, kTechniqueCount> kTable = {
#define PDFLAB_ROW(T) leaf::T::info,
    PDFLAB_TECHNIQUES(PDFLAB_ROW)
#undef PDFLAB_ROW
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::string known_list() {
  std::string out;
  for (const TechniqueInfo& t : kTable) {
    if (!out.empty()) out += ", ";
    out.append(t.name);
    if (!t.parameter.empty()) out.append("[:").append(t.parameter).append("]");
  }
  return out + ", mix:TECHNIQUE=W,..., nee-mis, nee-mis:balance";
}

std::string format_number(float x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", static_cast<double>(x));
  return buf;
}

float parse_parameter(const TechniqueInfo& t, std::string_view text, std::string_view whole) {
  float value = 0.0f;
  const auto* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || !(value >= t.parameter_min && value <= t.parameter_max))
    throw InputError("strategy '" + std::string(whole) + "': " + std::string(t.name) + "'s " +
                     std::string(t.parameter) + " '" + std::string(text) + "' is not a number in [" +
                     format_number(t.parameter_min) + ", " + format_number(t.parameter_max) + "]");
  return value;
}

struct ParsedTechnique {
  Technique technique;
  float parameter;
};

// NAME or NAME:PARAMETER, for a technique whose row has a parameter.
ParsedTechnique parse_technique(std::string_view text, std::string_view whole) {
  const size_t colon = text.find(':');
  const std::string_view name = text.substr(0, colon);
  for (int i = 0; i < kTechniqueCount; ++i) {
    const TechniqueInfo& t = kTable[i];
    if (t.name != name) continue;
    if (colon == std::string_view::npos) return {static_cast<Technique>(i), t.parameter_default};
    if (t.parameter.empty())
      throw InputError("strategy '" + std::string(whole) + "': technique '" + std::string(name) +
                       "' takes no parameter");
    return {static_cast<Technique>(i), parse_parameter(t, text.substr(colon + 1), whole)};
  }
  if (name.substr(0, 7) == "nee-mis")
    throw InputError("strategy '" + std::string(whole) + "': nee-mis is a strategy of its own and cannot be mixed");
  throw InputError("unknown strategy '" + std::string(whole) + "'" +
                   (name != whole ? " (unknown technique '" + std::string(name) + "')" : "") +
                   "; expected one of: " + known_list());
}

float parse_weight(std::string_view text, std::string_view whole) {
  // std::from_chars for float is available in GCC 12's libstdc++.
  float value = 0.0f;
  const auto* begin = text.data();
  const auto* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(begin, end, value);
  if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(value) || value < 0.0f)
    throw InputError("strategy '" + std::string(whole) + "': weight '" + std::string(text) +
                     "' is not a finite number >= 0");
  return value;
}

}  // namespace

const TechniqueInfo& technique_info(Technique t) { return kTable[static_cast<int>(t)]; }
std::string_view technique_name(Technique t) { return kTable[static_cast<int>(t)].name; }

std::string strategy_help() {
  std::string out =
      "Strategies: TECHNIQUE | mix:TECHNIQUE=W,TECHNIQUE=W[,...] | nee-mis | nee-mis:balance\nTechniques:\n";
  for (const TechniqueInfo& t : kTable) {
    std::string name(t.name);
    if (!t.parameter.empty())
      name.append("[:").append(t.parameter).append("]");
    out.append("  ").append(name).append(name.size() < 20 ? 20 - name.size() : 1, ' ');
    out.append(t.draws).append("; pdf ").append(t.pdf);
    if (!t.parameter.empty())
      out.append("; ").append(t.parameter).append(" in [").append(format_number(t.parameter_min)).append(", ")
          .append(format_number(t.parameter_max)).append("], default ").append(format_number(t.parameter_default));
    if (!t.covers_hemisphere) out.append(" (biased alone: sees only its targets)");
    out.append("\n");
  }
  return out;
}

std::array<float, kTechniqueCount> Strategy::default_parameters() {
  std::array<float, kTechniqueCount> p{};
  for (int i = 0; i < kTechniqueCount; ++i) p[i] = kTable[i].parameter_default;
  return p;
}

Strategy Strategy::single(Technique t) {
  Strategy s;
  s.weights[static_cast<int>(t)] = 1.0f;
  return s;
}

Strategy Strategy::nee(MisHeuristic h) {
  Strategy s;
  s.nee_mis = true;
  s.heuristic = h;
  return s;
}

Strategy Strategy::parse(std::string_view text) {
  const std::string_view whole = trim(text);
  if (whole.empty()) throw InputError("empty strategy; expected one of: " + known_list());
  if (whole == "nee-mis" || whole == "nee-mis:power") return nee(MisHeuristic::Power);
  if (whole == "nee-mis:balance") return nee(MisHeuristic::Balance);
  if (whole.substr(0, 8) == "nee-mis:")
    throw InputError("strategy '" + std::string(whole) + "': the heuristic must be 'power' or 'balance'");
  constexpr std::string_view kMix = "mix:";
  if (whole.substr(0, kMix.size()) != kMix) {
    const ParsedTechnique p = parse_technique(whole, whole);
    Strategy s = single(p.technique);
    s.parameters[static_cast<int>(p.technique)] = p.parameter;
    return s;
  }

  Strategy s;
  std::array<bool, kTechniqueCount> seen{};
  std::string_view rest = whole.substr(kMix.size());
  if (trim(rest).empty()) throw InputError("strategy '" + std::string(whole) + "': the mixture lists no technique");
  while (true) {
    const size_t comma = rest.find(',');
    const std::string_view term = trim(rest.substr(0, comma));
    const size_t eq = term.find('=');
    if (eq == std::string_view::npos)
      throw InputError("strategy '" + std::string(whole) + "': term '" + std::string(term) +
                       "' is not TECHNIQUE=WEIGHT");
    const ParsedTechnique p = parse_technique(trim(term.substr(0, eq)), whole);
    const Technique t = p.technique;
    const int i = static_cast<int>(t);
    s.parameters[i] = p.parameter;
    if (seen[i])
      throw InputError("strategy '" + std::string(whole) + "': technique '" +
                       std::string(technique_name(t)) + "' appears twice");
    seen[i] = true;
    s.weights[i] = parse_weight(trim(term.substr(eq + 1)), whole);
    if (comma == std::string_view::npos) break;
    rest = rest.substr(comma + 1);
  }
  float total = 0.0f;
  for (float w : s.weights) total += w;
  if (!(total > 0.0f)) throw InputError("strategy '" + std::string(whole) + "': all weights are zero");
  return s;
}

std::string Strategy::to_string() const {
  if (nee_mis) return heuristic == MisHeuristic::Power ? "nee-mis" : "nee-mis:balance";
  int used = 0, last = 0;
  for (int i = 0; i < kTechniqueCount; ++i)
    if (weights[i] > 0.0f) ++used, last = i;
  double total = 0.0;  // in double: weights near FLT_MAX would overflow a float sum
  for (float w : weights) total += w;
  // NAME, or NAME:PARAMETER for a technique with one.
  auto spelled = [&](int i) {
    std::string name(kTable[i].name);
    if (!kTable[i].parameter.empty()) name.append(":").append(format_number(parameters[i]));
    return name;
  };
  if (used == 1) return spelled(last);
  std::string out = "mix:";
  bool first = true;
  for (int i = 0; i < kTechniqueCount; ++i) {
    if (weights[i] <= 0.0f) continue;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", static_cast<double>(weights[i]) / total);
    if (!first) out += ',';
    out.append(spelled(i)).append("=").append(buf);
    first = false;
  }
  return out;
}

bool Strategy::is_unbiased() const {
  if (nee_mis) return true;
  for (int i = 0; i < kTechniqueCount; ++i)
    if (kTable[i].covers_hemisphere && uses(static_cast<Technique>(i))) return true;
  return false;
}

}  // namespace pdflab
