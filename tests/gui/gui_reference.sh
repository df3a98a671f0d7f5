#!/usr/bin/env bash
# GUI test of references under Xvfb: a reference made in a few seconds (short
# of its target, 5% of the figures' error) is labelled rough, never measured,
# and stays out of the cache; with an empty cache the Measure panel shows
# estimates; M (the Make reference action) renders one to a stated spp in the
# background with a progress bar (Cancel stops one and throws it away), stores
# it in the cache, and the panel switches to measured figures, which the
# screenshot's sidecar records with the reference; an orbit of the camera turns them to estimates with the
# reason, Home measures again; `render --reference auto` and a second viewer
# find it in the cache; a biased strategy without a reference shows no
# efficiency.
#   gui_reference.sh PDFLAB SCENE ARTIFACT_DIR [DOCS_DIR]
# With DOCS_DIR the Measure section estimated, making a reference, measured
# and with a rough reference is saved there as make_reference.png.
# Exit 77 only when xvfb-run itself is missing.
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x900x24" "xdotool import identify compare convert" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3 docs=${4:-}
rm -rf "$art"
mkdir -p "$art"
export PDFLAB_REFERENCE_CACHE="$art/cache"
shot() {
  import -window "$wid" "$art/window_$1.png"
  convert "$art/window_$1.png" -crop "$(crop_of panel)" +repage "$art/panel_$1.png"
  # The Measure section, from its header to its plot line, for the docs.
  local measure
  measure=$(layout_py "'%dx%d+%d+%d' % (d['items']['panel']['w'], min(d['items']['measure.plot']['y'] + d['items']['measure.plot']['h'], d['window']['height']) - d['items']['section.3']['y'], d['items']['panel']['x'], d['items']['section.3']['y'])" 2>/dev/null || true)
  [ -z "$measure" ] || convert "$art/window_$1.png" -crop "$measure" +repage "$art/measure_$1.png"
}
cached() { find "$PDFLAB_REFERENCE_CACHE" -name '*.json' 2>/dev/null | wc -l; }
# select_all: Ctrl held across frames, then A: the field's text selected, to be typed over.
select_all() {
  xdotool keydown --window "$wid" ctrl
  sleep 0.15
  send_key a
  sleep 0.15
  xdotool keyup --window "$wid" ctrl
  sleep 0.15
}

# open_viewer ARG...: the viewer on the scene, its messages in viewer_stderr.txt.
open_viewer() { start_viewer "$pdflab" --scene "$scene" "$@" 2>"$art/viewer_stderr.txt"; }

