#include "renderer/metrics/reference.h"

#include "renderer/error.h"
#include "renderer/film/exr_io.h"
#include "renderer/film/film.h"
#include "renderer/film/film_file.h"
#include "renderer/film/image_io.h"
#include "renderer/hash.h"
#include "renderer/input_file.h"
#include "renderer/metrics/metrics.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/scene.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

namespace pdflab {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr const char* kFormat = "pdflab-reference";
constexpr int kFormatVersion = 1;

// A sidecar or an image whose checksum is taken: a regular file, never a pipe.
std::string read_bytes(const std::string& path, const char* what) {
  return read_input_file(path, what, std::numeric_limits<std::size_t>::max());
}

std::string file_checksum(const std::string& path) {
  const std::string bytes = read_bytes(path, "file");
  return fnv1a_hex(bytes.data(), bytes.size());
}

// A reference with NaN or infinity would turn every error into NaN and rank
// strategies at random; a negative variance is no variance. Say where the first bad value is.
void check_values(const std::string& path, const std::vector<float>& values, int width, bool variance) {
  std::size_t bad = 0, first = 0;
  for (std::size_t i = 0; i < values.size(); ++i)
    if ((!std::isfinite(values[i]) || (variance && values[i] < 0.0f)) && bad++ == 0) first = i;
  if (bad == 0) return;
  const std::size_t pixel = first / 3, w = static_cast<std::size_t>(width);
  throw InputError((variance ? "variance file '" : "reference '") + path + "' has " + std::to_string(bad) +
                   (variance ? " values that are negative or not finite" : " values that are not finite") +
                   " (first at pixel " + std::to_string(pixel % w) + "," + std::to_string(pixel / w) + ")");
}

template <class T>
T field(const json& j, const char* key, T fallback) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return fallback;
  return it->get<T>();
}

json parse_json(const std::string& path) {
  try {
    json j = json::parse(read_bytes(path, "sidecar"));
    if (j.is_object()) return j;
  } catch (const json::exception&) {
    throw InputError("sidecar '" + path + "' is not valid JSON (truncated or damaged)");
  }
  throw InputError("sidecar '" + path + "' is not a JSON object");
}

ReferenceInfo parse_sidecar(const std::string& path, const json& j) {
  ReferenceInfo info;
  try {
    info.has_sidecar = true;
    info.is_reference = field<std::string>(j, "format", "") == kFormat;
    info.scene_name = field<std::string>(j, "scene", "");
    info.scene_file = field<std::string>(j, "scene_file", "");
    info.scene_hash = field<std::string>(j, "scene_hash", "");
    info.max_depth = field<int>(j, "max_depth", 0);
    info.strategy = field<std::string>(j, "strategy", "");
    // "seeds" (a render's sidecar lists every seed of a merge), else "seed".
    std::vector<std::uint64_t> seeds;
    if (j.contains("seeds") && j["seeds"].is_array())
      for (const json& seed : j["seeds"]) seeds.push_back(seed.get<std::uint64_t>());
    else if (j.contains("seed") && j["seed"].is_number_unsigned())
      seeds.push_back(j["seed"].get<std::uint64_t>());
    set_seeds(info, seeds);
    if (info.seed_known && is_reference_seed(info.seed))
      info.seed_stream = static_cast<std::uint32_t>(info.seed - kReferenceSeedBase);
    info.spp = field<std::uint32_t>(j, "spp", 0);
    info.seconds = field<double>(j, "seconds", 0.0);
    info.estimated_relmse = field<double>(j, "estimated_relmse", 0.0);
    info.version = field<std::string>(j, "version", "");
  } catch (const json::exception&) {
    throw InputError("sidecar '" + path + "' has a field of the wrong type");
  }
  return info;
}

}  // namespace

ReferencePaths reference_paths(const std::string& mean_path) {
  fs::path p(mean_path);
  ReferencePaths r;
  r.mean = mean_path;
  fs::path stem = p;
  stem.replace_extension();
  r.variance = stem.string() + ".var.pfm";
  r.sidecar = stem.string() + ".json";
  return r;
}

