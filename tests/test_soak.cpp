// Soak test: one RenderSession (recreated now and then) has its settings
// switched at random for PDFLAB_SOAK_SECONDS seconds (default 240; ctest
// passes the CMake cache variable PDFLAB_SOAK_SECONDS, 20 in CI): scene and
// resolution, strategy and weights, seed, target spp, pause and resume, image
// and film copies, all the while rendering. It checks
//  - the session's own promises at every step (spp never passes the target, a
//    finished render has exactly the target in every pixel, images have the
//    size of a scene that was asked for, a refused strategy leaves the render
//    alone);
//  - that nothing leaks from one generation into the next: every so often a
//    reference render is asked for in the middle of the churn, and its film
//    must be bit-identical to one rendered by a fresh session;
//  - that resident memory stays flat: RSS after a warm-up (every scene size and
//    thread count seen) against RSS at the end.
// Under a sanitizer the RSS figures are printed but not judged (ASan keeps
// freed memory in quarantine; TSan grows shadow memory); the sanitizer itself
// judges leaks and races there.
#include "renderer/error.h"
#include "renderer/film/film.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define PDFLAB_UNDER_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define PDFLAB_UNDER_SANITIZER 1
#endif
#endif

namespace pdflab {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

const std::string kSource = PDFLAB_SOURCE_DIR;

double soak_seconds() {
  const char* env = std::getenv("PDFLAB_SOAK_SECONDS");
  if (!env || !*env) return 240.0;
  const double s = std::atof(env);
  return s > 0.0 ? s : 240.0;
}

// Resident set size in bytes, from /proc/self/statm (second field, in pages).
long long resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  long long size_pages = 0, resident_pages = 0;
  statm >> size_pages >> resident_pages;
  return statm ? resident_pages * ::sysconf(_SC_PAGESIZE) : -1;
}

double mib(long long bytes) { return static_cast<double>(bytes) / (1 << 20); }

std::shared_ptr<const Scene> sized(const Scene& base, int width, int height) {
  auto s = std::make_shared<Scene>(base);
  s->camera.width = width;
  s->camera.height = height;
  s->prepare();
  return s;
}

bool same_film(const Film& a, const Film& b) {
  if (a.width() != b.width() || a.height() != b.height()) return false;
  for (std::size_t p = 0; p < a.pixel_count(); ++p) {
    double ma[3], mb[3], va[3], vb[3];
    a.mean(p, ma);
    b.mean(p, mb);
    a.variance_of_mean(p, va);
    b.variance_of_mean(p, vb);
    if (a.count(p) != b.count(p) || std::memcmp(ma, mb, sizeof ma) != 0 || std::memcmp(va, vb, sizeof va) != 0)
      return false;
  }
  return true;
}

