#!/usr/bin/env bash
# GUI test of references under Xvfb: with an empty cache the Measure panel shows
# estimates; M (the Make reference action) renders one in the background with a
# progress bar, stores it in the cache, and the panel switches to measured
# figures; `render --reference auto` and a second viewer find it in the cache; a
# biased strategy without a reference shows no efficiency.
#   gui_reference.sh PDFLAB SCENE ARTIFACT_DIR
# Exit 77 only when xvfb-run itself is missing.
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x900x24" "xdotool import identify compare convert" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3
rm -rf "$art"
mkdir -p "$art"
export PDFLAB_REFERENCE_CACHE="$art/cache"
shot() {
  import -window "$wid" "$art/window_$1.png"
  convert "$art/window_$1.png" -crop "400x${HEIGHT}+$((WIDTH - 400))+0" +repage "$art/panel_$1.png"
}
cached() { find "$PDFLAB_REFERENCE_CACHE" -name '*.json' 2>/dev/null | wc -l; }

# open_viewer ARG...: the viewer on the scene, its messages in viewer_stderr.txt.
open_viewer() { start_viewer "$pdflab" --scene "$scene" "$@" 2>"$art/viewer_stderr.txt"; }

echo "== no reference: estimates"
open_viewer --strategy cosine --reference-seconds 4
sleep 3
shot estimated
[ "$(cached)" -eq 0 ] || fail "the cache is not empty before Make reference"

echo "== Make reference (M): a progress bar, then a cached reference and measured figures"
send_key m
sleep 1.5
shot making
changed "$art/panel_estimated.png" "$art/panel_making.png" 0.005
for _ in $(seq 60); do [ "$(cached)" -ge 1 ] && break; sleep 0.5; done
[ "$(cached)" -eq 1 ] || fail "no reference in the cache after Make reference"
sleep 2
shot measured
changed "$art/panel_making.png" "$art/panel_measured.png" 0.005
alive "$viewer" "Make reference"
grep -q "note: made a reference, stored as $PDFLAB_REFERENCE_CACHE/" "$art/viewer_stderr.txt" ||
  fail "the viewer did not report the reference it made"
quit_viewer
ls -l "$PDFLAB_REFERENCE_CACHE"
[ "$(find "$PDFLAB_REFERENCE_CACHE" -name '*.pfm' | wc -l)" -eq 2 ] || fail "expected a mean and a variance PFM"

echo "== the command line finds the viewer's reference"
"$pdflab" render --scene "$scene" --strategy cosine --spp 16 --out "$art/cosine.pfm" --reference auto --quiet \
  >"$art/render_auto.txt"
cat "$art/render_auto.txt"
grep -q "relMSE .* against $PDFLAB_REFERENCE_CACHE" "$art/render_auto.txt" || fail "render --reference auto missed it"

echo "== a second viewer loads it by itself"
open_viewer --strategy cosine
sleep 3
shot autoloaded
grep -q "note: loaded the cached reference $PDFLAB_REFERENCE_CACHE/" "$art/viewer_stderr.txt" ||
  fail "the second viewer did not load the cached reference"
quit_viewer

echo "== a biased strategy without a reference: no efficiency"
PDFLAB_REFERENCE_CACHE="$art/empty_cache" open_viewer --strategy light
sleep 3
shot biased
quit_viewer
echo "== the seed trap: a screenshot (seed 1, cosine) loaded as the reference of a cosine render at seed 1"
"$pdflab" --scene "$scene" --strategy cosine --spp 16 --screenshot "$art/old.png" >/dev/null
grep -q '"seed": 1' "$art/old.json" || fail "the screenshot's sidecar does not record seed 1"
PDFLAB_SCREENSHOT_DIR="$art/shots" PDFLAB_REFERENCE_CACHE="$art/empty_cache" \
  open_viewer --strategy cosine --reference "$art/old.pfm"
sleep 3
shot seed_trap
send_key F12   # the sidecar records the seed the render now uses
for _ in $(seq 40); do ls "$art"/shots/*.json >/dev/null 2>&1 && break; sleep 0.25; done
quit_viewer
grep -h '"seed"' "$art"/shots/*.json
grep -q '"seed": 2' "$art"/shots/*.json || fail "the viewer kept the reference's seed"
echo "== a damaged cached reference: named and ignored, the viewer keeps running"
for f in "$PDFLAB_REFERENCE_CACHE"/*.pfm; do head -c 100 "$f" >"$f.cut" && mv "$f.cut" "$f"; done
open_viewer --strategy cosine
sleep 3
shot damaged
alive "$viewer" "a damaged cached reference"
grep -q "damaged and was ignored" "$art/viewer_stderr.txt" || fail "a damaged cached reference was not named"
quit_viewer
echo "PASS"
