#!/usr/bin/env bash
# GUI test of what a student hands in, under Xvfb, by the mouse: each export
# writes its files (the heat map, difference, best-weight and technique-share
# views as PNG figures with their legend; the predicted curve and the
# convergence plot as SVG and CSV); "Stop at seconds" stops the render at its
# time; presentation mode shows its caption; a film resumed in the viewer
# keeps its rendering time.
#   gui_export.sh PDFLAB SCENE ARTIFACT_DIR [DOCS_DIR]
# With DOCS_DIR the figures are made longer and copied there (figure_*.png,
# figure_*.svg, view_caption.png).
# Exit 77 only when xvfb-run itself is missing.
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1400x900x24" "xdotool import identify compare convert" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3 docs=${4:-}
rm -rf "$art"
mkdir -p "$art/shots"
export PDFLAB_SCREENSHOT_DIR="$art/shots"
settle=3
[ -n "$docs" ] && settle=20

# newest KIND EXT: the newest exported file of a kind (waits for it).
newest() {
  for _ in $(seq 100); do ls "$art"/shots/*-"$1"."$2" >/dev/null 2>&1 && break; sleep 0.1; done
  ls -t "$art"/shots/*-"$1"."$2" 2>/dev/null | head -1
}
# png_size FILE: "width height".
png_size() { identify -format '%w %h' "$1"; }
image_size() { layout_py "'%d %d' % (d['image']['w'], d['image']['h'])"; }

echo "== a reference to show the difference against"
"$pdflab" render --scene "$scene" --strategy "mix:cosine=0.5,light=0.5" --spp 256 --seed 9 --out "$art/reference.pfm" --quiet

start_viewer "$pdflab" --scene "$scene" --strategy "mix:cosine=0.5,light=0.5" --reference "$art/reference.pfm" --window 1400x900
read -r rw rh <<<"$("$pdflab" render --scene "$scene" --strategy cosine --spp 1 --out "$art/size.png" --quiet >/dev/null; identify -format '%w %h' "$art/size.png")"
sleep "$settle"
reveal section.5
click section.5

for view in heatmap difference best-weight technique-share; do
  echo "== the $view view as a PNG figure"
  case $view in
    heatmap) label="relative standard error" ;;
    difference) label="difference to reference" ;;
    best-weight) label="best weight (predicted)" ;;
    technique-share) label="which technique found the light" ;;
  esac
  for _ in $(seq 6); do [ "$(layout_py "d['view']")" = "$label" ] && break; send_key v; sleep 0.4; done
  [ "$(layout_py "d['view']")" = "$label" ] || fail "V never reached the $view view"
  # Enabled once the view has its layer (the weight views wait for the prediction).
  sleep 1.5
  reveal export.view
  click export.view
  png=$(newest "$view" png)
  [ -n "$png" ] && [ -s "$png" ] || fail "no $view figure was written"
  read -r w h <<<"$(png_size "$png")"
  echo "$(basename "$png"): ${w}x${h} (the image ${rw}x${rh})"
  [ "$w" -ge 480 ] && [ "$h" -gt "$((w * rh / rw + 60))" ] || fail "the $view figure is not the view enlarged with a legend beneath"
  sd=$(stddev "$png")
  awk -v s="$sd" 'BEGIN { exit !(s > 0.05) }' || fail "the $view figure looks blank"
  [ -z "$docs" ] || cp "$png" "$docs/figure_${view//-/_}.png"
done
for _ in $(seq 6); do [ "$(layout_py "d['view']")" = image ] && break; send_key v; sleep 0.3; done

echo "== the predicted curve as SVG and CSV"
reveal sampling.export_curve
click sampling.export_curve
svg=$(newest curve svg) csv=$(newest curve csv)
[ -s "$svg" ] && [ -s "$csv" ] || fail "the curve's SVG and CSV were not written"
head -1 "$csv"
[ "$(head -1 "$csv")" = "w,relative_efficiency,largest_path_share" ] || fail "the curve's CSV has another header"
[ "$(($(wc -l <"$csv") - 1))" -ge 10 ] || fail "the curve's CSV has too few rows"
grep -q "<svg" "$svg" && grep -q "predicted best w" "$svg" || fail "the curve's SVG is not a plot with its best weight"
[ -z "$docs" ] || { cp "$svg" "$docs/figure_weight_curve.svg"; cp "$csv" "$docs/figure_weight_curve.csv"; }

echo "== the convergence plot as SVG and CSV"
send_key k   # a pinned curve beside the running one
send_key 4   # nee-mis
sleep "$settle"
send_key g
await_layout "'plot.export' in d['items']"
click plot.export
svg=$(newest convergence svg) csv=$(newest convergence csv)
[ -s "$svg" ] && [ -s "$csv" ] || fail "the convergence plot's SVG and CSV were not written"
head -3 "$csv"
grep -q '^pin 1,"mix:cosine=0.5,light=0.5",no,' "$csv" || fail "the pinned curve is not in the CSV with its size"
grep -q '^now,"nee-mis",no,' "$csv" || fail "the running curve is not in the CSV"
grep -q "<svg" "$svg" || fail "the convergence SVG is not an SVG"
[ -z "$docs" ] || { cp "$svg" "$docs/figure_convergence.svg"; cp "$csv" "$docs/figure_convergence.csv"; }
send_key g

echo "== Stop at seconds: the render stops at its time"
send_key 3
reveal scene.stop_seconds
read -r sx sy sw sh <<<"$(item scene.stop_seconds)"
# The field left of its -/+ buttons.
xdotool mousemove "$((sx + sw / 4))" "$((sy + sh / 2))" click 1
sleep 0.2
xdotool keydown --window "$wid" ctrl; sleep 0.15; send_key a; sleep 0.15; xdotool keyup --window "$wid" ctrl
xdotool type --window "$wid" "3"
send_key Return
xdotool mousemove 2 2
send_key r   # from the start: 3 s of this render
await_layout "d['done']"
sleep 1
send_key F12
for _ in $(seq 100); do ls "$art"/shots/pdflab-*[0-9].json >/dev/null 2>&1 && break; sleep 0.1; done
sleep 0.3
json=$(ls -t "$art"/shots/pdflab-*[0-9].json | head -1)
seconds=$(json_field "$json" seconds)
echo "stopped after $seconds s of rendering"
awk -v s="$seconds" 'BEGIN { exit !(s >= 3.0 && s < 6.0) }' || fail "Stop at 3 seconds stopped at $seconds s"
spp=$(layout_py "d['figures']['spp']")
sleep 1.5
[ "$(layout_py "d['figures']['spp']")" = "$spp" ] || fail "the render went on after its time"

echo "== presentation mode's caption"
reveal section.4
click section.4
reveal display.caption
click display.caption
send_key F11
await_layout "d['presentation'] and any(w['name'] == '##caption' for w in d['windows'])"
sleep 1.5
import -window root "$art/caption.png"
[ -z "$docs" ] || cp "$art/caption.png" "$docs/view_caption.png"
send_key F11
quit_viewer

echo "== a film resumed in the viewer keeps its rendering time"
"$pdflab" render --scene "$scene" --strategy cosine --spp 1024 --seed 4 --film-out "$art/long.film" \
  --stats-json "$art/long.json" --quiet
film_seconds=$(json_field "$art/long.json" seconds)
"$pdflab" --resume "$art/long.film" --spp 1100 --screenshot "$art/resumed.png" >/dev/null
resumed_seconds=$(json_field "$art/resumed.json" seconds)
echo "film: $film_seconds s for 1024 spp; resumed to 1100 spp: $resumed_seconds s"
awk -v f="$film_seconds" -v r="$resumed_seconds" 'BEGIN { exit !(r > f) }' ||
  fail "the resumed film's time restarted ($resumed_seconds s after a film of $film_seconds s)"
echo "PASS"
