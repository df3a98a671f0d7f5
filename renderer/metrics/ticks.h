#pragma once
// Axis ticks and their labels, one rule for every plot: the viewer's plots and
// colour bars and the SVG plots of `bench` and `sweep`.
#include <string>
#include <vector>

namespace pdflab {

// The smallest of 1, 2, 5 times a power of ten that is >= v (v > 0 and
// finite; anything else gives 1). A caller that wants a round value to count
// as its own ceiling, or to leave headroom above it, scales v by 1 -/+ 1e-9.
double nice_ceiling(double v);

// The largest of 1, 2, 5 times a power of ten that is <= v (same conventions).
double nice_floor(double v);

// Ticks at multiples of a nice step covering [lo, hi], at most about `max_ticks`.
std::vector<double> nice_ticks(double lo, double hi, int max_ticks = 6);

// Powers of ten inside [lo, hi] (lo > 0), each one exact within 1e-9 of a decade.
std::vector<double> decade_ticks(double lo, double hi);

// Short tick label: 0, 0.5, 2, 0.001, 100, 1000, 1e-04, 1e+04 (three
// significant digits between 1e-3 and 100, four up to 1e4, one digit and an
// exponent outside).
std::string tick_label(double v);

}  // namespace pdflab
