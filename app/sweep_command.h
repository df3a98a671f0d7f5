#pragma once
#include <cstdint>
#include <string>

namespace pdflab {

struct SweepOptions {
  std::string scene;
  std::string vary;       // "A,B": the two techniques whose shares are swept
  std::string weights;    // "LO:HI:STEP": A's share of the pair
  std::string strategy;   // optional base mixture: the other techniques' weights and the pair's total
  int roulette_depth = 0;  // --rr: Russian roulette from this depth on in every strategy (0: as given)
  double seconds = 0.0;   // equal time per run (or)
  std::uint32_t spp = 0;  // equal samples per pixel
  std::string reference;  // PFM (its size sets the render size) or "auto" (the cache)
  int width = 0, height = 0;  // with "auto": the size to look up (0: the scene's)
  std::string cache_dir;      // empty: reference_cache_dir()
  int seeds = 3;          // runs per weight, seeds seed, seed + 1, ...
  std::uint64_t seed = 2;  // not the reference's (see BenchOptions::seed)
  std::string csv;
  std::string plot;       // SVG, optional
  std::string map;        // PNG of the per-pixel best weight, optional
  int threads = 0;
  bool quiet = false;
  bool auto_weight = false;  // also render with the weight chosen between passes
  // Price the runs by the CPU time of the process (the render threads, and
  // auto weight's prediction) instead of the wall clock: on a machine shared
  // with other work the wall clock's time per sample follows the others' load.
  bool cpu_time = false;

};

// Runs `pdflab sweep`. Returns the exit status; throws InputError for bad input.
int run_sweep(const SweepOptions& options);

}  // namespace pdflab
