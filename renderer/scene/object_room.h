#pragma once
// A scene of many objects, generated: the book's room (five walls, its
// camera) holding `objects` small spheres and quads at random places, sizes
// and orientations, one in eight of them emitting. What the tree over objects
// (bvh.h) is measured on (bench/bench_objects.cpp, docs/many_lights.md) and
// tested on; the same count and seed give the same scene.
#include "renderer/scene/scene.h"

#include <cstdint>
#include <string>

namespace pdflab {

// The scene file's text (assets/scenes' format), for load_scene_text.
std::string object_room_text(int objects, std::uint64_t seed = 1);
// The scene itself, prepared, with the tree as `tree` asks.
Scene object_room(int objects, std::uint64_t seed = 1, BvhUse tree = BvhUse::Auto);

}  // namespace pdflab