Reference reference_from_film(const Film& film, ReferenceInfo info) {
  Reference r;
  r.width = film.width();
  r.height = film.height();
  std::vector<float> map;
  const NoiseSummary noise = noise_summary(film, map, kRelMseEpsilon, &r.rgb);
  r.variance.resize(r.rgb.size());
  for (std::size_t p = 0; p < film.pixel_count(); ++p) {
    double v[3];
    film.variance_of_mean(p, v);
    for (int c = 0; c < 3; ++c) r.variance[3 * p + static_cast<std::size_t>(c)] = static_cast<float>(v[c]);
  }
  info.estimated_relmse = noise.estimated_relmse;
  r.info = std::move(info);
  return r;
}

void put_render_facts(json& j, const RenderFacts& f) {
  j["scene"] = f.scene_name;
  j["scene_file"] = f.scene_file;
  j["strategy"] = f.strategy;
  j["width"] = f.width;
  j["height"] = f.height;
  j["max_depth"] = f.max_depth;
  j["seed"] = f.seed;
  j["spp"] = f.spp;
  j["seconds"] = f.seconds;
  j["version"] = f.version;
}

void save_reference(const std::string& mean_path, const Reference& ref) {
  const ReferencePaths paths = reference_paths(mean_path);
  check_output_path(paths.mean);
  if (!ref.has_variance()) throw InputError("a reference needs its variance to be saved");
  const std::vector<std::uint8_t> mean = encode_pfm(ref.rgb, ref.width, ref.height);
  const std::vector<std::uint8_t> variance = encode_pfm(ref.variance, ref.width, ref.height);
  const ReferenceInfo& i = ref.info;
  json j;
  j["format"] = kFormat;
  j["format_version"] = kFormatVersion;
  put_render_facts(j, {i.scene_name, i.scene_file, i.strategy, ref.width, ref.height, i.max_depth, i.seed, i.spp,
                      i.seconds, i.version});
  j["scene_hash"] = i.scene_hash;
  j["seed_stream"] = i.seed_stream;
  j["estimated_relmse"] = i.estimated_relmse;
  j["mean_file"] = fs::path(paths.mean).filename().string();
  j["variance_file"] = fs::path(paths.variance).filename().string();
  j["mean_checksum"] = fnv1a_hex(mean.data(), mean.size());
  j["variance_checksum"] = fnv1a_hex(variance.data(), variance.size());
  const std::string text = j.dump(2) + "\n";
  write_file_atomic(paths.variance, variance);
  write_file_atomic(paths.mean, mean);
  write_file_atomic(paths.sidecar, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
}

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// A film file (film_file.h) as a reference: its mean and variance of the mean,
// and what it records. A film of one seed says which; a merge of several
// seeds leaves the seed unknown.
Reference load_film_reference(const std::string& path) {
  FilmFile file = read_film_file(path);  // InputError naming the file
  const FilmInfo& f = file.info;
  ReferenceInfo info;
  info.has_sidecar = true;  // the film records what a sidecar would
  info.scene_file = f.scene_file;
  char hash[24];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(f.scene_hash));
  info.scene_hash = hash;
  info.max_depth = f.max_depth;
  info.strategy = f.strategy;
  std::vector<std::uint64_t> seeds;
  for (const SampleRange& range : f.ranges) seeds.push_back(range.seed);
  set_seeds(info, seeds);  // every seed of a merge, one or several
  info.spp = static_cast<std::uint32_t>(f.spp());
  info.seconds = f.seconds;
  Reference r = reference_from_film(file.film, std::move(info));
  r.path = path;
  return r;
}

