#!/usr/bin/env bash
# GUI test of the mixture-weight parts of the viewer under Xvfb: a bad --view
# is bad input; --auto-weight moves a far-off w towards the predicted best
# between passes and the film goes on (the saved sidecar's strategy is another
# weight, at the spp asked for); the best-weight and technique-share views are
# non-blank and differ from the image and from each other; the panel shows the
# predicted curve (its area changes from the first look to a later one).
#   gui_weights.sh PDFLAB SCENE ARTIFACT_DIR
# Exit 77 only when xvfb-run is missing (see gui_smoke.sh).
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x800x24" "xdotool import identify compare convert" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3
rm -rf "$art"
mkdir -p "$art"

echo "== a bad --view is bad input: status 2, no window"
set +e
"$pdflab" --scene "$scene" --view sideways 2>"$art/bad_view.txt"
status=$?
set -e
cat "$art/bad_view.txt"
[ "$status" -eq 2 ] || fail "--view sideways: expected status 2, got $status"
grep -q "not a view mode" "$art/bad_view.txt" || fail "the message does not name the problem"

echo "== auto weight from w = 0.1: the weight moves, the film reaches its spp"
"$pdflab" --scene "$scene" --strategy "mix:cosine=0.1,light=0.9" --auto-weight --spp 256 \
  --screenshot "$art/auto.png" 2>"$art/auto.txt" || { cat "$art/auto.txt"; fail "auto-weight screenshot run failed"; }
strategy=$(json_field "$art/auto.json" strategy)
spp=$(json_field "$art/auto.json" spp)
echo "sidecar: $strategy at $spp spp"
[ "$spp" = "256" ] || fail "expected 256 spp, got $spp"
cosine=$(echo "$strategy" | sed -n 's/.*cosine=\([0-9.e-]*\).*/\1/p')
light=$(echo "$strategy" | sed -n 's/.*light=\([0-9.e-]*\).*/\1/p')
awk -v c="$cosine" -v l="$light" 'BEGIN { w = c / (c + l); print "final w", w; exit !(w > 0.2 && w <= 0.95) }' ||
  fail "auto weight did not move w from 0.1 towards the best (about 0.5 here): $strategy"

echo "== the weight views"
start_viewer "$pdflab" --scene "$scene" --strategy "mix:cosine=0.5,light=0.5"
# The first look as soon as the window is up: the curve's prediction starts
# with the first pass, so a later first look may already show a settled curve.
import -window "$wid" "$art/panel_early.png"
sleep 7
crop=$(layout_py "'%dx%d+%d+%d' % (d['image']['w'] - 40, d['image']['h'] - 40, d['image']['x'] + 20, d['image']['y'] + 20)")
# The prediction's box under the w slider (the viewer's layout report says where).
panel=$(crop_of sampling.curve)
import -window "$wid" "$art/panel.png"
convert "$art/panel_early.png" -crop "$panel" +repage "$art/curve_early.png"
convert "$art/panel.png" -crop "$panel" +repage "$art/curve.png"
convert "$art/panel.png" -crop "$crop" +repage "$art/image.png"
changed "$art/curve_early.png" "$art/curve.png" 0.02
for i in 1 2 3 4; do send_key v; sleep 0.3; done
sleep 1.5
import -window "$wid" "$art/window_best.png"
convert "$art/window_best.png" -crop "$crop" +repage "$art/best.png"
send_key v
sleep 1.5
import -window "$wid" "$art/window_share.png"
convert "$art/window_share.png" -crop "$crop" +repage "$art/share.png"
quit_viewer

for m in best share; do
  sd=$(stddev "$art/$m.png")
  echo "$m: stddev $sd"
  awk -v s="$sd" 'BEGIN { exit !(s > 0.02) }' || fail "$m view looks blank"
done
changed "$art/image.png" "$art/best.png" 0.05
changed "$art/image.png" "$art/share.png" 0.05
changed "$art/best.png" "$art/share.png" 0.05
echo "PASS"
