#!/usr/bin/env bash
# Installs what is missing, builds (Release), and runs the whole test suite;
# then the reliability runs (CI runs all of this):
#   - the suite again under AddressSanitizer + UndefinedBehaviorSanitizer,
#     leaving out tests labelled `slow` (see tests/CMakeLists.txt);
#   - the render-session tests (label `session`) under ThreadSanitizer;
#   - the scene-loader fuzzer for PDFLAB_FUZZ_SECONDS seconds (default 60).
# PDFLAB_QUICK=1 stops after the Release suite. Each phase prints its time.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
jobs=$(nproc)
start=$SECONDS
phase_start=$SECONDS
phase_done() {
  echo "== $1: $((SECONDS - phase_start)) s (total $((SECONDS - start)) s)"
  phase_start=$SECONDS
}

bash scripts/configure.sh release >/dev/null
cmake --build --preset release -j"$jobs"
ctest --preset release -j"$jobs" --timeout 600 -LE gui
# The GUI tests drive a real (virtual) X server with xdotool, whose start-up and
# focus can race, and xdotool is at times refused (BadWindow) by a live window;
# they get up to four retries, everything else none. Each runs its own X
# server and artifact folder, and most of its time is spent waiting for the
# viewer, so they run side by side (apart from the rest of the suite).
ctest --preset release -j"$jobs" --timeout 600 -L gui --repeat until-pass:5
phase_done "Release build and suite"
[ "${PDFLAB_QUICK:-0}" = 1 ] && exit 0

# Sanitizer reports fail the test that triggers them; leaks count.
export ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1
bash scripts/configure.sh asan >/dev/null
cmake --build --preset asan -j"$jobs"
ctest --preset asan -j"$jobs" --timeout 900 -LE 'slow|nosan'
phase_done "ASan+UBSan build and suite (without slow tests)"

# ThreadSanitizer maps its shadow memory at fixed addresses, which some
# kernels' address randomisation collides with; run without it where we can.
no_aslr=()
if setarch "$(uname -m)" -R true 2>/dev/null; then no_aslr=(setarch "$(uname -m)" -R); fi
bash scripts/configure.sh tsan >/dev/null
cmake --build --preset tsan -j"$jobs" --target test_session_soak session_viewer_test test_reference_build
"${no_aslr[@]}" ctest --preset tsan -j"$jobs" --timeout 900 -L session
phase_done "TSan build and session tests"

bash scripts/fuzz.sh
phase_done "Scene loader fuzzing"