// An EXR: R, G, B, and the variance layers when it has them (pdflab's EXRs do).
Reference load_exr_reference(const std::string& path) {
  Reference r;
  r.path = path;
  r.rgb = read_exr(path, r.width, r.height);  // InputError naming the file
  check_values(path, r.rgb, r.width, false);
  r.variance = read_exr_variance(path);
  if (!r.variance.empty()) check_values(path, r.variance, r.width, true);
  r.info.strategy = read_exr_attribute(path, "pdflab.strategy");
  // pdflab.seeds lists every seed; an EXR written before it has pdflab.seed
  // (one range) or only pdflab.samples ("seed 1 samples [0, 64), ...").
  std::string seeds = read_exr_attribute(path, "pdflab.seeds");
  if (seeds.empty()) seeds = read_exr_attribute(path, "pdflab.seed");
  if (seeds.empty()) {
    const std::string samples = read_exr_attribute(path, "pdflab.samples");
    for (std::size_t at = samples.find("seed "); at != std::string::npos; at = samples.find("seed ", at + 5))
      seeds += std::to_string(std::strtoull(samples.c_str() + at + 5, nullptr, 10)) + ",";
  }
  std::vector<std::uint64_t> list;
  for (std::size_t at = 0; at < seeds.size();) {
    char* end = nullptr;
    const std::uint64_t seed = std::strtoull(seeds.c_str() + at, &end, 10);
    if (end == seeds.c_str() + at) break;
    list.push_back(seed);
    at = static_cast<std::size_t>(end - seeds.c_str());
    if (at < seeds.size() && seeds[at] == ',') ++at;
  }
  set_seeds(r.info, list);
  r.info.spp = static_cast<std::uint32_t>(std::strtoul(read_exr_attribute(path, "pdflab.spp").c_str(), nullptr, 10));
  r.info.has_sidecar = !r.info.strategy.empty();
  return r;
}

}  // namespace

Reference load_reference(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".film") return load_film_reference(path);
  if (ext == ".exr") return load_exr_reference(path);
  const ReferencePaths paths = reference_paths(path);
  Reference r;
  r.path = path;
  r.rgb = read_pfm(path, r.width, r.height);  // InputError naming the file
  check_values(path, r.rgb, r.width, false);
  std::error_code ec;
  if (fs::is_regular_file(paths.sidecar, ec)) try {
    const json j = parse_json(paths.sidecar);
    r.info = parse_sidecar(paths.sidecar, j);
    if (r.info.is_reference) {
      const int w = field<int>(j, "width", 0), h = field<int>(j, "height", 0);
      if (w != r.width || h != r.height)
        throw InputError("reference '" + path + "' is " + std::to_string(r.width) + "x" + std::to_string(r.height) +
                         " but its sidecar says " + std::to_string(w) + "x" + std::to_string(h));
      if (field<std::string>(j, "mean_checksum", "") != file_checksum(path))
        throw InputError("reference '" + path + "' does not match the checksum in its sidecar (changed or damaged)");
      if (!fs::is_regular_file(paths.variance, ec))
        throw InputError("reference '" + path + "': its variance file '" + paths.variance + "' is missing");
      if (field<std::string>(j, "variance_checksum", "") != file_checksum(paths.variance))
        throw InputError("variance file '" + paths.variance +
                         "' does not match the checksum in its sidecar (changed or damaged)");
      int vw = 0, vh = 0;
      r.variance = read_pfm(paths.variance, vw, vh);
      if (vw != r.width || vh != r.height)
        throw InputError("variance file '" + paths.variance + "' is not the size of its reference");
      check_values(paths.variance, r.variance, r.width, true);
    }
  } catch (const json::exception&) {
    throw InputError("sidecar '" + paths.sidecar + "' has a field of the wrong type");
  }
  return r;
}

void set_seeds(ReferenceInfo& info, std::vector<std::uint64_t> seeds) {
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  info.seed_known = !seeds.empty();
  info.seed = seeds.empty() ? 0 : seeds.front();
  info.seeds = std::move(seeds);
}

std::string shared_random_numbers(const ReferenceInfo& reference, std::uint64_t seed, const Strategy& strategy) {
  if (!reference.seed_known) return {};
  const bool listed = std::find(reference.seeds.begin(), reference.seeds.end(), seed) != reference.seeds.end();
  if (reference.seed != seed && !listed) return {};
  const bool same_strategy = reference.strategy == strategy.to_string();
  return "the reference was rendered with seed " + std::to_string(seed) + (same_strategy ? " and strategy " : "") +
         (same_strategy ? reference.strategy : std::string()) +
         ", the same as this render: the two would share random numbers and the error would look too small";
}

Strategy default_reference_strategy(const Scene& scene) {
  if (scene.environment && scene.environment->sampleable())
    return Strategy::parse("nee-mis+mix:cosine=0.5,environment=0.5");
  const Strategy book = Strategy::parse("mix:cosine=0.5,light=0.5");
  try {
    (void)SamplingPlan::make(book, scene);
    return book;
  } catch (const InputError&) {
    return Strategy::single(Technique::Cosine);
  }
}