TEST(Soak, SettingsChurnKeepsResultsExactAndMemoryFlat) {
  const double total_seconds = soak_seconds();
  const double warmup_seconds = std::max(2.0, 0.25 * total_seconds);

  const Scene book = load_scene_file(kSource + "/assets/scenes/cornell_book.json");
  const Scene no_targets = load_scene_file(kSource + "/tests/bad_input/no_targets.json");
  // Sizes that are, and are not, multiples of the 16-pixel tile, and one pixel.
  const std::vector<std::pair<int, int>> sizes = {{64, 48}, {33, 17}, {1, 1}, {80, 80}, {16, 64}};
  const std::vector<std::string> strategies = {"cosine", "light", "uniform-hemisphere", "uniform-sphere",
                                               "mix:cosine=0.5,light=0.5", "mix:cosine=0,light=1",
                                               "mix:cosine=1,uniform-sphere=3,light=0.25"};
  const std::vector<std::uint32_t> targets = {0, 1, 2, 7, 32};

  // The reference: rendered once by a fresh session, asked for again mid-churn.
  RenderSettings reference;
  reference.scene = sized(book, 24, 20);
  reference.strategy = Strategy::parse("mix:cosine=0.5,light=0.5");
  reference.seed = 77;
  reference.target_spp = 5;
  Film reference_film;
  {
    RenderSession fresh(2);
    fresh.set_settings(reference);
    ASSERT_TRUE(fresh.wait_until_done(60s));
    reference_film = fresh.copy_film();
  }

  std::mt19937 rng(20240611);
  const auto pick = [&](std::size_t n) { return static_cast<std::size_t>(rng() % n); };

  auto session = std::make_unique<RenderSession>(2);
  RenderSettings current;
  current.scene = sized(book, 64, 48);
  session->set_settings(current);

  long long changes = 0, pauses = 0, finished = 0, reference_checks = 0, sessions = 1, refused = 0, copies = 0;
  long long rss_warm = -1, rss_peak = 0;
  std::vector<float> image;
  int iw = 0, ih = 0;
  std::uint64_t version = 0;
  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };

  // Asks for the reference settings, maybe pausing and resuming on the way,
  // and compares the finished film with the fresh session's.
  const auto check_reference = [&] {
    session->set_settings(reference);
    if (rng() % 2) {
      session->set_paused(true);
      std::this_thread::sleep_for(std::chrono::milliseconds(pick(5)));
      session->set_paused(false);
    }
    ASSERT_TRUE(session->wait_until_done(120s)) << "the reference render never finished";
    const Film film = session->copy_film();
    EXPECT_TRUE(same_film(film, reference_film)) << "after " << changes << " changes the film differs from a fresh render";
    ++reference_checks;
    current = reference;
  };

  for (long long step = 0; elapsed() < total_seconds; ++step) {
    switch (pick(10)) {
      case 0:
      case 1:
      case 2: {  // new settings
        RenderSettings s;
        const auto [w, h] = sizes[pick(sizes.size())];
        s.scene = sized(book, w, h);
        s.strategy = Strategy::parse(strategies[pick(strategies.size())]);
        s.seed = rng();
        s.target_spp = targets[pick(targets.size())];
        session->set_settings(s);
        current = s;
        ++changes;
        break;
      }
      case 3: {  // a strategy the scene cannot use: refused, the render goes on
        RenderSettings s;
        s.scene = std::make_shared<Scene>(no_targets);
        s.strategy = Strategy::parse("light");
        EXPECT_THROW(session->set_settings(s), InputError);
        EXPECT_EQ(session->settings().scene, current.scene) << "a refused change replaced the scene";
        ++refused;
        break;
      }
      case 4: {  // pause, maybe copy the film while paused, resume
        session->set_paused(true);
        ++pauses;
        if (rng() % 2) {
          const Film film = session->copy_film();
          EXPECT_EQ(film.width(), current.scene->camera.width);
          EXPECT_EQ(film.height(), current.scene->camera.height);
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(pick(4)));
        session->set_paused(false);
        break;
      }
      case 5: {  // the viewer's copy: the size of a scene that was asked for
        if (session->copy_image(image, iw, ih, version)) {
          ++copies;
          EXPECT_EQ(image.size(), static_cast<std::size_t>(iw) * ih * 3);
          bool known = iw == 24 && ih == 20;
          for (const auto& [w, h] : sizes) known = known || (w == iw && h == ih);
          EXPECT_TRUE(known) << iw << "x" << ih;
        }
        break;
      }
      case 6: {  // wait a little; a finished render has exactly the target everywhere
        if (current.target_spp != 0 && session->wait_until_done(std::chrono::milliseconds(pick(20)))) {
          const SessionStats st = session->stats();
          EXPECT_TRUE(st.done);
          EXPECT_EQ(st.spp, current.target_spp);
          const Film film = session->copy_film();
          ASSERT_EQ(film.width(), current.scene->camera.width);
          for (std::size_t p = 0; p < film.pixel_count(); p += 1 + film.pixel_count() / 7)
            ASSERT_EQ(film.count(p), current.target_spp) << "pixel " << p;
          ++finished;
        }
        break;
      }
      case 7: {  // statistics are consistent at any moment
        const SessionStats st = session->stats();
        if (current.target_spp != 0) {
          EXPECT_LE(st.spp, current.target_spp);
          EXPECT_LE(st.progress, 1.0);
        }
        EXPECT_GE(st.seconds, 0.0);
        break;
      }
      case 8: {  // a new session with another thread count, mid-render
        if (step % 8 == 0) {
          session = std::make_unique<RenderSession>(1 + static_cast<int>(pick(3)));
          session->set_settings(current);
          ++sessions;
        }
        break;
      }
      case 9: {
        if (step % 25 == 0) check_reference();
        break;
      }
    }
    if (::testing::Test::HasFatalFailure()) return;
    std::this_thread::sleep_for(std::chrono::microseconds(pick(3000)));

    const long long rss = resident_bytes();
    rss_peak = std::max(rss_peak, rss);
    if (rss_warm < 0 && elapsed() >= warmup_seconds) rss_warm = rss;
  }
  check_reference();
  const long long rss_end = resident_bytes();
  session.reset();
  const long long rss_after = resident_bytes();

  std::printf("soak: %.1f s, %lld settings changes, %lld refused, %lld pauses, %lld finished renders, "
              "%lld reference checks, %lld sessions, %lld image copies\n",
              elapsed(), changes, refused, pauses, finished, reference_checks, sessions, copies);
  std::printf("soak: RSS after %.1f s warm-up %.2f MiB, at the end %.2f MiB (%+.2f MiB), peak %.2f MiB, "
              "after the session ends %.2f MiB\n",
              warmup_seconds, mib(rss_warm), mib(rss_end), mib(rss_end - rss_warm), mib(rss_peak), mib(rss_after));

  ASSERT_GT(rss_warm, 0) << "the soak ended before the warm-up did";
  EXPECT_GT(changes, 20);
  EXPECT_GT(finished + reference_checks, 2);
  EXPECT_GE(reference_checks, 1);
