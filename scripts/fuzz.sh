#!/usr/bin/env bash
# Builds the fuzzers (clang, libFuzzer, ASan + UBSan) and runs them for
# PDFLAB_FUZZ_SECONDS seconds in all (default 60): two thirds for the scene
# loader, seeded with the shipped scenes, the malformed inputs in
# tests/bad_input/ and the earlier findings in tests/fuzz_regressions/; one
# third for the film-file reader, seeded with tests/fuzz/film_seeds/. A crash
# stops the run with status 1 and leaves the
# input in build/fuzz/crashes/: copy it into tests/fuzz_regressions/, where
# test_fuzz_regressions loads it and expects an InputError.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${PDFLAB_FUZZ_SECONDS:-60}
jobs=${PDFLAB_JOBS:-$(nproc)}

bash scripts/configure.sh fuzz >/dev/null
cmake --build --preset fuzz -j"$jobs" >/dev/null

crashes=build/fuzz/crashes
mkdir -p "$crashes"
scene_seconds=$(( seconds * 2 / 3 ))
film_seconds=$(( seconds - scene_seconds ))

status=0
# run_fuzzer NAME SECONDS ARGS...: the corpus grows across local runs (CI starts empty).
run_fuzzer() {
  local name=$1 secs=$2
  shift 2
  local corpus=build/fuzz/corpus/$name log=build/fuzz/$name.log rc=0
  mkdir -p "$corpus"
  # Leaks are findings too. 10 s for one input is a hang: the CLI promises an
  # answer within a second.
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    "build/fuzz/tests/fuzz/$name" "$corpus" "$@" -timeout=10 -rss_limit_mb=2048 \
    -max_total_time="$secs" -artifact_prefix="$crashes/$name-" -print_final_stats=1 >"$log" 2>&1 || rc=$?
  local execs
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  echo "$name: ${execs:-?} executions in ${secs} s, corpus $(find "$corpus" -type f | wc -l) inputs"
  if [ "$rc" -ne 0 ]; then
    grep -E "ERROR|SUMMARY|invariant|runtime error|deadly signal|Test unit written" "$log" | head -20 || true
    echo "$name found a problem (status $rc); full log: $log" >&2
    status=1
  fi
}

run_fuzzer fuzz_scene_loader "$scene_seconds" assets/scenes tests/bad_input tests/fuzz_regressions \
  -dict=tests/fuzz/scene.dict -max_len=32768
run_fuzzer fuzz_film_reader "$film_seconds" tests/fuzz/film_seeds -max_len=4096

found=$(find "$crashes" -type f | wc -l)
echo "${found} crash files in $crashes"
exit "$status"
