#!/usr/bin/env bash
# Makes a reference with `pdflab reference` for every shipped scene
# (assets/scenes/*.json, or the ones named in SCENES), benchmarks every strategy
# the binary accepts at equal time against it with several independent seeds,
# and writes docs/convergence.md with the tables (means and 95% intervals over
# the seeds), the plots (SVG and PNG) and the interpretation kept in
# scripts/convergence_notes.md (prose lives there so a re-run refreshes the
# numbers without losing it).
#
# Each reference gets REF_FACTOR (48) times the samples per pixel of the
# most-sampled run of its scene: a short calibration run of every strategy
# measures their speeds first, so the reference's own noise stays a few per cent
# of the best row's error whatever the machine's speed. Its time is about
# 7 scenes x (REF_FACTOR x BENCH_SECONDS x (fastest strategy / reference strategy)
# + 11 strategies x (SEEDS + 1) x BENCH_SECONDS), plus set-up:
#   bash scripts/convergence_report.sh     # defaults: about an hour on 2 cores
#   SIZE=100 BENCH_SECONDS=1 bash scripts/convergence_report.sh   # about 20 minutes
#   SCENES="cornell_book small_light" bash scripts/convergence_report.sh
#
# Settings (environment): PDFLAB (binary, default build/release/app/pdflab),
# SIZE (image side, 200), BENCH_SECONDS (render time per strategy and seed, 4),
# SEEDS (independent runs per strategy, 4: seeds 2, 3, ...), REF_FACTOR (the
# reference's samples per pixel over the fastest strategy's in calibration, 48;
# at least 32), THREADS (0: all cores).
# NOTES_ONLY=1 rebuilds docs/convergence.md from the last run's files (after
# editing the notes) without rendering.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

PDFLAB=${PDFLAB:-build/release/app/pdflab}
SIZE=${SIZE:-200}
BENCH_SECONDS=${BENCH_SECONDS:-4}
SEEDS=${SEEDS:-4}
REF_FACTOR=${REF_FACTOR:-48}
THREADS=${THREADS:-0}
# What `pdflab reference` renders with by default on these scenes (the most
# efficient unbiased strategy in the boxes); nee-mis where the report finds it
# the most efficient by far (the open far-light scene). The table's reference
# share says whether the reference's noise is small enough.
REF_STRATEGY="mix:cosine=0.5,light=0.5"
declare -A REF_STRATEGY_OF=([far_light]=nee-mis)
if [[ -n ${SCENES:-} ]]; then
  read -r -a SCENES <<<"$SCENES"
