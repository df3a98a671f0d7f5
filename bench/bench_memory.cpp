// Peak memory of a headless render per pixel: `pdflab render` runs as a child
// process at several image sizes and its peak resident size (ru_maxrss from
// wait4) is fitted by a line against the pixel count; the slope is what a
// pixel costs, the intercept what a render costs at any size. Each output
// kind (.pfm, .exr with a film file, .png) is measured; with --compare OLD the
// same runs of another binary alternate with this one's, so both slopes come
// from one run of a noisy machine.
//
//   bench_memory [--binary PDFLAB] [--compare OLD_PDFLAB] [--sizes 600,1200,1800,2400] [--rounds R]
#include "renderer/metrics/statistics.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

// Peak resident bytes of one run, or -1 when it failed.
long long peak_rss(const std::string& binary, const std::vector<std::string>& args) {
  std::vector<std::string> storage{binary};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::fflush(stdout);  // or the child would print what is buffered again
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  int status = 0;
  rusage usage{};
  if (::wait4(pid, &status, 0, &usage) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
  return static_cast<long long>(usage.ru_maxrss) * 1024;  // kilobytes on Linux
}

struct Kind {
  std::string name;
  std::vector<std::string> outputs;  // relative to the scratch folder
  bool needs_film = false;
};

}  // namespace

int main(int argc, char** argv) {
  std::string binary = PDFLAB_BINARY, compare;
  std::vector<int> sizes = {600, 1200, 1800, 2400};
  int rounds = 2;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--binary") binary = value;
    else if (key == "--compare") compare = value;
    else if (key == "--rounds") rounds = std::max(1, std::atoi(value.c_str()));
    else if (key == "--sizes") {
      sizes.clear();
      std::stringstream ss(value);
      for (std::string item; std::getline(ss, item, ',');) sizes.push_back(std::atoi(item.c_str()));
    } else {
      std::fprintf(stderr, "usage: bench_memory [--binary P] [--compare OLD] [--sizes a,b,..] [--rounds R]\n");
      return 2;
    }
  }
  const fs::path scratch = fs::temp_directory_path() / ("pdflab-bench-memory-" + std::to_string(::getpid()));
  fs::create_directories(scratch);
  const std::string scene = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";
  const std::vector<Kind> kinds = {{".pfm", {"image.pfm"}, false},
                                   {".exr + film", {"image.exr", "--film-out", "image.film"}, true},
                                   {".png", {"image.png"}, false},
                                   {".hdr", {"image.hdr"}, false}};
  std::vector<std::pair<std::string, std::string>> binaries = {{"this", binary}};
  if (!compare.empty()) binaries.push_back({"compared", compare});

  std::printf("peak resident size of `pdflab render` (book scene, 1 spp, 2 threads) against pixels, least squares over");
  for (int s : sizes) std::printf(" %d^2", s);
  std::printf(", lowest of %d rounds\n\n", rounds);
  std::printf("| binary | output | bytes per pixel | fixed (MiB) | peak at %d^2 (MiB) |\n|---|---|---:|---:|---:|\n",
              sizes.back());
  int failures = 0;
  for (const Kind& kind : kinds) {
    for (const auto& [label, path] : binaries) {
      std::vector<double> x, y;
      bool ok = true;
      for (int s : sizes) {
        long long best = -1;
        for (int r = 0; r < rounds && ok; ++r) {
          std::vector<std::string> args = {"render", "--scene", scene, "--strategy", "mix:cosine=0.5,light=0.5",
                                           "--spp", "1", "--width", std::to_string(s), "--height", std::to_string(s),
                                           "--threads", "2", "--quiet", "--out"};
          for (const std::string& o : kind.outputs) args.push_back(o.rfind("--", 0) == 0 ? o : (scratch / o).string());
          const long long rss = peak_rss(path, args);
          if (rss < 0) ok = false;
          else best = best < 0 ? rss : std::min(best, rss);
        }
        if (!ok) break;
        x.push_back(static_cast<double>(s) * s);
        y.push_back(static_cast<double>(best));
      }
      if (!ok) {
        std::printf("| %s | %s | (not supported or failed) | | |\n", label.c_str(), kind.name.c_str());
        if (label == "this") ++failures;
        continue;
      }
      const std::optional<std::vector<double>> line = pdflab::stats::polynomial_fit(x, y, 1);
      if (!line) {
        std::printf("| %s | %s | (sizes give no line) | | |\n", label.c_str(), kind.name.c_str());
        if (label == "this") ++failures;
        continue;
      }
      std::printf("| %s | %s | %.1f | %.1f | %.0f |\n", label.c_str(), kind.name.c_str(), (*line)[1],
                  (*line)[0] / (1 << 20), y.back() / (1 << 20));
      std::fflush(stdout);
    }
  }
  fs::remove_all(scratch);
  return failures == 0 ? 0 : 1;
}
