#include "renderer/sampling/strategy.h"

#include "renderer/sampling/mixture.h"

#include "renderer/error.h"
#include "renderer/sampling/sobol.h"

#include <charconv>
#include <cmath>
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
  return out + ", mix:TECHNIQUE=W,..., nee-mis, nee-mis:balance, nee-mis+STRATEGY, fastest (each with +sobol, +rr or +rr:D; with guided +rr:guided)";
}

// The shortest decimal that reads back as the same float: a strategy's text
// (a film's header, a sidecar) parses back to the very estimator it names.
std::string format_number(float x) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, x);
  std::string text = ec == std::errc() ? std::string(buf, end) : std::string("nan");
  // 3e+38 as 3e38: '+' joins a strategy's parts, and from_chars reads both.
  if (const std::size_t plus = text.find("e+"); plus != std::string::npos) text.erase(plus + 1, 1);
  return text;
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

// "biased alone: it REASON" at the parameter's default; for a technique
// biased alone at some of its parameter's values only, also an end of the
// range where it is not (or is). Empty where it is unbiased alone.
std::string bias_text(const TechniqueInfo& t) {
  const std::string at_default = t.bias_alone(t.parameter_default);
  const float ends[] = {t.parameter_min, t.parameter_max};
  for (const float end : ends) {
    if (t.parameter.empty() || t.bias_alone(end).empty() == at_default.empty()) continue;
    const std::string at = std::string(t.parameter) + " = " + format_number(end);
    if (at_default.empty()) return "biased alone at " + at + ": it " + t.bias_alone(end);
    return "biased alone: it " + at_default + "; unbiased at " + at;
  }
  return at_default.empty() ? "" : "biased alone: it " + at_default;
}

// "alone on a diffuse surface: infinite variance, as REASON; finite at P = X"
// at the parameter's default; empty where the variance is finite.
std::string heavy_tail_text(const TechniqueInfo& t) {
  const std::string at_default = t.heavy_tail_alone(t.parameter_default);
  if (at_default.empty()) return "";
  std::string out = "alone on a diffuse surface: infinite variance, as " + at_default;
  for (const float end : {t.parameter_min, t.parameter_max})
    if (!t.parameter.empty() && t.heavy_tail_alone(end).empty()) {
      out.append("; finite at ").append(t.parameter).append(" = ").append(format_number(end));
      break;
    }
  return out;
}

}  // namespace

const TechniqueInfo& technique_info(Technique t) { return kTable[static_cast<int>(t)]; }
std::string_view technique_name(Technique t) { return kTable[static_cast<int>(t)].name; }

std::string stratified_vertices() {
  return qmc::kDepths == 1 ? "the first vertex's" : "the first " + std::to_string(qmc::kDepths) + " vertices'";
}

namespace {
// A technique as typed: name, or name[:P] for one with a parameter.
std::string spelled_with_parameter(const TechniqueInfo& t) {
  std::string name(t.name);
  if (!t.parameter.empty()) name.append("[:").append(t.parameter).append("]");
  return name;
}
// "; P in [min, max], default d", or nothing.
std::string parameter_help(const TechniqueInfo& t) {
  if (t.parameter.empty()) return "";
  return "; " + std::string(t.parameter) + " in [" + format_number(t.parameter_min) + ", " +
         format_number(t.parameter_max) + "], default " + format_number(t.parameter_default);
}
// What the technique is alone: its bias and its variance, or "unbiased".
std::string alone_text(const TechniqueInfo& t) {
  const std::string bias = bias_text(t), tail = heavy_tail_text(t);
  if (bias.empty() && tail.empty()) return "unbiased";
  return bias + (bias.empty() || tail.empty() ? "" : "; ") + tail;
}
}  // namespace

std::string technique_grammar() {
  std::string out = "TECHNIQUE := ";
  for (std::size_t i = 0; i < kTable.size(); ++i)
    out.append(i ? " | " : "").append(spelled_with_parameter(kTable[i]));
  return out;
}