else
  SCENES=(cornell_book small_light)  # the two the notes discuss first, then the rest
  for f in assets/scenes/*.json; do
    name=$(basename "$f" .json)
    [[ $name == cornell_book || $name == small_light ]] || SCENES+=("$name")
  done
fi
[[ $REF_FACTOR =~ ^[0-9]+$ ]] && (( REF_FACTOR >= 32 )) ||
  { echo "convergence_report: REF_FACTOR must be a whole number of at least 32" >&2; exit 2; }
(( SEEDS >= 2 )) || { echo "convergence_report: SEEDS must be at least 2 (intervals need them)" >&2; exit 2; }

die() { echo "convergence_report: $*" >&2; exit 2; }
[[ -x $PDFLAB ]] || die "no binary at $PDFLAB (cmake --preset release && cmake --build --preset release)"
CONVERT=$(command -v convert) || die "ImageMagick's convert is needed for the PNG plots"
[[ -f scripts/convergence_notes.md ]] || die "scripts/convergence_notes.md (the interpretation) is missing"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The report's own cache: it never uses (or fills) the user's.
cache=$work/cache

# A strategy exists when a one-sample render accepts it; new techniques join
# the report without editing this script.
accepts() {
  "$PDFLAB" render --scene assets/scenes/cornell_book.json --strategy "$1" --spp 1 --width 2 --height 2 \
    --threads 1 --quiet --out "$work/probe.pfm" >/dev/null 2>&1
}
strategies=(cosine uniform-hemisphere uniform-sphere light "mix:cosine=0.5,light=0.5" "mix:cosine=0.25,light=0.75")
if accepts light-sa; then
  strategies+=(light-sa "mix:cosine=0.5,light-sa=0.5" "mix:cosine=0.25,light-sa=0.75")
fi
if accepts nee-mis; then strategies+=(nee-mis nee-mis:balance); fi
strategy_list=$(IFS=';'; echo "${strategies[*]}")

mkdir -p docs
run_info=docs/convergence_run.env
if [[ ${NOTES_ONLY:-0} == 1 ]]; then
  [[ -f $run_info ]] || die "NOTES_ONLY=1 needs a previous full run ($run_info)"
  # shellcheck source=/dev/null
  source "$run_info"
else
start=$(date +%s)
for scene in "${SCENES[@]}"; do
  file=assets/scenes/$scene.json
  # Calibration: the run time for every strategy, against a rough reference;
  # the fastest one's samples per pixel per second sets the reference's size.
  echo "== $scene: calibrating the strategies' speeds" >&2
  # (bench needs a reference to compare with: a rough one does for timing)
  calibration_seconds=$BENCH_SECONDS
  "$PDFLAB" reference --scene "$file" --width "$SIZE" --height "$SIZE" --seconds "$calibration_seconds" \
    --threads "$THREADS" --cache-dir "$work/calibration" --out "$work/$scene.calibration.pfm" --quiet >&2
  "$PDFLAB" bench --scene "$file" --strategies "$strategy_list" --seconds "$calibration_seconds" \
    --reference "$work/$scene.calibration.pfm" --threads "$THREADS" --quiet --csv "$work/$scene.calibration.csv" >&2
  ref_spp=$(awk -v f="$REF_FACTOR" -v b="$BENCH_SECONDS" '
    NR == 1 { for (i = 1; i <= split($0, h, ","); ++i) col[h[i]] = i; next }
    {
      sub(/"[^"]*"/, "s")  # the strategy, which may hold commas
      split($0, g, ",")
      if (g[col["seconds"]] > 0 && g[col["spp"]] / g[col["seconds"]] > rate) rate = g[col["spp"]] / g[col["seconds"]]
    }
    END { n = int(f * rate * b) + 1; print (n > 1 ? n : 1) }' "$work/$scene.calibration.csv")
  echo "== $scene: reference, $ref_spp spp at ${SIZE}x$SIZE ($REF_FACTOR x the fastest run's)" >&2
  "$PDFLAB" reference --scene "$file" --width "$SIZE" --height "$SIZE" --spp "$ref_spp" \
    --strategy "${REF_STRATEGY_OF[$scene]:-$REF_STRATEGY}" \
    --threads "$THREADS" --cache-dir "$cache" --out "$work/$scene.pfm" --quiet >&2
  cp "$work/$scene.json" "docs/convergence_${scene}_reference.json"
  "$CONVERT" "$work/$scene.pfm" -gamma 2 -resize 200x200 "docs/convergence_${scene}_preview.png" 2>/dev/null ||
    "$PDFLAB" render --scene "$file" --strategy "$REF_STRATEGY" --spp 64 --width "$SIZE" --height "$SIZE" \
      --threads "$THREADS" --quiet --out "docs/convergence_${scene}_preview.png" >&2
  rm -f "docs/convergence_${scene}.csv"
  for ((k = 0; k < SEEDS; ++k)); do
    seed=$((2 + k))
    echo "== $scene: ${#strategies[@]} strategies, $BENCH_SECONDS s each, seed $seed" >&2
    extra=()
    # The first seed's run also draws the plot and keeps every checkpoint.
    ((k == 0)) && extra=(--plot "docs/convergence_$scene.svg" --curves "docs/convergence_${scene}_curves.csv")
    "$PDFLAB" bench --scene "$file" --strategies "$strategy_list" --seconds "$BENCH_SECONDS" --seed "$seed" \
      --reference auto --width "$SIZE" --height "$SIZE" --cache-dir "$cache" --threads "$THREADS" --quiet \
      --csv "$work/$scene.$seed.csv" "${extra[@]}" >&2
    # One CSV for the scene: the bench columns with the seed in front.
    awk -v seed="$seed" -v first=$((k == 0)) 'NR == 1 { if (first) print "seed," $0; next } { print seed "," $0 }' \
      "$work/$scene.$seed.csv" >>"docs/convergence_${scene}.csv"
  done
  "$CONVERT" -density 96 "docs/convergence_$scene.svg" "$work/$scene.png"
  mv "$work/$scene.png" "docs/convergence_$scene.png"
done
elapsed=$(( $(date +%s) - start ))
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
run_date=$(date -u +%Y-%m-%d)
{
  echo "elapsed=$elapsed commit=$commit run_date=$run_date SIZE=$SIZE BENCH_SECONDS=$BENCH_SECONDS SEEDS=$SEEDS"
  echo "REF_FACTOR=$REF_FACTOR"
  echo "SCENES=(${SCENES[*]})"
  echo "strategies_run=$(printf '%q' "$strategy_list")"
} > "$run_info"
fi

# An awk function the tables use: one CSV row into f[], the strategy field
# quoted (mixtures hold commas), the rest plain numbers.
SPLIT_ROW='
    function split_row(line, f,   rest, n, head, i) {
      rest = line
      n = 0
      while (substr(rest, 1, 1) != "\"" && index(rest, ",") > 0 && n < 1) {
        f[++n] = substr(rest, 1, index(rest, ",") - 1)
        rest = substr(rest, index(rest, ",") + 1)
      }
      if (substr(rest, 1, 1) == "\"") {
        f[++n] = substr(rest, 2, index(substr(rest, 2), "\"") - 1)
        rest = substr(rest, length(f[n]) + 4)
      }
      m = split(rest, tail, ",")
      for (i = 1; i <= m; ++i) f[n + i] = tail[i]
      return n + m
    }
'

# The per-scene figures, one line per strategy (in the order run), tab-separated:
# strategy unbiased spp seconds relmse relmse_ci raw est eff eff_ci ratio ratio_lo ratio_hi share msps ref_noise
# Means over the seeds; *_ci are 95% t calibration_seconds widths over them; the ratio to
# cosine is taken seed by seed (independent runs) and averaged.
aggregate() {
  awk "$SPLIT_ROW$(<scripts/student_t.awk)"'
    NR == 1 { for (i = 1; i <= split($0, h, ","); ++i) col[h[i]] = i; next }
    {
      split_row($0, f)
      s = f[col["strategy"]]; seed = f[col["seed"]]
      if (!(s in seen)) { seen[s] = 1; order[++ns] = s }
      n[s]++
      unb[s] = f[col["unbiased"]]
      e = f[col["efficiency"]] + 0; r = f[col["relmse"]] + 0
      eff[s, seed] = e; seeds[seed] = 1
      sum_e[s] += e; sq_e[s] += e * e; sum_r[s] += r; sq_r[s] += r * r
      sum_raw[s] += f[col["relmse_raw"]]; sum_est[s] += f[col["est_relmse"]]
      sum_spp[s] += f[col["spp"]]; sum_sec[s] += f[col["seconds"]]; sum_sps[s] += f[col["samples_per_second"]]
      sum_share[s] += f[col["ref_share"]]
      ref_noise[s] += f[col["ref_share"]] * f[col["relmse_raw"]]
    }
    function hw(sum, sq, k,   m, v) { if (k < 2) return 0; m = sum / k; v = (sq - k * m * m) / (k - 1); return t95(k) * sqrt(v > 0 ? v : 0) / sqrt(k) }
    END {
      for (i = 1; i <= ns; ++i) {
        s = order[i]; k = n[s]
        rs = 0; rq = 0; rk = 0
        for (seed in seeds) if ((s, seed) in eff && ("cosine", seed) in eff && eff["cosine", seed] > 0) {
          q = eff[s, seed] / eff["cosine", seed]; rs += q; rq += q * q; ++rk
        }
        rm = rk ? rs / rk : 0; rh = hw(rs, rq, rk)
        printf "%s\t%d\t%.0f\t%.2f\t%.4g\t%.2g\t%.4g\t%.4g\t%.4g\t%.2g\t%.3g\t%.3g\t%.3g\t%.3g\t%.2f\t%.4g\n", s, unb[s],
               sum_spp[s] / k, sum_sec[s] / k, sum_r[s] / k, hw(sum_r[s], sq_r[s], k), sum_raw[s] / k, sum_est[s] / k,
               sum_e[s] / k, hw(sum_e[s], sq_e[s], k), rm, (rm - rh > 0 ? rm - rh : 0), rm + rh, sum_share[s] / k,
               sum_sps[s] / k / 1e6, ref_noise[s] / k
      }
    }' "$1"
}

# One markdown table from the aggregate.
table() {
  aggregate "$1" | awk -F '\t' '
    BEGIN {
      print "| strategy | unbiased | spp | seconds | relMSE (95% CI) | raw relMSE | est. relMSE | efficiency (95% CI) | vs cosine (95% CI) | ref. share | M samples/s |"
      print "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    }
    {
      printf "| `%s` | %s | %d | %.2f | %.4g ± %.2g | %.4g | %.4g | %.4g ± %.2g | %.3gx [%.3g, %.3g] | %.1f%% | %.2f |\n",
             $1, $2 == 1 ? "yes" : "**no**", $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, 100 * $14, $15
    }'
}

# Sentences computed from the numbers, so they cannot disagree with the table:
# the reference and its share of the best row's error, the most efficient
# unbiased strategy, and how far the film's own estimate is from the measured relMSE.
summary() {
  local side=$2
  local ref_spp ref_seconds ref_est
  ref_spp=$(sed -n 's/^ *"spp": *\([0-9]*\).*/\1/p' "$side")
  ref_seconds=$(sed -n 's/^ *"seconds": *\([0-9.e+-]*\).*/\1/p' "$side")
  ref_est=$(sed -n 's/^ *"estimated_relmse": *\([0-9.e+-]*\).*/\1/p' "$side")
  ref_strategy=$(sed -n 's/^ *"strategy": *"\(.*\)",*$/\1/p' "$side")
  aggregate "$1" | awk -F '\t' -v ref_spp="$ref_spp" -v ref_seconds="$ref_seconds" -v ref_est="$ref_est" \
      -v ref_strategy="$ref_strategy" -v seeds="$SEEDS" '
    {
      s = $1
      if (s == ref_strategy) own_spp = $3
      if ($3 > max_spp) max_spp = $3
      noise = $16
      if ($2 == 1 && $5 > 0 && (best_r == "" || $5 < best_r)) { best_r = $5; best_rs = s }
      if ($2 == 1 && $9 > best_e) { best_e = $9; best_es = s; best_ratio = $11; best_lo = $12; best_hi = $13; best_est = $8; best_m = $5 }
      if (s == "cosine") { cm = $5; cest = $8 }
    }
    END {
      share = best_r > 0 ? noise / best_r : 0
      printf "Reference: `pdflab reference`, `%s`, %d spp in %.0f s (%.0fx the spp of its own strategy'"'"'s run, %.0fx the most of any run%s); ", ref_strategy, ref_spp, ref_seconds, (own_spp > 0 ? ref_spp / own_spp : 0), (max_spp > 0 ? ref_spp / max_spp : 0), (max_spp > 0 && ref_spp < 32 * max_spp ? ", LESS than the 32x this report aims at" : "")
      printf "its own noise (relMSE %.3g) is **%.1f%%** of the best row'"'"'s relMSE (`%s`, %.4g)%s. ", noise, 100 * share, best_rs, best_r, (share <= 0.05 ? ", within the 5% this report aims at" : ", MORE than the 5% this report aims at: the ranking of the best rows is not settled")
      printf "Most efficient unbiased strategy here: `%s`, %.3gx the efficiency of `cosine` (95%% interval %.3g to %.3g over %d seeds). ", best_es, best_ratio, best_lo, best_hi, seeds
      printf "The film'"'"'s own estimate of relMSE (no reference) is %.2gx the measured value for `cosine` and %.2gx for `%s`.\n", (cm > 0 ? cest / cm : 0), (best_m > 0 ? best_est / best_m : 0), best_es
    }'
}

