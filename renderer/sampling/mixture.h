#pragma once
// The sampling plan's draw (mixture.inc) and the techniques' sample and pdf
// (renderer/sampling/techniques/) for one path at a time, in namespace
// pdflab::leaf beside the leaf math. The packet kernel compiles the same files
// for its lanes.
#include "renderer/sampling/leaf.h"
#include "renderer/sampling/strategy.h"

#include <cmath>
#include <concepts>
#include <cstdio>
#include <numbers>
#include <vector>

namespace pdflab::leaf {
#define PDFLAB_LEAF inline
#include "renderer/sampling/mixture.inc"
#undef PDFLAB_LEAF
}  // namespace pdflab::leaf
