#pragma once
#include "app/comparison.h"

#include <string>

namespace pdflab {

struct BenchOptions : ComparisonOptions {
  std::string strategies;  // "S1;S2;..."
  std::string curves;      // CSV of every checkpoint, optional
  // "A,B": predict, from the paths of the strategy nearest w = 0.5 among those
  // mixing A and B (A's share w of the pair, the others as in the first such
  // strategy), the efficiency of every other such strategy. Optional.
  std::string predict;
};

// Runs `pdflab bench`. Returns the exit status; throws InputError for bad input.
int run_bench(const BenchOptions& options);

}  // namespace pdflab
