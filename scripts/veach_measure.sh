#!/usr/bin/env bash
# Veach's table and figure (docs/veach.md) from the CLI alone:
#   1. a reference of assets/scenes/veach_mis.json (pdflab reference, 4096 spp of
#      nee-mis+mix:bsdf=0.5,light-sa=0.5: at least 64x every run below);
#   2. the four estimators at equal time: each timed at SPP samples per pixel
#      on one thread (the best of five, in turn), then given SPP * (fastest
#      time / its time) samples;
#   3. SEEDS renders of each (--reference: the whole image's relMSE in each summary);
#   4. scripts/veach_table.py: relMSE per plate and per plate-light pair;
#      scripts/veach_panel.py: the four renders of the first seed as one PNG.
# Usage: scripts/veach_measure.sh [OUT_DIR] (PDFLAB, SPP, SEEDS, REF_SPP from the environment)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-veach_out}
pdflab=${PDFLAB:-$here/build/release/app/pdflab}
spp=${SPP:-64}
seeds=${SEEDS:-"101 102 103 104 105 106 107 108"}
ref_spp=${REF_SPP:-4096}
scene=$here/assets/scenes/veach_mis.json
mkdir -p "$out"
labels=("BSDF only (bsdf)" "light only (light-sa)" "balance (nee-mis:balance+bsdf)" "power (nee-mis+bsdf)")
strategies=("bsdf" "light-sa" "nee-mis:balance+bsdf" "nee-mis+bsdf")

[ -f "$out/ref.pfm" ] || "$pdflab" reference --scene "$scene" --strategy "nee-mis+mix:bsdf=0.5,light-sa=0.5" \
  --spp "$ref_spp" --out "$out/ref.pfm" --cache-dir "$out/cache" --quiet

# Seconds per render at $spp on one thread: the best of five, the estimators
# taken in turn (A B C D A B C D ...) so that a drift in the machine's speed
# falls on all four alike.
declare -a seconds
for k in 1 2 3 4 5; do
  for i in "${!strategies[@]}"; do
    t=$("$pdflab" render --scene "$scene" --strategy "${strategies[$i]}" --spp "$spp" --seed 7 --threads 1 \
          --out "$out/timing.pfm" --quiet 2>&1 | head -1 | awk '{print $4}')
    seconds[$i]=$(awk -v a="${seconds[$i]:-$t}" -v b="$t" 'BEGIN{print (b < a) ? b : a}')
  done
done
fastest=$(printf '%s\n' "${seconds[@]}" | sort -g | head -1)

args=()
for i in "${!strategies[@]}"; do
  n=$(awk -v s="$spp" -v f="$fastest" -v t="${seconds[$i]}" 'BEGIN{printf "%d", s * f / t + 0.5}')
  tag=$(echo "${strategies[$i]}" | tr ':+' '__')
  echo "${strategies[$i]}: ${seconds[$i]} s at $spp spp -> $n spp" | tee -a "$out/equal_time.txt"
  runs=
  for seed in $seeds; do
    "$pdflab" render --scene "$scene" --strategy "${strategies[$i]}" --spp "$n" --seed "$seed" --threads 1 \
      --reference "$out/ref.pfm" --out "$out/${tag}_$seed.pfm" --quiet 2>&1 | head -2 | tr '\n' ' ' >> "$out/runs.log"
    echo >> "$out/runs.log"
    runs=${runs:+$runs,}$out/${tag}_$seed.pfm
  done
  args+=("${labels[$i]}=$runs")
done
python3 "$here/scripts/veach_table.py" "$out/ref.pfm" "${args[@]}" | tee "$out/table.md"
first=${seeds%% *}
python3 "$here/scripts/veach_panel.py" "$out/veach_panel.png" \
  "$out/bsdf_$first.pfm" "$out/light-sa_$first.pfm" "$out/nee-mis_balance_bsdf_$first.pfm" "$out/nee-mis_bsdf_$first.pfm"