{
  cat <<EOF
# Convergence: what each sampling strategy buys per second

Generated by \`scripts/convergence_report.sh\` (commit \`$commit\`, $run_date, $(nproc) cores,
$elapsed s in all) with \`SIZE=$SIZE BENCH_SECONDS=$BENCH_SECONDS SEEDS=$SEEDS REF_FACTOR=$REF_FACTOR\`.
Each scene is rendered at ${SIZE}x$SIZE. Its reference is made by \`pdflab reference\` (seeds reserved for
references) with $REF_FACTOR times the samples per pixel of the fastest strategy's run (measured by a short
calibration run first), with its default strategy, \`$REF_STRATEGY\`, or where that is far from the
most efficient, the one named below the table (\`nee-mis\` for the far light); every strategy then
renders for $BENCH_SECONDS s (equal time) with each of $SEEDS seeds (2 to $((SEEDS + 1))), and is compared with it.

- relMSE = mean over pixels and channels of ((x - ref)^2 - var(ref)) / (ref^2 + 0.01): the error against
  the true image, with the reference's own noise (its per-pixel variance of the mean) removed
  ([measuring.md](measuring.md)); *raw relMSE* leaves it in. Means over the seeds, with 95% Student t
  intervals over them.
- efficiency = 1 / (relMSE * seconds), higher is better, and for an unbiased strategy it does not depend
  on how long it ran. *vs cosine*: the ratio of efficiencies to cosine sampling (the book's starting
  point), seed by seed, averaged, with its 95% interval.
- *ref. share*: the reference's own noise as a part of the row's raw relMSE. Below each table: that noise
  against the best row's relMSE, which the report keeps at 5% or less.
- *est. relMSE* is what the render predicts about itself from its per-pixel sample variance, with no
  reference: a lower bound.
- A strategy marked **no** under *unbiased* (pure \`light\`) never sees indirect light: its error
  stops falling at the size of what it misses, so its efficiency is not comparable with the others.
- Timings come from a machine shared with other work; ratios within one table are more trustworthy
  than absolute samples per second.

EOF
  for scene in "${SCENES[@]}"; do
    title=$(sed -n 's/^ *"name": *"\(.*\)",$/\1/p' "assets/scenes/$scene.json" | head -1)
    cat <<EOF
## $title (\`assets/scenes/$scene.json\`)

![reference preview](convergence_${scene}_preview.png)

$(table "docs/convergence_$scene.csv")

$(summary "docs/convergence_$scene.csv" "docs/convergence_${scene}_reference.json")

RMSE against time (seed 2), log-log ([SVG](convergence_$scene.svg)); the dashed line has the slope of 1/sqrt(N):

![RMSE against time for $scene](convergence_$scene.png)

Raw numbers, every seed: [convergence_$scene.csv](convergence_$scene.csv); every checkpoint of seed 2:
[convergence_${scene}_curves.csv](convergence_${scene}_curves.csv); the reference's sidecar:
[convergence_${scene}_reference.json](convergence_${scene}_reference.json).

EOF
  done
  cat scripts/convergence_notes.md
} > "$work/convergence.md"
mv "$work/convergence.md" docs/convergence.md
echo "wrote docs/convergence.md ($elapsed s)" >&2
