#pragma once
// What the tests that touch files or run the binary share: a temporary folder
// per test, and running the pdflab binary as a child process — no shell, stdin
// from /dev/null, stdout and stderr captured to files, a working folder, a
// wall-clock deadline after which the child is killed, and an optional
// file-size limit (RLIMIT_FSIZE) to simulate a full disk.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stdlib.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace pdflab::testing {

// The build these tests and the pdflab binary beside them come from. A
// sanitizer build renders 10-30x slower than a release build (ASan: about
// 0.09 M samples/s on the book's box on a loaded 2-core machine, against
// 15 M), an unoptimised one several times slower: tests size their work in
// samples for the build (spp_for_build) and give children deadlines that
// hold on such a machine (deadline_for_build), never a release build's
// seconds.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || !defined(__OPTIMIZE__)
inline constexpr bool kSlowBuild = true;
#else
inline constexpr bool kSlowBuild = false;
#endif

// `release` samples per pixel in a release build, `slow` in a sanitizer or
// unoptimised one (chosen to test the same property).
constexpr std::uint32_t spp_for_build(std::uint32_t release, std::uint32_t slow) { return kSlowBuild ? slow : release; }
// A child's deadline: `release_seconds` already allows for a loaded machine;
// a slow build gets ten times that.
constexpr double deadline_for_build(double release_seconds) { return kSlowBuild ? 10.0 * release_seconds : release_seconds; }

// A fresh empty folder, removed with everything in it when the object goes.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "pdflab-test") {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  // Names directly inside the folder, sorted.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(path_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::filesystem::path path_;
};

struct ChildResult {
  bool started = false;
  bool exited = false;     // false: killed by a signal (or by the deadline)
  bool timed_out = false;  // killed by the deadline
  int status = -1;         // exit status when exited
  double seconds = 0.0;    // wall time
  double cpu_seconds = 0.0;  // user + system time of the child: what the load of the machine does not inflate
  std::string out, err;
};

struct ChildOptions {
  std::filesystem::path cwd;              // the child's working folder
  std::filesystem::path capture;          // where stdout/stderr files go (not cwd)
  double deadline_seconds = 10.0;
  long long file_size_limit = -1;         // bytes; -1: unlimited
};

inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline ChildResult run_pdflab(const std::vector<std::string>& args, const ChildOptions& o) {
  const std::string out_path = (o.capture / "stdout").string();
  const std::string err_path = (o.capture / "stderr").string();
  std::vector<std::string> storage{PDFLAB_BINARY};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);

  ChildResult r;
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid < 0) return r;
  if (pid == 0) {
    // Only async-signal-safe calls from here to exec.
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || err < 0 || ::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(err, 2) < 0) ::_exit(126);
    if (!o.cwd.empty() && ::chdir(o.cwd.c_str()) != 0) ::_exit(126);
    if (o.file_size_limit >= 0) {
      ::signal(SIGXFSZ, SIG_IGN);  // the write fails with EFBIG, as with ENOSPC, instead of killing
      const rlimit limit{static_cast<rlim_t>(o.file_size_limit), static_cast<rlim_t>(o.file_size_limit)};
      if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(126);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  r.started = true;
  int status = 0;
  rusage usage{};
  for (;;) {
    const pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
    if (done == pid) break;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (elapsed > o.deadline_seconds && !r.timed_out) {
      r.timed_out = true;
      ::kill(pid, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.cpu_seconds = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                  static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
  r.exited = WIFEXITED(status) && !r.timed_out;
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out_path);
  r.err = slurp(err_path);
  return r;
}

// Every path under `root`, relative and sorted: "nothing was written" is a
// comparison of two listings.
inline std::vector<std::string> listing(const std::filesystem::path& root) {
  std::vector<std::string> names;
  std::error_code ec;
  for (auto it = std::filesystem::recursive_directory_iterator(root, ec); !ec && it != decltype(it)(); it.increment(ec))
    names.push_back(std::filesystem::relative(it->path(), root).string());
  std::sort(names.begin(), names.end());
  return names;
}

// A test's own place to run the binary: an empty working folder (the child's
// cwd, where its outputs go) and a separate folder for the captured streams,
// so that "nothing was written" is a listing of the working folder.
class CommandWorkspace {
 public:
  explicit CommandWorkspace(const std::string& prefix) : root_(prefix) {
    std::filesystem::create_directory(work());
    std::filesystem::create_directory(root_.path() / "io");
  }
  std::filesystem::path work() const { return root_.path() / "work"; }
  std::string in_work(const std::string& name) const { return (work() / name).string(); }
  std::vector<std::string> work_entries() const { return listing(work()); }
  // The binary itself (no shell), stdin from /dev/null, in the working folder.
  ChildResult run(const std::vector<std::string>& args, double deadline_seconds = deadline_for_build(120.0)) const {
    ChildOptions o;
    o.cwd = work();
    o.capture = root_.path() / "io";
    o.deadline_seconds = deadline_seconds;
    return run_pdflab(args, o);
  }
  const std::filesystem::path& root() const { return root_.path(); }

 private:
  TempDir root_;
};

}  // namespace pdflab::testing
