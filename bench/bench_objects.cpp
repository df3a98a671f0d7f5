// Cost per sample against the number of objects, with and without the tree
// over objects (renderer/scene/bvh.h): the generated room (object_room) of N
// small spheres and quads, one in eight emitting, rendered by the packet
// tracer on one thread, the flat loop and the tree alternately, each the
// median of R rounds of the same samples, in the thread's CPU time. Checks that both give the same
// bits. Prints a markdown table; --svg writes the log-log plot of
// docs/many_lights.md.
//
//   bench_objects [--counts 10,100,1000,10000] [--strategies "cosine;nee-mis"]
//                 [--side 32] [--spp 2] [--rounds 3] [--svg FILE]
#include "renderer/integrator/packet.h"
#include "renderer/metrics/svg_plot.h"
#include "renderer/scene/object_room.h"

#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace pdflab;

namespace {

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, separator);)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// This thread's CPU time: on a machine shared with other work the clock on
// the wall also counts the time the thread waited for a core.
double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// CPU seconds to render `block` once; the samples in `out`.
double render(const Scene& scene, const SamplingPlan& plan, const SampleBlock& block, std::vector<SampleResult>& out) {
  out.assign(block.size(), {});
  const double start = thread_seconds();
  trace_block(scene, plan, 3, block, out.data());
  return thread_seconds() - start;
}

bool same_bits(const std::vector<SampleResult>& a, const std::vector<SampleResult>& b) {
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i].radiance, &b[i].radiance, sizeof a[i].radiance) != 0 || a[i].drops != b[i].drops) return false;
  return a.size() == b.size();
}

}  // namespace

int main(int argc, char** argv) {
  std::string counts_text = "10,100,1000,10000", strategies_text = "cosine;nee-mis", svg;
  int side = 32, rounds = 3;
  std::uint32_t spp = 2;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--counts") counts_text = value;
    else if (key == "--strategies") strategies_text = value;
    else if (key == "--side") side = std::stoi(value);
    else if (key == "--spp") spp = static_cast<std::uint32_t>(std::stoul(value));
    else if (key == "--rounds") rounds = std::stoi(value);
    else if (key == "--svg") svg = value;
    else {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
      return 2;
    }
  }
  const PacketIsa isa = best_packet_isa();
  std::printf("packets of %d paths (%s), one thread, %dx%d pixels x %u spp per run, median of %d rounds of CPU time\n\n",
              packet_lanes(isa), std::string(packet_isa_name(isa)).c_str(), side, side, spp, rounds);
  std::printf("| strategy | objects | emitters | flat (us/sample) | tree (us/sample) | flat / tree | tree nodes | same bits |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---|\n");
  std::vector<PlotSeries> series;
  for (const std::string& strategy : split(strategies_text, ';')) {
    PlotSeries flat_series{strategy + ", flat", {}, {}, {}, {}, true};
    PlotSeries tree_series{strategy + ", tree", {}, {}, {}, {}, false};
    for (const std::string& count : split(counts_text, ',')) {
      const int n = std::stoi(count);
      Scene flat = object_room(n, 1, BvhUse::Never), tree = object_room(n, 1, BvhUse::Always);
      for (Scene* s : {&flat, &tree}) {
        s->camera.width = side;
        s->camera.height = side;
        s->prepare();
      }
      const SamplingPlan flat_plan = SamplingPlan::make(Strategy::parse(strategy), flat);
      const SamplingPlan tree_plan = SamplingPlan::make(Strategy::parse(strategy), tree);
      const SampleBlock block{0, 0, side, side, 0, spp};
      std::vector<SampleResult> a, b;
      std::vector<double> flat_times, tree_times;
      bool same = true;
      for (int r = 0; r < rounds; ++r) {
        flat_times.push_back(render(flat, flat_plan, block, a));
        tree_times.push_back(render(tree, tree_plan, block, b));
        same = same && same_bits(a, b);
      }
      const double samples = static_cast<double>(block.size());
      const double flat_us = 1e6 * median(flat_times) / samples, tree_us = 1e6 * median(tree_times) / samples;
      const std::size_t objects = flat.quads.size() + flat.spheres.size();
      int emitters = 0;
      for (const Quad& q : flat.quads) emitters += flat.materials[q.material].type == MaterialType::DiffuseLight;
      for (const Sphere& s : flat.spheres) emitters += flat.materials[s.material].type == MaterialType::DiffuseLight;
      std::printf("| %s | %zu | %d | %.2f | %.2f | %.2f | %zu | %s |\n", strategy.c_str(), objects, emitters, flat_us,
                  tree_us, flat_us / tree_us, tree.bvh.wide.size(), same ? "yes" : "NO");
      std::fflush(stdout);
      flat_series.x.push_back(static_cast<double>(objects));
      flat_series.y.push_back(flat_us);
      tree_series.x.push_back(static_cast<double>(objects));
      tree_series.y.push_back(tree_us);
      if (!same) return 1;
    }
    series.push_back(flat_series);
    series.push_back(tree_series);
  }
  if (!svg.empty()) {
    PlotOptions options;
    options.title = "Cost per sample against the number of objects";
    options.x_label = "objects (the room's 5 walls, small spheres and quads)";
    options.y_label = "microseconds per sample (one thread's CPU time)";
    options.guide_slope = 1.0;
    options.guide_label = "slope 1 (every object per ray)";
    std::ofstream(svg) << loglog_svg(series, options);
    std::printf("\nplot: %s\n", svg.c_str());
  }
  return 0;
}
