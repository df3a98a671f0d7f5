#!/usr/bin/env bash
# The table that chooses `fastest`: each candidate's efficiency at equal time
# against the book's mixture, seed by seed, on the shipped scenes (or those in
# SCENES). A calibration run gives every candidate SECONDS_PER_RUN; each then
# renders the samples per pixel it reached there, with every seed, so the
# reference, with REF_FACTOR (48) times the most of them, has exactly that
# multiple of the most-sampled run whatever the machine's load does meanwhile
# (efficiency is 1 / (relMSE x the run's own time)). Prints one markdown row
# per scene and candidate (mean ratio and its 95% t interval over the seeds),
# the reference's multiple and the load average before and after each scene;
# keeps the CSVs in OUT.
#   bash scripts/fastest_report.sh                           # 100x100, 2 s runs, 4 seeds: about 15 min on 2 cores
#   SIZE=600 SECONDS_PER_RUN=5 SCENES=cornell_book bash scripts/fastest_report.sh
# Settings (environment): PDFLAB (binary), SIZE (100), SECONDS_PER_RUN (2), SEEDS (4: seeds 2, 3, ...),
# REF_FACTOR (48, at least 32), THREADS (0: all cores), OUT (a new temporary folder), CANDIDATES
# (';'-separated; the first is the yardstick).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

PDFLAB=${PDFLAB:-build/release/app/pdflab}
SIZE=${SIZE:-100}
SECONDS_PER_RUN=${SECONDS_PER_RUN:-2}
SEEDS=${SEEDS:-4}
REF_FACTOR=${REF_FACTOR:-48}
THREADS=${THREADS:-0}
OUT=${OUT:-$(mktemp -d)}
CANDIDATES=${CANDIDATES:-"mix:cosine=0.5,light=0.5;fastest;nee-mis;nee-mis+sobol;nee-mis+mix:cosine=0.8,specular-objects=0.2+sobol+rr:8"}
die() { echo "fastest_report: $*" >&2; exit 2; }
[[ -x $PDFLAB ]] || die "no binary at $PDFLAB"
[[ $REF_FACTOR =~ ^[0-9]+$ ]] && (( REF_FACTOR >= 32 )) || die "REF_FACTOR must be a whole number of at least 32"
[[ $SEEDS =~ ^[0-9]+$ ]] && (( SEEDS >= 2 )) || die "SEEDS must be a whole number of at least 2"
if [[ -n ${SCENES:-} ]]; then read -r -a SCENES <<<"$SCENES"; else
  SCENES=()
  for f in assets/scenes/*.json; do SCENES+=("$(basename "$f" .json)"); done
fi
declare -A REF_STRATEGY_OF=([far_light]=nee-mis)  # as scripts/convergence_report.sh
mkdir -p "$OUT"

# The CSV's rows as: strategy <tab> spp <tab> seconds <tab> efficiency (the strategy may hold commas).
rows() { awk 'NR > 1 { q = index(substr($0, 2), "\""); s = substr($0, 2, q - 1); rest = substr($0, q + 3)
                       split(rest, f, ","); print s "\t" f[1] "\t" f[2] "\t" f[5] }' "$1"; }

echo "| scene | candidate | spp | efficiency / book mixture (95% CI, $SEEDS seeds) |"
echo "|---|---|---:|---:|"
for scene in "${SCENES[@]}"; do
  file=assets/scenes/$scene.json
  load_before=$(cut -d' ' -f1-3 /proc/loadavg)
  "$PDFLAB" reference --scene "$file" --width "$SIZE" --height "$SIZE" --spp 16 --threads "$THREADS" \
    --cache-dir "$OUT/cache" --out "$OUT/$scene.rough.pfm" --quiet >&2
  "$PDFLAB" bench --scene "$file" --strategies "$CANDIDATES" --seconds "$SECONDS_PER_RUN" --seed 1 \
    --reference "$OUT/$scene.rough.pfm" --threads "$THREADS" --quiet --csv "$OUT/$scene.calibration.csv" >/dev/null
  ref_spp=$(rows "$OUT/$scene.calibration.csv" | awk -F '\t' -v f="$REF_FACTOR" '$2 > m { m = $2 } END { print int(f * m) + 1 }')
  ref_strategy=${REF_STRATEGY_OF[$scene]:-mix:cosine=0.5,light=0.5}
  "$PDFLAB" reference --scene "$file" --width "$SIZE" --height "$SIZE" --spp "$ref_spp" --strategy "$ref_strategy" \
    --threads "$THREADS" --cache-dir "$OUT/cache" --out "$OUT/$scene.pfm" --quiet >&2
  : >"$OUT/$scene.tsv"
  mapfile -t calibrated < <(rows "$OUT/$scene.calibration.csv" | cut -f1,2)
  for ((k = 0; k < SEEDS; ++k)); do
    seed=$((2 + k))
    for ((c = 0; c < ${#calibrated[@]}; ++c)); do
      strategy=${calibrated[c]%%$'\t'*}
      spp=${calibrated[c]##*$'\t'}
      "$PDFLAB" bench --scene "$file" --strategies "$strategy" --spp "$spp" --seed "$seed" \
        --reference "$OUT/$scene.pfm" --threads "$THREADS" --quiet --csv "$OUT/$scene.$seed.$c.csv" >/dev/null
      rows "$OUT/$scene.$seed.$c.csv" | awk -v seed="$seed" '{ print seed "\t" $0 }' >>"$OUT/$scene.tsv"
    done
  done
  load_after=$(cut -d' ' -f1-3 /proc/loadavg)
  awk -F '\t' -v scene="$scene" -v ref_spp="$ref_spp" -v lb="$load_before" -v la="$load_after" -v size="$SIZE" "$(<scripts/student_t.awk)"'
    NR == 1 { first = $2 }
    $2 == first { base[$1] = $5 }
    { if (!($2 in seen)) { seen[$2] = 1; order[++n] = $2 } eff[$2, $1] = $5; spp[$2] += $3; cnt[$2]++; if ($3 > most) most = $3; seeds[$1] = 1 }
    END {
      for (i = 1; i <= n; ++i) {
        s = order[i]; sum = 0; sq = 0; k = 0
        for (seed in seeds) if (base[seed] > 0) { q = eff[s, seed] / base[seed]; sum += q; sq += q * q; ++k }
        if (k == 0) { printf "| %s | `%s` | | no seed of the book mixture has an efficiency |\n", scene, s; continue }
        m = sum / k; v = k > 1 ? (sq - k * m * m) / (k - 1) : 0; h = t95(k) * sqrt(v > 0 ? v : 0) / sqrt(k)
        printf "| %s | `%s` | %.0f | %.2fx [%.2f, %.2f] |\n", scene, s, spp[s] / cnt[s], m, (m - h > 0 ? m - h : 0), m + h
      }
      printf "| %s | reference: %d spp, %.1fx the most-sampled run (%d spp); %dx%d; load %s before, %s after | | |\n", scene, ref_spp, ref_spp / most, most, size, size, lb, la
    }' "$OUT/$scene.tsv"
done
echo "CSVs in $OUT" >&2
