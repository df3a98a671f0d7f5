#!/usr/bin/env bash
# Renders references for every shipped scene (assets/scenes/*.json, or the ones
# named in SCENES), benchmarks every strategy the binary accepts at equal time
# against them, and
# writes docs/convergence.md with the tables, the plots (SVG and PNG) and the
# interpretation kept in scripts/convergence_notes.md (prose lives there so a
# re-run refreshes the numbers without losing it).
#
#   bash scripts/convergence_report.sh          # about 10 minutes on 2 cores
#   SCENES="cornell_book small_light" bash scripts/convergence_report.sh
#
# Settings (environment): PDFLAB (binary, default build/release/app/pdflab),
# SIZE (image side, 200), REF_SPP (reference samples per pixel for every
# scene; default 2048, 8192 for the small-light box, whose reference needs more),
# BENCH_SECONDS (render time per strategy, 4), THREADS (0: all cores).
# NOTES_ONLY=1 rebuilds docs/convergence.md from the last run's files (after
# editing the notes) without rendering.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

PDFLAB=${PDFLAB:-build/release/app/pdflab}
SIZE=${SIZE:-200}
BENCH_SECONDS=${BENCH_SECONDS:-4}
THREADS=${THREADS:-0}
# The reference strategy: the book's mixture, unbiased and tested against the
# others; seed 1 (bench uses seed 2, so no sample is shared with a benchmark run).
REF_STRATEGY="mix:cosine=0.5,light=0.5"
if [[ -n ${SCENES:-} ]]; then
  read -r -a SCENES <<<"$SCENES"
