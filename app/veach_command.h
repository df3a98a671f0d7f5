#pragma once
// `pdflab veach`: Veach's figure and table (docs/veach.md). The four
// estimators of Veach's multiple importance sampling figure -- BSDF sampling
// only (bsdf), light sampling only (light-sa), MIS with the balance heuristic
// (nee-mis:balance+bsdf) and with the power heuristic (nee-mis+bsdf) -- each
// rendered at equal time over several seeds against a reference; writes the
// four first-seed renders as one 2 x 2 image and a Markdown table of relMSE
// per plate (each microfacet material the camera sees) and per plate-light
// pair (the emitting sphere nearest each pixel's mirror direction).
#include "app/comparison.h"

#include <string>

namespace pdflab {

struct VeachOptions : ComparisonOptions {
  int seeds = 4;      // seeds seed, seed + 1, ... per estimator
  std::string out;    // the 2 x 2 image (any format render writes)
  std::string table;  // the Markdown table (optional; it is printed either way)
};

// Runs `pdflab veach`. Returns the exit status; throws InputError for bad input.
int run_veach(const VeachOptions& options);

}  // namespace pdflab
