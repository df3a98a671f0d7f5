#pragma once
// Reference images: a converged estimate of a scene to measure renders against.
// A reference is three files beside each other:
//   NAME.pfm      the mean radiance (linear RGB)
//   NAME.var.pfm  the variance of that mean per pixel and channel (its own noise)
//   NAME.json     the sidecar: scene content hash, size, depth, strategy, seed,
//                 spp, seconds, version, and a checksum of each image file
// save_reference/load_reference are the one way in and out, so other file
// formats plug in here. A cache (reference_cache_dir) keeps one reference per
// scene content, size and depth, where `pdflab reference` stores and
// `render`/`bench --reference auto` and the viewer look.
#include "renderer/sampling/strategy.h"

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace pdflab {

class Film;
struct Scene;

// Seeds at or above this are reserved for references: renders use small seeds
// (the viewer 1, bench 2), so a reference never repeats a render's random numbers.
inline constexpr std::uint64_t kReferenceSeedBase = 0xF00D000000000000ULL;
constexpr std::uint64_t reference_seed(std::uint32_t stream) { return kReferenceSeedBase + stream; }
constexpr bool is_reference_seed(std::uint64_t seed) { return seed >= kReferenceSeedBase; }

// What the sidecar says. For a PFM with no sidecar only the size is known; a
// sidecar written by `pdflab render --stats-json` or a viewer screenshot gives
// the seed and strategy but no variance.
struct ReferenceInfo {
  bool has_sidecar = false;
  bool is_reference = false;  // written by save_reference (format pdflab-reference)
  std::string scene_name, scene_file, scene_hash;
  int max_depth = 0;
  std::string strategy;  // canonical form; empty when unknown
  bool seed_known = false;
  std::uint64_t seed = 0;  // the first of `seeds`
  // Every seed its samples came from, when known: one for a render, several
  // for a merge of seeds (film, EXR, sidecar).
  std::vector<std::uint64_t> seeds;
  std::uint32_t seed_stream = 0;  // seed - kReferenceSeedBase for a reference seed
  std::uint32_t spp = 0;
  double seconds = 0.0;
  double estimated_relmse = 0.0;  // the reference's own noise, as relMSE
  std::string version;
};

// The facts of a render that every sidecar carries (a reference's, a
// screenshot's), which load_reference reads back: written by one function.
struct RenderFacts {
  std::string scene_name, scene_file, strategy;
  int width = 0, height = 0, max_depth = 0;
  std::uint64_t seed = 0;
  std::uint32_t spp = 0;
  double seconds = 0.0;
  std::string version;
};
void put_render_facts(nlohmann::json& sidecar, const RenderFacts& facts);

struct Reference {
  std::string path;         // of the mean image
  std::vector<float> rgb;   // mean, linear RGB, row 0 at the top
  // Variance of the mean per pixel and channel; empty when unknown (then no
  // figure can be corrected for the reference's noise).
  std::vector<float> variance;
  int width = 0, height = 0;
  ReferenceInfo info;
  bool loaded() const { return width > 0 && height > 0; }
  bool has_variance() const { return !variance.empty() && variance.size() == rgb.size(); }
};

struct ReferencePaths {
  std::string mean, variance, sidecar;
};
// From the mean's path: "x.pfm" -> "x.pfm", "x.var.pfm", "x.json".
ReferencePaths reference_paths(const std::string& mean_path);

// From a finished film: its mean and variance of the mean, and `info`'s fields
// (width, height and the estimated relMSE come from the film).
Reference reference_from_film(const Film& film, ReferenceInfo info);

// Writes the three files, each to a temporary name and renamed; the sidecar,
// written last, holds a checksum of the two images, so a set left half-replaced
// by a crash is found out when loaded. Throws InputError for a bad path,
// IoError when writing fails.
void save_reference(const std::string& mean_path, const Reference& reference);

// Reads a reference (or a plain PFM). Throws InputError naming the file and
// the problem when it is unreadable, truncated, not finite, or disagrees with
// its sidecar (size, checksum); a missing variance file or sidecar is allowed
// only when the sidecar does not claim one.
Reference load_reference(const std::string& path);

// Sets seed_known, seed and seeds from a list of seeds (duplicates dropped);
// an empty list leaves the seed unknown.
void set_seeds(ReferenceInfo& info, std::vector<std::uint64_t> seeds);

// A render with `seed` compared against `reference` would share random
// numbers with it (one of its seeds, whatever the strategy: pixel positions
// and first bounces would repeat). Empty when not; otherwise a sentence saying so.
std::string shared_random_numbers(const ReferenceInfo& reference, std::uint64_t seed, const Strategy& strategy);

// The strategy a reference is made with when none is given: the most efficient
// unbiased one in pdflab's convergence report for the shipped scenes (the
// book's mixture), or cosine when the scene has no importance target; under
// an environment light nee-mis continued by cosine and the map's sampler (the
// map is nee-mis's light sample too: docs/environment.md).
Strategy default_reference_strategy(const Scene& scene);

// The strategy a reference of `scene` is made with: `text` (empty: the
// default above), with Russian roulette from `roulette_depth` where that is
// given (with_roulette), as it runs on the scene (for_scene). `pdflab
// reference` and the Python module's reference() both take it.
Strategy reference_strategy(const std::string& text, int roulette_depth, const Scene& scene);

// The cache -------------------------------------------------------------------

// `option` when not empty, else $PDFLAB_REFERENCE_CACHE, else
// $XDG_CACHE_HOME/pdflab/references, else $HOME/.cache/pdflab/references.
std::string reference_cache_dir(const std::string& option = {});

struct ReferenceKey {
  std::string scene_hash;
  int width = 0, height = 0, max_depth = 0;
  std::string stem() const;  // "HASH-WxH-dD"
};
ReferenceKey reference_key(const Scene& scene);  // scene hash, camera size and max depth
std::string cached_reference_path(const std::string& cache_dir, const ReferenceKey& key);

struct CacheLookup {
  enum Status { Found, Missing, Damaged } status = Missing;
  std::string path;     // where the reference is (or would be)
  std::string message;  // Damaged: what is wrong, and that it is ignored
  Reference reference;  // Found
};
// Never throws for a bad cached file: a damaged one is reported as Damaged.
CacheLookup find_cached_reference(const std::string& cache_dir, const ReferenceKey& key);
// Stores under the key (creating the folder). Returns the mean's path.
std::string store_cached_reference(const std::string& cache_dir, const ReferenceKey& key, const Reference& reference);

// How a reference render decides it is done -----------------------------------

struct ReferenceGoal {
  std::uint32_t spp = 0;  // stop at this many samples per pixel, or
  double seconds = 0.0;   // after this much rendering time, or
  double relmse = 0.0;    // when the film's own relMSE estimate is at most this
  // Beside the goal: stop after this much time at the latest, goal reached or
  // not (0: no limit). A reference stopped by it is short of its goal.
  double max_seconds = 0.0;
};
struct ReferenceProgress {
  double fraction = 0.0;      // 0..1
  double seconds_left = 0.0;  // estimated; 0 when unknown
  bool reached = false;       // the goal, or the time limit (then `capped`)
  bool capped = false;        // stopped by max_seconds short of the goal
};
// Where a render of `spp` samples after `seconds` stands. An unbiased
// estimate's relMSE falls as 1/time, which predicts the time to a relMSE target.
ReferenceProgress reference_progress(const ReferenceGoal& goal, std::uint32_t spp, double seconds,
                                     double estimated_relmse);

}  // namespace pdflab