#ifdef PDFLAB_UNDER_SANITIZER
  std::printf("soak: built with a sanitizer, the RSS margin is not applied\n");
#else
  // The margin: after the warm-up every buffer has reached its largest size
  // (the 80x80 film is 330 KiB, its float images 75 KiB each), so what is left
  // is allocator noise: glibc keeps freed chunks in per-thread arenas, copies of
  // the film come and go. Measured on the CI machine kind over three 20 s runs
  // and one 90 s run: end minus warm-up between -0.09 and +0.35 MiB, peak at
  // most 0.6 MiB above the warm-up. 2 MiB is three times that excursion, and
  // below what the smallest plausible leak adds in the 20 s CI soak: the scene
  // kept alive once per settings change (a leaked shared_ptr) grew RSS by
  // 3.3 MiB in that time when tried on purpose.
  constexpr long long kMargin = 2ll << 20;
  EXPECT_LT(rss_end - rss_warm, kMargin) << "resident memory grew by " << mib(rss_end - rss_warm) << " MiB";
#endif
}

// Several threads drive one session at once (the viewer has one, but nothing
// in the API says so): settings, pauses, statistics and image copies race with
// the workers for a few seconds. Under ThreadSanitizer this is the race test;
// everywhere it checks that the session ends in a consistent state: the last
// settings win and render exactly as a fresh session does.
TEST(Stress, ConcurrentControllersLeaveAConsistentSession) {
  const Scene book = load_scene_file(kSource + "/assets/scenes/cornell_book.json");
  std::vector<std::shared_ptr<const Scene>> scenes;
  for (const auto& [w, h] : {std::pair{40, 24}, std::pair{17, 33}, std::pair{8, 8}}) scenes.push_back(sized(book, w, h));
  const std::vector<std::string> strategies = {"cosine", "light", "mix:cosine=0.5,light=0.5", "uniform-sphere"};

  RenderSession session(3);
  std::atomic<bool> stop{false};
  std::atomic<long long> operations{0};
  const auto controller = [&](unsigned seed) {
    std::mt19937 rng(seed);
    while (!stop.load()) {
      RenderSettings s;
      s.scene = scenes[rng() % scenes.size()];
      s.strategy = Strategy::parse(strategies[rng() % strategies.size()]);
      s.seed = rng() % 4;
      s.target_spp = rng() % 4 == 0 ? 0u : 1u + rng() % 8;
      session.set_settings(s);
      if (rng() % 3 == 0) session.set_paused(rng() % 2 == 0);
      (void)session.wait_until_done(std::chrono::milliseconds(rng() % 3));
      ++operations;
    }
  };
  const auto observer = [&] {
    std::vector<float> image;
    int w = 0, h = 0;
    std::uint64_t version = 0;
    while (!stop.load()) {
      const SessionStats st = session.stats();
      EXPECT_LE(st.progress, 1.0);
      if (session.copy_image(image, w, h, version)) {
        EXPECT_EQ(image.size(), static_cast<std::size_t>(w) * h * 3);
      }
      (void)session.settings();
      ++operations;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  };
  std::vector<std::thread> threads;
  threads.emplace_back(controller, 1u);
  threads.emplace_back(controller, 2u);
  threads.emplace_back(observer);
  std::this_thread::sleep_for(3s);
  stop = true;
  for (auto& t : threads) t.join();

  RenderSettings last;
  last.scene = scenes[0];
  last.strategy = Strategy::parse("mix:cosine=0.5,light=0.5");
  last.seed = 9;
  last.target_spp = 3;
  session.set_paused(false);
  session.set_settings(last);
  ASSERT_TRUE(session.wait_until_done(120s));
  RenderSession fresh(1);
  fresh.set_settings(last);
  ASSERT_TRUE(fresh.wait_until_done(120s));
  EXPECT_TRUE(same_film(session.copy_film(), fresh.copy_film()));
  std::printf("stress: %lld operations from 3 threads in 3 s\n", operations.load());
  EXPECT_GT(operations.load(), 30);
}

}  // namespace
}  // namespace pdflab
