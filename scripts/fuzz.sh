#!/usr/bin/env bash
# Builds the scene-loader fuzzer (clang, libFuzzer, ASan + UBSan) and runs it
# for PDFLAB_FUZZ_SECONDS seconds (default 60). Seeds: the shipped scenes, the
# malformed inputs in tests/bad_input/ and the earlier findings in
# tests/fuzz_regressions/. A crash stops the run with status 1 and leaves the
# input in build/fuzz/crashes/: copy it into tests/fuzz_regressions/, where
# test_fuzz_regressions loads it and expects an InputError.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${PDFLAB_FUZZ_SECONDS:-60}
jobs=${PDFLAB_JOBS:-$(nproc)}

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j"$jobs" >/dev/null

corpus=build/fuzz/corpus   # grows across local runs; CI starts empty
crashes=build/fuzz/crashes
mkdir -p "$corpus" "$crashes"
log=build/fuzz/last_run.log

status=0
# Leaks are findings too. 10 s for one input is a hang: the CLI promises an
# answer within a second.
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  build/fuzz/tests/fuzz/fuzz_scene_loader "$corpus" assets/scenes tests/bad_input tests/fuzz_regressions \
  -dict=tests/fuzz/scene.dict -max_len=32768 -timeout=10 -rss_limit_mb=2048 \
  -max_total_time="$seconds" -artifact_prefix="$crashes/" -print_final_stats=1 >"$log" 2>&1 || status=$?

execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
found=$(find "$crashes" -type f | wc -l)
echo "fuzz_scene_loader: ${execs:-?} executions in ${seconds} s, corpus $(find "$corpus" -type f | wc -l) inputs, ${found} crash files in $crashes"
if [ "$status" -ne 0 ]; then
  grep -E "ERROR|SUMMARY|invariant|runtime error|deadly signal|Test unit written" "$log" | head -20 || true
  echo "the fuzzer found a problem (status $status); full log: $log" >&2
  exit 1
fi
