#!/usr/bin/env bash
# Path guiding against `fastest` on assets/scenes/door_ajar.json at equal time,
# the training included (docs/guiding.md, "Measured"), from the CLI alone:
#   1. a reference (pdflab reference, REF_SPP samples per pixel of `fastest` as
#      it is on general scenes (the door scene's own `fastest` is guided):
#      the established estimator, so that a fault of guiding cannot hide in
#      the reference; the summary says how many times the largest run's
#      samples it holds);
#   2. equal time, training included: the first strategy (general `fastest`) rendered
#      at SPP samples per pixel on one thread takes T seconds (the render's
#      own clock); each other strategy is timed at SPP and 2 SPP (seed 7),
#      which gives its training time and its time per sample, and is then
#      given the samples that fill T;
#   3. SEEDS renders of each against the reference: relMSE, and efficiency
#      1 / (relMSE * seconds), the seconds being the render's own (training
#      included); per strategy the mean efficiency over the seeds with its
#      standard error, and its ratio to the first strategy's.
# Usage: scripts/guiding_measure.sh [OUT_DIR]
#   (PDFLAB, SPP, SEEDS, REF_SPP, WIDTH, HEIGHT, SCENE, STRATEGIES from the environment)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-guiding_out}
pdflab=${PDFLAB:-$here/build/release/app/pdflab}
spp=${SPP:-256}
seeds=${SEEDS:-"101 102 103 104"}
ref_spp=${REF_SPP:-16384}
width=${WIDTH:-100}
height=${HEIGHT:-75}
scene=${SCENE:-$here/assets/scenes/door_ajar.json}
# On the door scene `fastest` itself runs as path guiding (the scene sets
# fastest_uses_guiding), so the baseline and the reference name what fastest
# is on general scenes, as `pdflab --help` prints it.
general=$("$pdflab" --help | sed -n 's/^ *fastest: .* now \([^ ]*\)$/\1/p')
[ -n "$general" ] || { echo "guiding_measure.sh: cannot read fastest's expansion from pdflab --help" >&2; exit 2; }
read -r -a strategies <<< "${STRATEGIES:-$general nee-mis+mix:cosine=0.3,guided=0.7+sobol+rr:guided nee-mis+mix:cosine=0.5,guided=0.5+sobol+rr:guided nee-mis+mix:cosine=0.5,guided=0.5+sobol+rr:10}"
size=(--width "$width" --height "$height")
mkdir -p "$out"

[ -f "$out/ref.pfm" ] || "$pdflab" reference --scene "$scene" "${size[@]}" --strategy "$general" \
  --spp "$ref_spp" --out "$out/ref.pfm" --cache-dir "$out/cache" --quiet

# render STRATEGY SEED SPP [REFERENCE]: one render on one thread; its summary in $out/run.json.
render() {
  local extra=()
  [ -n "${4:-}" ] && extra=(--reference "$4")
  "$pdflab" render --scene "$scene" "${size[@]}" --strategy "$1" --spp "$3" --seed "$2" --threads 1 \
    "${extra[@]}" --out "$out/run.pfm" --stats-json "$out/run.json" --quiet > /dev/null 2>&1
}
seconds_of() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["seconds"])' "$out/run.json"; }

render "${strategies[0]}" 7 "$spp"
budget=$(seconds_of)
declare -a given
given[0]=$spp
for i in "${!strategies[@]}"; do
  [ "$i" = 0 ] && continue
  render "${strategies[$i]}" 7 "$spp"
  t1=$(seconds_of)
  render "${strategies[$i]}" 7 $((2 * spp))
  t2=$(seconds_of)
  given[$i]=$(awk -v b="$budget" -v t1="$t1" -v t2="$t2" -v n="$spp" 'BEGIN{
    per = (t2 - t1) / n; train = t1 - n * per; if (per <= 0) per = t1 / n;
    m = int((b - train) / per + 0.5); if (m < 1) m = 1; print m }')
  echo "${strategies[$i]}: ${t1} s at $spp spp, ${t2} s at $((2 * spp)): ${given[$i]} spp in ${budget} s" \
    | tee -a "$out/equal_time.txt"
done

echo "strategy;seed;spp;seconds;relmse;efficiency;guiding" > "$out/runs.csv"  # strategies hold commas
for i in "${!strategies[@]}"; do
  for seed in $seeds; do
    render "${strategies[$i]}" "$seed" "${given[$i]}" "$out/ref.pfm"
    python3 - "$out/run.json" "${strategies[$i]}" "$seed" >> "$out/runs.csv" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
g = s.get("guiding")
guide = f"{g['training_passes']} passes {g['leaves']} leaves {g['nodes']} nodes {g['bytes'] / 1048576:.2f} MiB" if g else ""
print(f"{sys.argv[2]};{sys.argv[3]};{s['spp']};{s['seconds']:.3f};{s['relmse']:.5g};{1 / (s['relmse'] * s['seconds']):.5g};{guide}")
PY
  done
done

python3 - "$out/runs.csv" "$ref_spp" <<'PY' | tee "$out/summary.txt"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter=";"))
by = {}
for r in rows:
    by.setdefault(r["strategy"], []).append(r)
most = max(int(r["spp"]) for r in rows)
print(f"reference: {sys.argv[2]} spp, {int(sys.argv[2]) / most:.0f}x the largest run's {most}")
base = None
for name, rs in by.items():
    e = [float(r["efficiency"]) for r in rs]
    m = sum(e) / len(e)
    se = math.sqrt(sum((x - m) ** 2 for x in e) / (len(e) - 1) / len(e)) if len(e) > 1 else 0.0
    if base is None:
        base = m
    rel = [float(r["relmse"]) for r in rs]
    print(f"{name}: {len(e)} seeds, {rs[0]['spp']} spp in {min(float(r['seconds']) for r in rs):.2f}-{max(float(r['seconds']) for r in rs):.2f} s, "
          f"relMSE {sum(rel) / len(rel):.4g}, efficiency {m:.4g} +- {se:.2g} ({m / base:.2f}x the first) {rs[0]['guiding']}")
PY
