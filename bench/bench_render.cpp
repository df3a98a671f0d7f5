// Throughput of the path tracer: pixel samples per second on a scene, with one
// thread and with all threads, measured alternately in one run so that the
// ratio is meaningful on a noisy machine. Also checks that both thread counts
// produce bit-identical accumulations (determinism must not be traded away).
//
//   bench_render [--scene F] [--strategy S] [--spp N] [--rounds R] [--threads T]
#include "renderer/integrator/packet.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

using namespace pdflab;

namespace {

struct Run {
  double samples_per_second;
  std::vector<float> image;
};

Run render_once(const std::shared_ptr<const Scene>& scene, const Strategy& strategy, std::uint32_t spp, int threads) {
  RenderSession session(threads);
  RenderSettings settings;
  settings.scene = scene;
  settings.strategy = strategy;
  settings.seed = 7;
  settings.target_spp = spp;
  session.set_settings(settings);
  session.wait_until_done();
  const SessionStats st = session.stats();
  return {st.samples_per_second, session.copy_film().mean_rgb()};
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_path = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";
  std::string strategy_text = "mix:cosine=0.5,light=0.5";
  std::uint32_t spp = 8;
  int rounds = 3;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--scene") scene_path = value;
    else if (key == "--strategy") strategy_text = value;
    else if (key == "--spp") spp = static_cast<std::uint32_t>(std::stoul(value));
    else if (key == "--rounds") rounds = std::stoi(value);
    else if (key == "--threads") threads = std::stoi(value);
    else {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
      return 2;
    }
  }
  auto scene = std::make_shared<Scene>(load_scene_file(scene_path));
  const Strategy strategy = Strategy::parse(strategy_text);
  std::printf("scene %s, %dx%d, depth %d, strategy %s, %u spp per run, %d rounds\n", scene->name.c_str(),
              scene->camera.width, scene->camera.height, scene->max_depth, strategy.to_string().c_str(), spp, rounds);
  const PacketIsa isa = best_packet_isa();
  std::printf("tracer: packets of %d paths (%s)\n", packet_lanes(isa), std::string(packet_isa_name(isa)).c_str());

  std::vector<double> one, all;
  bool identical = true;
  for (int r = 0; r < rounds; ++r) {
    const Run a = render_once(scene, strategy, spp, 1);
    const Run b = render_once(scene, strategy, spp, threads);
    one.push_back(a.samples_per_second);
    all.push_back(b.samples_per_second);
    identical = identical && a.image.size() == b.image.size() &&
                std::memcmp(a.image.data(), b.image.data(), a.image.size() * sizeof(float)) == 0;
  }
  const double m1 = median(one), mn = median(all);
  std::printf("1 thread:   %.3f M samples/s (median of %d)\n", m1 * 1e-6, rounds);
  std::printf("%d threads: %.3f M samples/s (median of %d), scaling %.2fx\n", threads, mn * 1e-6, rounds, mn / m1);
  std::printf("1 vs %d threads bit-identical: %s\n", threads, identical ? "yes" : "NO");
  return identical ? 0 : 1;
}
