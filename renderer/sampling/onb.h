#pragma once
// Orthonormal basis around a unit normal: leaf::Onb (renderer/sampling/leaf_math.inc).
#include "renderer/sampling/leaf.h"