else
  SCENES=(cornell_book small_light)  # the two the notes discuss first, then the rest
  for f in assets/scenes/*.json; do
    name=$(basename "$f" .json)
    [[ $name == cornell_book || $name == small_light ]] || SCENES+=("$name")
  done
fi
# The reference's noise adds to every measured relMSE about (run spp / reference
# spp) times the reference strategy's own relMSE; these keep that near a tenth
# for the reference strategy's own row at the default time.
declare -A REF_SPP_OF=()
for scene in "${SCENES[@]}"; do REF_SPP_OF[$scene]=${REF_SPP:-2048}; done
[[ -n ${REF_SPP_OF[small_light]:-} && -z ${REF_SPP:-} ]] && REF_SPP_OF[small_light]=8192

die() { echo "convergence_report: $*" >&2; exit 2; }
[[ -x $PDFLAB ]] || die "no binary at $PDFLAB (cmake --preset release && cmake --build --preset release)"
CONVERT=$(command -v convert) || die "ImageMagick's convert is needed for the PNG plots"
[[ -f scripts/convergence_notes.md ]] || die "scripts/convergence_notes.md (the interpretation) is missing"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

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
  echo "== $scene: reference, ${REF_SPP_OF[$scene]} spp at ${SIZE}x$SIZE" >&2
  "$PDFLAB" render --scene "$file" --strategy "$REF_STRATEGY" --spp "${REF_SPP_OF[$scene]}" --seed 1 \
    --width "$SIZE" --height "$SIZE" --threads "$THREADS" --quiet --out "$work/$scene.pfm" >&2
  "$PDFLAB" render --scene "$file" --strategy "$REF_STRATEGY" --spp 64 --seed 1 \
    --width "$SIZE" --height "$SIZE" --threads "$THREADS" --quiet --out "docs/convergence_${scene}_preview.png" >&2
  echo "== $scene: ${#strategies[@]} strategies, $BENCH_SECONDS s each" >&2
  "$PDFLAB" bench --scene "$file" --strategies "$strategy_list" --seconds "$BENCH_SECONDS" \
    --reference "$work/$scene.pfm" --threads "$THREADS" --quiet \
    --csv "docs/convergence_$scene.csv" --plot "docs/convergence_$scene.svg" \
    --curves "docs/convergence_${scene}_curves.csv" | tee "$work/$scene.txt" >&2
  "$CONVERT" -density 96 "docs/convergence_$scene.svg" "$work/$scene.png"
  mv "$work/$scene.png" "docs/convergence_$scene.png"
done
elapsed=$(( $(date +%s) - start ))
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
run_date=$(date -u +%Y-%m-%d)
{
  echo "elapsed=$elapsed commit=$commit run_date=$run_date SIZE=$SIZE BENCH_SECONDS=$BENCH_SECONDS"
  echo "SCENES=(${SCENES[*]})"
  printf 'REF_SPP_OF=('
  for scene in "${SCENES[@]}"; do printf '[%s]=%s ' "$scene" "${REF_SPP_OF[$scene]}"; done
  echo ')'
  echo "strategies_run=$(printf '%q' "$strategy_list")"
} > "$run_info"
fi

# An awk function both tables use: one CSV row into f[], the strategy field
# quoted (mixtures hold commas), the rest plain numbers.
SPLIT_ROW='
    function split_row(line, f,   rest, n) {
      rest = line
      if (substr(rest, 1, 1) == "\"") {
        f[1] = substr(rest, 2, index(substr(rest, 2), "\"") - 1)
        rest = substr(rest, length(f[1]) + 4)
        n = split(rest, tail, ",")
        for (i = 1; i <= n; ++i) f[i + 1] = tail[i]
        return n + 1
      }
      return split(rest, f, ",")
    }
'

# One markdown table from a bench CSV. The strategy field is quoted (mixtures
# hold commas); the rest are plain numbers. "vs cosine" is the efficiency ratio.
table() {
  awk "$SPLIT_ROW"'
    NR == 1 { for (i = 1; i <= split($0, h, ","); ++i) col[h[i]] = i; next }
    {
      split_row($0, f)
      ++rows
      for (c in col) v[rows, c] = f[col[c]]
      if (f[col["strategy"]] == "cosine") cosine_eff = f[col["efficiency"]]
    }
    END {
      print "| strategy | unbiased | spp | seconds | relMSE | est. relMSE | efficiency | vs cosine | M samples/s | dropped |"
      print "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"
      for (r = 1; r <= rows; ++r) {
        ratio = cosine_eff > 0 ? sprintf("%.2fx", v[r, "efficiency"] / cosine_eff) : "-"
        printf "| `%s` | %s | %d | %.2f | %.4g | %.4g | %.4g | %s | %.2f | %d |\n", v[r, "strategy"],
               v[r, "unbiased"] == 1 ? "yes" : "**no**", v[r, "spp"], v[r, "seconds"], v[r, "relmse"],
               v[r, "est_relmse"], v[r, "efficiency"], ratio, v[r, "samples_per_second"] / 1e6, v[r, "dropped"]
      }
    }' "$1"
}

# Sentences computed from the numbers, so they cannot disagree with the table:
# the most efficient unbiased strategy, how far the reference-free estimate is
# from the measured relMSE for cosine and for the winner, and the reference's
# share of the error (from the run of the reference's own strategy).
summary() {
  awk -v ref_spp="$2" -v ref_strategy="$REF_STRATEGY" "$SPLIT_ROW"'
    NR == 1 { for (i = 1; i <= split($0, h, ","); ++i) col[h[i]] = i; next }
    {
      split_row($0, f)
      s = f[col["strategy"]]; e = f[col["efficiency"]] + 0
      if (s == "cosine") { ce = e; cm = f[col["relmse"]]; cest = f[col["est_relmse"]] }
      if (s == ref_strategy) { floor_relmse = f[col["est_relmse"]] * f[col["spp"]] / ref_spp; rm = f[col["relmse"]] }
      if (f[col["unbiased"]] == 1 && e > best) { best = e; bs = s; bm = f[col["relmse"]]; best_est = f[col["est_relmse"]] }
    }
    END {
      printf "Most efficient unbiased strategy here: `%s`, %.3gx the efficiency of `cosine`. ", bs, (ce > 0 ? best / ce : 0)
      printf "The film'"'"'s own estimate of relMSE (no reference) is %.2gx the measured value for `cosine` ", cest / cm
      printf "and %.2gx for `%s`. ", best_est / bm, bs
      printf "The reference'"'"'s own noise accounts for roughly %.0f%% of the measured relMSE of `%s` ", 100 * floor_relmse / rm, ref_strategy
      printf "(its sample-variance estimate, scaled by the ratio of sample counts; less for noisier rows).\n"
    }' "$1"
}

{
  cat <<EOF
# Convergence: what each sampling strategy buys per second

Generated by \`scripts/convergence_report.sh\` (commit \`$commit\`, $run_date, $(nproc) cores,
about $elapsed s). Each scene is rendered at ${SIZE}x$SIZE. The reference is \`$REF_STRATEGY\`
(seed 1) at $(for s in "${SCENES[@]}"; do printf '%s spp for %s, ' "${REF_SPP_OF[$s]}" "$s"; done | sed 's/, $//');
every strategy then renders for $BENCH_SECONDS s (equal time, seed 2) and is compared with it.

- relMSE = mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01); efficiency = 1 / (relMSE * seconds),
  higher is better, and for an unbiased strategy it does not depend on how long it ran.
- *est. relMSE* is what the render predicts about itself from its per-pixel sample variance, with no reference.
- *vs cosine*: efficiency relative to cosine sampling, the book's starting point.
- The reference has its own noise, which adds about (spp of a run / reference spp) of the reference
  strategy's relMSE to every row: the best rows are slightly pessimistic.
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

$(summary "docs/convergence_$scene.csv" "${REF_SPP_OF[$scene]}")

RMSE against time, log-log ([SVG](convergence_$scene.svg)); the dashed line has the slope of 1/sqrt(N):

![RMSE against time for $scene](convergence_$scene.png)

Raw numbers: [convergence_$scene.csv](convergence_$scene.csv), every checkpoint:
[convergence_${scene}_curves.csv](convergence_${scene}_curves.csv).

EOF
  done
  cat scripts/convergence_notes.md
} > "$work/convergence.md"
mv "$work/convergence.md" docs/convergence.md
echo "wrote docs/convergence.md ($elapsed s)" >&2
