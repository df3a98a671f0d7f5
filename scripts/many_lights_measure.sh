#!/usr/bin/env bash
# The light tree against the choice by power on assets/scenes/many_lights.json
# (docs/many_lights.md, "The light tree"), from the CLI alone:
#   1. a reference (pdflab reference, REF_SPP samples per pixel of
#      nee-mis+lights:power, the choice by power: the established estimator, so that a
#      fault of the tree cannot hide in the reference; at least 32x every run
#      below);
#   2. each strategy timed at SPP samples per pixel on one thread (its CPU
#      time, the best of three: on a machine shared with other work the clock
#      also counts the time other work held the core), then given
#      SPP * (slowest time / its time) samples: equal time;
#   3. SEEDS renders of each against the reference (the whole image's relMSE
#      from each summary), and efficiency 1 / (relMSE * seconds), the seconds
#      the runs' own CPU time (the timing's, scaled to the samples, beside it).
# Usage: scripts/many_lights_measure.sh [OUT_DIR]
#   (PDFLAB, SPP, SEEDS, REF_SPP, WIDTH, HEIGHT, STRATEGIES from the environment)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-many_lights_out}
pdflab=${PDFLAB:-$here/build/release/app/pdflab}
spp=${SPP:-8}
seeds=${SEEDS:-"101 102 103 104 105 106 107 108"}
ref_spp=${REF_SPP:-512}
width=${WIDTH:-80}
height=${HEIGHT:-60}
read -r -a strategies <<< "${STRATEGIES:-nee-mis+lights:power nee-mis+lights:tree}"
scene=$here/assets/scenes/many_lights.json
size=(--width "$width" --height "$height")
mkdir -p "$out"

[ -f "$out/ref.pfm" ] || "$pdflab" reference --scene "$scene" "${size[@]}" --strategy nee-mis+lights:power \
  --spp "$ref_spp" --out "$out/ref.pfm" --cache-dir "$out/cache" --quiet

declare -a seconds
for i in "${!strategies[@]}"; do
  best=
  for k in 1 2 3; do
    /usr/bin/time -f %U -o "$out/cpu.txt" "$pdflab" render --scene "$scene" "${size[@]}" \
      --strategy "${strategies[$i]}" --spp "$spp" --seed 7 --threads 1 --out "$out/timing.pfm" --quiet > /dev/null 2>&1
    t=$(cat "$out/cpu.txt")
    best=$(awk -v a="${best:-$t}" -v b="$t" 'BEGIN{print (b < a) ? b : a}')
  done
  seconds[$i]=$best
done
slowest=$(printf '%s\n' "${seconds[@]}" | sort -g | tail -1)

: > "$out/runs.csv"
for i in "${!strategies[@]}"; do
  n=$(awk -v s="$spp" -v f="$slowest" -v t="${seconds[$i]}" 'BEGIN{printf "%d", s * f / t + 0.5}')
  echo "${strategies[$i]}: ${seconds[$i]} s at $spp spp -> $n spp" | tee -a "$out/equal_time.txt"
  for seed in $seeds; do
    /usr/bin/time -f %U -o "$out/cpu.txt" "$pdflab" render --scene "$scene" "${size[@]}" \
      --strategy "${strategies[$i]}" --spp "$n" --seed "$seed" --threads 1 --reference "$out/ref.pfm" \
      --out "$out/run.pfm" --stats-json "$out/run.json" --quiet > /dev/null 2>&1
    python3 - "$out/run.json" "${strategies[$i]}" "$seed" "$n" "${seconds[$i]}" "$spp" "$(cat "$out/cpu.txt")" \
      >> "$out/runs.csv" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
timed = float(sys.argv[5]) / float(sys.argv[6]) * float(sys.argv[4])
print(f"{sys.argv[2]},{sys.argv[3]},{sys.argv[4]},{sys.argv[7]},{timed},{s['relmse']}")
PY
  done
done
python3 - "$out/runs.csv" <<'PY' | tee "$out/table.md"
import csv, math, statistics, sys
rows = list(csv.reader(open(sys.argv[1])))
by = {}
for strategy, seed, spp, seconds, timed, relmse in rows:
    by.setdefault(strategy, []).append((int(spp), float(seconds), float(timed), float(relmse)))
print("| strategy | spp | CPU seconds (mean of runs) | relMSE (mean of seeds, +- its standard error) | efficiency 1/(relMSE s) | vs first | timing's CPU seconds, scaled |")
print("|---|---|---|---|---|---|---|")
first = None
for strategy, runs in by.items():
    t = statistics.mean(r[1] for r in runs)
    rel = [r[3] for r in runs]
    m = statistics.mean(rel)
    se = statistics.stdev(rel) / math.sqrt(len(rel)) if len(rel) > 1 else float("nan")
    e = 1.0 / (m * t)
    first = first or e
    print(f"| {strategy} | {runs[0][0]} | {t:.2f} | {m:.4g} +- {se:.2g} | {e:.4g} | {e / first:.2f}x | {runs[0][2]:.2f} |")
PY