# figures: the source of the figures shown (measured, rough, estimated, none).
figures() { layout_py "d['figures']['source']"; }
# save_shot: F12, then the newest sidecar's path.
save_shot() {
  local before; before=$(ls "$art"/shots/*.json 2>/dev/null | wc -l)
  send_key F12
  for _ in $(seq 100); do [ "$(ls "$art"/shots/*.json 2>/dev/null | wc -l)" -gt "$before" ] && break; sleep 0.1; done
  sleep 0.3
  ls -t "$art"/shots/*.json | head -1
}
mkdir -p "$art/shots"
export PDFLAB_SCREENSHOT_DIR="$art/shots"

echo "== a reference made in a few seconds is labelled rough and stays out of the cache"
# Its target, 5% of the figures' error, takes far longer than the 1 s it is given.
open_viewer --strategy cosine --reference-seconds 1
sleep 4
[ "$(figures)" = estimated ] || fail "figures before any reference: $(figures)"
reveal measure.make_reference
click measure.make_reference
await_layout "d['figures']['source'] == 'rough'"
reveal measure.plot
shot rough
grep -q "short of its target" "$art/viewer_stderr.txt" || fail "the viewer did not say the reference fell short"
[ "$(cached)" -eq 0 ] || fail "a reference short of its target went into the cache"
json=$(save_shot)
echo "sidecar figures: $(json_field "$json" figures)"
[ "$(json_field "$json" figures source)" = rough ] || fail "the sidecar does not call the figures rough"
awk -v s="$(json_field "$json" figures reference_share)" 'BEGIN { exit !(s > 0.25) }' || fail "a rough reference's share is not above 25%"
[ "$(json_field "$json" reference matches)" = True ] || fail "the sidecar does not record the reference it measured against"
quit_viewer

echo "== no reference: estimates"
# The render stops at 64 spp, so a 1024-spp reference is a fine one for it
# (its noise a few percent of the error; against a render run on, it would turn rough).
open_viewer --strategy cosine --spp 64 --reference-seconds 120
sleep 3
reveal measure.plot
shot estimated
[ "$(cached)" -eq 0 ] || fail "the cache is not empty before Make reference"

echo "== Make reference to a stated spp (M): a progress bar, Cancel; then a cached reference and measured figures"
reveal measure.make_target
click measure.make_target
click measure.target.spp
# set_make_spp N: the stated spp typed into its field.
set_make_spp() {
  click measure.make_spp
  select_all
  xdotool type --window "$wid" "$1"
  send_key Return
  sleep 0.3
}
# A fast machine makes the 1024-spp reference of this 96x96 scene in a fraction
# of a second, before any capture could see its progress: the progress bar is
# shot on a reference of 2^20 spp, which no machine finishes while it is
# watched, and which Cancel then stops and throws away.
set_make_spp 1048576
send_key m
await_layout "'measure.reference_progress' in d['items']"
sleep 0.5
shot making
changed "$art/panel_estimated.png" "$art/panel_making.png" 0.005
click measure.cancel_reference
await_layout "'measure.make_reference' in d['items']"
[ "$(cached)" -eq 0 ] || fail "a cancelled reference went into the cache"
[ "$(figures)" = estimated ] || fail "figures after a cancelled reference: $(figures)"
echo "cancelled: no reference cached, the figures still estimates"
set_make_spp 1024
send_key m
for _ in $(seq 120); do [ "$(cached)" -ge 1 ] && break; sleep 0.5; done
[ "$(cached)" -eq 1 ] || fail "no reference in the cache after Make reference"
await_layout "d['figures']['source'] == 'measured'"
shot measured
changed "$art/panel_making.png" "$art/panel_measured.png" 0.005
alive "$viewer" "Make reference"
grep -q "note: made a reference, stored as $PDFLAB_REFERENCE_CACHE/" "$art/viewer_stderr.txt" ||
  fail "the viewer did not report the reference it made"
json=$(save_shot)
[ "$(json_field "$json" reference spp)" = 1024 ] || fail "the reference was not made to its 1024 spp: $(json_field "$json" reference)"
[ "$(json_field "$json" figures source)" = measured ] || fail "the sidecar's figures are not measured"
for f in relmse relmse_interval efficiency reference_share; do
  json_field "$json" figures "$f" >/dev/null || fail "the sidecar has no figures.$f"
done

echo "== an orbit after the reference: the figures turn to estimates, and say why"
read -r cx cy <<<"$(layout_py "'%d %d' % (d['image']['x'] + d['image']['w'] / 2, d['image']['y'] + d['image']['h'] / 2)")"
send_key o
sleep 0.3
xdotool mousemove "$cx" "$cy" mousedown 1
for dx in 10 20 30 40; do xdotool mousemove "$((cx + dx))" "$((cy + dx / 4))"; sleep 0.1; done
xdotool mouseup 1
xdotool mousemove 2 2
send_key o
await_layout "d['figures']['source'] == 'estimated' and 'camera moved' in d['figures']['why_estimated']"
shot orbited
json=$(save_shot)
echo "after the orbit: $(json_field "$json" figures source), $(json_field "$json" reference why_not)"
[ "$(json_field "$json" figures source)" = estimated ] || fail "after an orbit the sidecar's figures are not estimates"
[ "$(json_field "$json" reference matches)" = False ] || fail "after an orbit the reference still counts as matching"
send_key Home
await_layout "d['figures']['source'] == 'measured'"
echo "Home: measured against the reference again"
quit_viewer
ls -l "$PDFLAB_REFERENCE_CACHE"
[ "$(find "$PDFLAB_REFERENCE_CACHE" -name '*.pfm' | wc -l)" -eq 2 ] || fail "expected a mean and a variance PFM"

if [ -n "$docs" ]; then
  convert "$art/measure_estimated.png" "$art/measure_making.png" "$art/measure_measured.png" "$art/measure_rough.png" \
    -background "#1c1c20" -splice 8x0 +append "$docs/make_reference.png"
  echo "wrote $docs/make_reference.png"
fi

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
PDFLAB_REFERENCE_CACHE="$art/empty_cache" open_viewer --strategy cosine --reference "$art/old.pfm"
sleep 3
shot seed_trap
json=$(save_shot)   # the sidecar records the seed the render now uses
quit_viewer
grep -h '"seed"' "$json"
grep -q '"seed": 2' "$json" || fail "the viewer kept the reference's seed"
echo "== a damaged cached reference: named and ignored, the viewer keeps running"
for f in "$PDFLAB_REFERENCE_CACHE"/*.pfm; do head -c 100 "$f" >"$f.cut" && mv "$f.cut" "$f"; done
open_viewer --strategy cosine
sleep 3
shot damaged
alive "$viewer" "a damaged cached reference"
grep -q "damaged and was ignored" "$art/viewer_stderr.txt" || fail "a damaged cached reference was not named"
quit_viewer
echo "PASS"