std::string technique_table_markdown() {
  std::string out = "| technique | draws | pdf | alone |\n|---|---|---|---|\n";
  for (const TechniqueInfo& t : kTable)
    out.append("| `").append(spelled_with_parameter(t)).append("` | ").append(t.draws).append(parameter_help(t))
        .append(" | `").append(t.pdf).append("` | ").append(alone_text(t)).append(" |\n");
  return out;
}

std::string strategy_help() {
  std::string out =
      "Strategies: BASE[+sobol][+rr[:guided][:D]][+lights:CHOICE] | fastest[+sobol][+rr[:D]][+lights:CHOICE]\n"
      "  BASE := MIXTURE | nee-mis[:balance][+MIXTURE]\n"
      "  MIXTURE := TECHNIQUE | mix:TECHNIQUE=W,TECHNIQUE=W[,...]\n"
      "  nee-mis: a light sample and a continuation at each diffuse vertex, weighed by MIS (power heuristic,\n"
      "    :balance the balance heuristic); the continuation is drawn by MIXTURE (default cosine), e.g.\n"
      "    nee-mis+mix:cosine=0.5,light=0.5 keeps aiming at the book's glass sphere; its light sample takes an\n"
      "    emitter by power (none behind a one-sided light, 2% of the choices uniform), uniformly in solid\n"
      "    angle, or by area from where the light's farthest point is at most twice as far as its nearest\n"
      "    (there the two densities are within a factor 8, area is cheaper)\n"
      "  +rr[:D]: Russian roulette from D path segments on (default " + std::to_string(kDefaultRouletteDepth) +
      "): a path goes on with probability\n"
      "    min(1, largest throughput component), its throughput divided by it (unbiased; off by default)\n"
      "  +rr:guided[:D] (with guided): Russian roulette by the light the guide learned: a path goes on in\n"
      "    proportion to the light it is expected to bring over its pixel's, however small its throughput\n"
      "    (where the guide learned nothing, the throughput rule from D)\n"
      "  +sobol: " + stratified_vertices() +
      " draws (continuation, light sample, specular bounce) from Owen-scrambled Sobol points\n"
      "    stratified across a pixel's samples, the rest from the sample's random stream (unbiased;\n"
      "    off by default: every draw independent)\n"
      "  +lights:CHOICE (nee-mis): how the light sample's emitter is chosen: power (the default, or the scene's\n"
      "    light_choice), uniform, or tree (a light tree: power, distance and orientation from the point)\n"
      "  fastest: pdflab's most efficient unbiased strategy for general scenes, now " + std::string(kFastestStrategy) +
      "\n    (where a scene sets fastest_uses_guiding, its light hard to find: " + std::string(kFastestGuidedStrategy) +
      ")\nTechniques:\n";
  for (const TechniqueInfo& t : kTable) {
    const std::string name = spelled_with_parameter(t);
    out.append("  ").append(name).append(name.size() < 22 ? 22 - name.size() : 1, ' ');
    out.append(t.draws).append("; pdf ").append(t.pdf).append(parameter_help(t));
    for (const std::string& note : {bias_text(t), heavy_tail_text(t)})
      if (!note.empty()) out.append(" (").append(note).append(")");
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
  Strategy s = single(Technique::Cosine);
  s.nee_mis = true;
  s.heuristic = h;
  return s;
}

namespace {

// TECHNIQUE or mix:TECHNIQUE=W,... (`whole` is the full text, for messages).
Strategy parse_mixture(std::string_view text, std::string_view whole) {
  if (text.empty()) throw InputError("strategy '" + std::string(whole) + "': the mixture is empty");
  if (text.find('+') != std::string_view::npos)
    throw InputError("strategy '" + std::string(whole) + "': '+' joins only nee-mis, its continuation, sobol and rr");
  constexpr std::string_view kMix = "mix:";
  if (text.substr(0, kMix.size()) != kMix) {
    const ParsedTechnique p = parse_technique(text, whole);
    Strategy s = Strategy::single(p.technique);
    s.parameters[static_cast<int>(p.technique)] = p.parameter;
    return s;
  }

  Strategy s;
  std::array<bool, kTechniqueCount> seen{};
  std::string_view rest = text.substr(kMix.size());
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

// rr, rr:D, rr:guided or rr:guided:D (`guided` set for the last two).
int parse_roulette(std::string_view text, std::string_view whole, bool& guided) {
  guided = text == "rr:guided" || text.substr(0, 10) == "rr:guided:";
  if (text == "rr" || text == "rr:guided") return kDefaultRouletteDepth;
  const std::string_view depth = text.substr(guided ? 10 : text.find(':') + 1);
  int value = 0;
  const auto* end = depth.data() + depth.size();
  auto [ptr, ec] = std::from_chars(depth.data(), end, value);
  if (text.substr(0, 3) != "rr:" || depth.empty() || ec != std::errc() || ptr != end || value < 1 ||
      value > kMaxRouletteDepth)
    throw InputError("strategy '" + std::string(whole) + "': '" + std::string(text) +
                     "' is not rr, rr:D, rr:guided or rr:guided:D with D, the first depth of Russian roulette "
                     "(by throughput), an integer in 1.." +
                     std::to_string(kMaxRouletteDepth));
  return value;
}

}  // namespace

Strategy Strategy::parse(std::string_view text) {
  const std::string_view whole = trim(text);
  if (whole.empty()) throw InputError("empty strategy; expected one of: " + known_list());
  std::string_view body = whole;
  // Last terms `sobol` and `rr[:D]`, in either order, choose the sampler and
  // turn on Russian roulette.
  int roulette = 0;
  bool guided_roulette = false;
  bool sobol = false;
  std::optional<LightChoice> lights;
  for (;;) {
    const std::size_t last_plus = body.rfind('+');
    if (last_plus == std::string_view::npos) break;
    const std::string_view term = trim(body.substr(last_plus + 1));
    if (term.substr(0, 7) == "lights:" && !lights) {
      LightChoice c;
      if (!parse_light_choice(trim(term.substr(7)), c))
        throw InputError("strategy '" + std::string(whole) + "': the light choice must be 'power', 'uniform' or 'tree'");
      lights = c;
    } else if (term.substr(0, 2) == "rr" && !roulette) {
      roulette = parse_roulette(term, whole, guided_roulette);
    } else if (term == "sobol" && !sobol) {
      sobol = true;
    } else {
      break;
    }
    body = trim(body.substr(0, last_plus));
  }
  const auto no_guide = [&] {
    return InputError("strategy '" + std::string(whole) +
                      "': +rr:guided is Russian roulette by the light the guided technique learns, and the strategy "
                      "has no guided technique");
  };
  Strategy s;
  if (body == "fastest") {
    if (guided_roulette) throw no_guide();
    s = parse(kFastestStrategy);
    s.fastest = true;
    if (roulette) s.roulette_depth = roulette;
    if (sobol) s.sobol = true;
    s.light_choice = lights;
    return s;
  }
  if (body.substr(0, 7) == "nee-mis") {
    const std::size_t plus = body.find('+');
    const std::string_view head = trim(body.substr(0, plus));
    MisHeuristic h = MisHeuristic::Power;
    if (head == "nee-mis" || head == "nee-mis:power") h = MisHeuristic::Power;
    else if (head == "nee-mis:balance") h = MisHeuristic::Balance;
    else if (head.substr(0, 8) == "nee-mis:")
      throw InputError("strategy '" + std::string(whole) + "': the heuristic must be 'power' or 'balance'");
    else
      throw InputError("unknown strategy '" + std::string(whole) + "'; expected one of: " + known_list());
    s = nee(h);
    if (plus != std::string_view::npos) {
      const Strategy continuation = parse_mixture(trim(body.substr(plus + 1)), whole);
      s.weights = continuation.weights;
      s.parameters = continuation.parameters;
    }
  } else {
    s = parse_mixture(body, whole);
  }
  if (lights && !s.nee_mis)
    throw InputError("strategy '" + std::string(whole) + "': +lights chooses nee-mis's light sample; the strategy has none");
  if (guided_roulette && !s.uses(Technique::Guided)) throw no_guide();
  s.roulette_depth = roulette;
  s.guided_roulette = guided_roulette;
  s.sobol = sobol;
  s.light_choice = lights;
  return s;
}

bool Strategy::cosine_continuation() const {
  for (int i = 0; i < kTechniqueCount; ++i)
    if ((weights[i] > 0.0f) != (static_cast<Technique>(i) == Technique::Cosine)) return false;
  return true;
}

std::string Strategy::to_string() const {
  std::string out;
  if (nee_mis) {
    out = heuristic == MisHeuristic::Power ? "nee-mis" : "nee-mis:balance";
    if (!cosine_continuation()) out.append("+").append(mixture_string());
  } else {
    out = mixture_string();
  }
  if (sobol) out.append("+sobol");
  if (roulette_depth > 0) {
    out.append(guided_roulette ? "+rr:guided" : "+rr");
    if (roulette_depth != kDefaultRouletteDepth) out.append(":").append(std::to_string(roulette_depth));
  }
  if (light_choice) out.append("+lights:").append(light_choice_name(*light_choice));
  return out;
}

std::string Strategy::mixture_string() const {
  int used = 0, last = 0;
  for (int i = 0; i < kTechniqueCount; ++i)
    if (weights[i] > 0.0f) ++used, last = i;
  double total = 0.0;  // in double: weights near FLT_MAX would overflow a float sum
  for (float w : weights) total += w;
  // Shares (weights over their total) where the total is a power of two (1
  // for cosine=0.5,light=0.5, 4 for cosine=1,light=3): dividing by it is exact,
  // so the shares parse back to weights in exactly the same proportions and
  // the sampler's choice (SamplingPlan, from w / total) is the same bits.
  // Otherwise (cosine=1,light=2) the weights as given, which parse back to
  // themselves; rounded shares (0.333333) would choose another estimator.
  int exponent = 0;
  const bool power_of_two = std::frexp(total, &exponent) == 0.5;
  const double scale = power_of_two ? std::ldexp(1.0, 1 - exponent) : 1.0;
  bool exact = true;  // every scaled weight a float (no underflow)
  for (float w : weights)
    exact = exact && static_cast<double>(static_cast<float>(w * scale)) == static_cast<double>(w) * scale;
  const double divisor = exact ? 1.0 / scale : 1.0;
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
    if (!first) out += ',';
    out.append(spelled(i)).append("=").append(format_number(static_cast<float>(weights[i] / divisor)));
    first = false;
  }
  return out;
}

bool Strategy::is_unbiased() const {
  for (int i = 0; i < kTechniqueCount; ++i)
    if (uses(static_cast<Technique>(i)) && kTable[i].bias_alone(parameters[i]).empty()) return true;
  return false;
}

std::string Strategy::bias_reason() const {
  if (is_unbiased()) return {};
  std::string out;
  for (int i = 0; i < kTechniqueCount; ++i) {
    if (!uses(static_cast<Technique>(i))) continue;
    const TechniqueInfo& t = kTable[i];
    std::string name(t.name);
    if (!t.parameter.empty()) name.append(":").append(format_number(parameters[i]));
    out.append(out.empty() ? "" : ", ").append(name).append(" ").append(t.bias_alone(parameters[i]));
  }
  if (nee_mis) out.insert(0, "its continuation misses light: ");
  return out;
}

}  // namespace pdflab
