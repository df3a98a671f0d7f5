#pragma once
#include "app/comparison.h"

#include <string>

namespace pdflab {

struct SweepOptions : ComparisonOptions {
  std::string vary;       // "A,B": the two techniques whose shares are swept
  std::string weights;    // "LO:HI:STEP": A's share of the pair
  std::string strategy;   // optional base mixture: the other techniques' weights and the pair's total
  int seeds = 3;          // runs per weight, seeds seed, seed + 1, ...
  std::string map;        // PNG of the per-pixel best weight, optional
  bool auto_weight = false;  // also render with the weight chosen between passes
  // Price the runs by the CPU time of the process (the render threads, and
  // auto weight's prediction) instead of the wall clock: on a machine shared
  // with other work the wall clock's time per sample follows the others' load.
  bool cpu_time = false;
};

// Runs `pdflab sweep`. Returns the exit status; throws InputError for bad input.
int run_sweep(const SweepOptions& options);

}  // namespace pdflab