Strategy reference_strategy(const std::string& text, int roulette_depth, const Scene& scene) {
  return for_scene(with_roulette(text.empty() ? default_reference_strategy(scene) : Strategy::parse(text), roulette_depth),
                   scene);
}

std::string reference_cache_dir(const std::string& option) {
  if (!option.empty()) return option;
  if (const char* env = std::getenv("PDFLAB_REFERENCE_CACHE"); env && *env) return env;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return (fs::path(xdg) / "pdflab" / "references").string();
  if (const char* home = std::getenv("HOME"); home && *home)
    return (fs::path(home) / ".cache" / "pdflab" / "references").string();
  return (fs::path(".cache") / "pdflab" / "references").string();
}

std::string ReferenceKey::stem() const {
  return scene_hash + "-" + std::to_string(width) + "x" + std::to_string(height) + "-d" + std::to_string(max_depth);
}

ReferenceKey reference_key(const Scene& scene) {
  ReferenceKey k;
  k.scene_hash = scene.content_hash.empty() ? std::string("unhashed") : scene.content_hash;
  k.width = scene.camera.width;
  k.height = scene.camera.height;
  k.max_depth = scene.max_depth;
  return k;
}

std::string cached_reference_path(const std::string& cache_dir, const ReferenceKey& key) {
  return (fs::path(cache_dir) / (key.stem() + ".pfm")).string();
}

CacheLookup find_cached_reference(const std::string& cache_dir, const ReferenceKey& key) {
  CacheLookup out;
  out.path = cached_reference_path(cache_dir, key);
  std::error_code ec;
  const ReferencePaths paths = reference_paths(out.path);
  if (!fs::exists(paths.mean, ec) && !fs::exists(paths.sidecar, ec)) return out;
  try {
    Reference r = load_reference(out.path);
    if (!r.info.is_reference) throw InputError("its sidecar is missing or not a reference's");
    if (r.info.scene_hash != key.scene_hash || r.width != key.width || r.height != key.height ||
        r.info.max_depth != key.max_depth)
      throw InputError("its sidecar names another scene, size or depth");
    out.status = CacheLookup::Found;
    out.reference = std::move(r);
  } catch (const std::exception& e) {
    out.status = CacheLookup::Damaged;
    out.message = "cached reference '" + out.path + "' is damaged and was ignored: " + e.what();
  }
  return out;
}

std::string store_cached_reference(const std::string& cache_dir, const ReferenceKey& key, const Reference& reference) {
  std::error_code ec;
  fs::create_directories(cache_dir, ec);
  if (ec) throw InputError("cannot create the reference cache folder '" + cache_dir + "': " + ec.message());
  const std::string path = cached_reference_path(cache_dir, key);
  save_reference(path, reference);
  return path;
}

ReferenceProgress reference_progress(const ReferenceGoal& goal, std::uint32_t spp, double seconds,
                                     double estimated_relmse) {
  ReferenceProgress p;
  if (goal.spp > 0) {
    p.fraction = static_cast<double>(spp) / goal.spp;
    p.reached = spp >= goal.spp;
  } else if (goal.seconds > 0.0) {
    p.fraction = seconds / goal.seconds;
    p.reached = seconds >= goal.seconds;
  } else if (goal.relmse > 0.0) {
    // relMSE * time stays about constant: the time needed is seconds * est / target.
    if (spp >= 2 && estimated_relmse > 0.0) {
      p.reached = estimated_relmse <= goal.relmse;
      p.fraction = std::min(1.0, goal.relmse / estimated_relmse);
    } else {
      p.reached = spp >= 2 && estimated_relmse <= 0.0;  // a black image is converged
    }
  }
  p.fraction = std::clamp(p.fraction, 0.0, 1.0);
  if (p.reached) p.fraction = 1.0;
  if (!p.reached && p.fraction > 0.0 && seconds > 0.0) p.seconds_left = seconds * (1.0 - p.fraction) / p.fraction;
  if (!p.reached && goal.max_seconds > 0.0) {
    if (seconds >= goal.max_seconds) {
      p.reached = p.capped = true;
      p.seconds_left = 0.0;
    } else {
      const double limit_left = goal.max_seconds - seconds;
      p.seconds_left = p.seconds_left > 0.0 ? std::min(p.seconds_left, limit_left) : limit_left;
    }
  }
  return p;
}

}  // namespace pdflab
