#!/usr/bin/env bash
# GUI smoke test: the viewer under Xvfb, driven with xdotool.
#   gui_smoke.sh PDFLAB SCENE ARTIFACT_DIR
# Exit 77 (ctest SKIP_RETURN_CODE) only when xvfb-run itself is missing; any
# other missing tool is a failure, so a broken setup cannot pass as "skipped".
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x800x24" "xdotool import identify" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3
rm -rf "$art"
mkdir -p "$art/shots"

# png_stats FILE -> "width height mean stddev" (mean and stddev in 0..1)
png_stats() { identify -format "%w %h %[fx:mean] %[fx:standard_deviation]" "$1"; }
# abs_diff A B
abs_diff() { awk -v a="$1" -v b="$2" 'BEGIN { d = a - b; if (d < 0) d = -d; printf "%.6f", d }'; }

echo "== bad input exits 2 without a window"
set +e
"$pdflab" --scene "$scene" --strategy bogus --spp 2 --screenshot "$art/never.png" 2>"$art/bad_strategy.txt"
[ $? -eq 2 ] || fail "unknown strategy: expected status 2"
"$pdflab" --scene "$art/missing.json" --spp 2 --screenshot "$art/never.png" 2>"$art/bad_scene.txt"
[ $? -eq 2 ] || fail "missing scene: expected status 2"
"$pdflab" --scene "$scene" --spp 2 --screenshot "$art/no/such/folder/x.png" 2>"$art/bad_out.txt"
[ $? -eq 2 ] || fail "unwritable screenshot path: expected status 2"
"$pdflab" --scene "$scene" --ui-scale 9 2>"$art/bad_ui_scale.txt"
[ $? -eq 2 ] || fail "--ui-scale 9: expected status 2"
set -e
[ ! -e "$art/never.png" ] || fail "bad input left an output file"
cat "$art"/bad_*.txt

echo "== --screenshot renders in the window, saves, exits 0"
"$pdflab" --scene "$scene" --strategy cosine --spp 8 --screenshot "$art/cli.png"
for f in cli.png cli.pfm cli.json; do [ -s "$art/$f" ] || fail "missing $f"; done
read -r w h _ _ <<<"$(png_stats "$art/cli.png")"
[ "$w" = 96 ] && [ "$h" = 96 ] || fail "cli.png is ${w}x${h}, expected 96x96"
[ "$(json_field "$art/cli.json" spp)" = 8 ] || fail "cli.json spp"

echo "== interactive: preset key 3, then F12 twice"
PDFLAB_SCREENSHOT_DIR="$art/shots" start_viewer "$pdflab" --scene "$scene" --strategy cosine
send_key 3
sleep 2
send_key F12
for _ in $(seq 100); do ls "$art"/shots/*.json >/dev/null 2>&1 && [ -s "$(ls "$art"/shots/*.json | head -1)" ] && break; sleep 0.2; done
sleep 0.5
send_key F12
for _ in $(seq 100); do [ "$(ls "$art"/shots/*.png 2>/dev/null | wc -l)" -ge 2 ] && break; sleep 0.2; done
sleep 1
import -window root "$art/window.png"
quit_viewer

ls -l "$art/shots"
[ "$(ls "$art"/shots/*.png | wc -l)" -eq 2 ] || fail "expected two screenshots (names must not collide)"
[ "$(ls "$art"/shots/*.pfm | wc -l)" -eq 2 ] || fail "expected two PFMs"
[ "$(ls "$art"/shots/*.json | wc -l)" -eq 2 ] || fail "expected two sidecars"
shot=$(ls "$art"/shots/*.png | head -1)
json=${shot%.png}.json
ls "$shot" | grep -Eq '/pdflab-[0-9]{8}-[0-9]{6}-[0-9]+\.png$' || fail "unexpected name $shot"
strategy=$(json_field "$json" strategy)
spp=$(json_field "$json" spp)
seed=$(json_field "$json" seed)
echo "screenshot: $shot  strategy=$strategy spp=$spp seed=$seed"
[ "$strategy" = "mix:cosine=0.5,light=0.5" ] || fail "preset 3 not applied: strategy '$strategy'"
[ "$spp" -ge 1 ] || fail "spp $spp"

read -r w h mean sd <<<"$(png_stats "$shot")"
echo "viewer PNG: ${w}x${h} mean=$mean sd=$sd"
[ "$w" = 96 ] && [ "$h" = 96 ] || fail "screenshot is ${w}x${h}, expected 96x96"
awk -v m="$mean" -v s="$sd" 'BEGIN { exit !(m > 0.02 && s > 0.02) }' || fail "screenshot looks blank"

echo "== headless render of the same settings"
"$pdflab" render --scene "$scene" --strategy "$strategy" --spp "$spp" --seed "$seed" --out "$art/headless.png" --quiet
"$pdflab" render --scene "$scene" --strategy "$strategy" --spp "$spp" --seed "$((seed + 1))" --out "$art/headless_other_seed.png" --quiet
read -r _ _ mean_headless _ <<<"$(png_stats "$art/headless.png")"
read -r _ _ mean_other _ <<<"$(png_stats "$art/headless_other_seed.png")"
# Tolerance: several times the difference between two independent renders
# (another seed) of the same settings, with a floor for an unlucky close pair.
spread=$(abs_diff "$mean_headless" "$mean_other")
tol=$(awk -v s="$spread" 'BEGIN { t = 4 * s; if (t < 0.004) t = 0.004; printf "%.6f", t }')
diff=$(abs_diff "$mean" "$mean_headless")
echo "mean: viewer $mean, headless $mean_headless, other seed $mean_other; |diff| $diff, tolerance $tol"
awk -v d="$diff" -v t="$tol" 'BEGIN { exit !(d <= t) }' || fail "viewer and headless means disagree"
echo "PASS"
