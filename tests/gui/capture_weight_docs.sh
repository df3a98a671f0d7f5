#!/usr/bin/env bash
# Regenerates docs/view_weight_curve.png (the predicted efficiency curve beside
# the w slider), docs/view_best_weight.png (the best-weight view) and
# docs/view_technique_share.png (which technique found the light): the book's
# scene at half size under Xvfb after it has rendered for a while.
#   tests/gui/capture_weight_docs.sh [PDFLAB] [SECONDS]
set -euo pipefail
source "$(dirname "$0")/lib.sh"
inside_xvfb "1400x900x24" "xdotool import convert" "$0" "$@"
shift
root=$(cd "$(dirname "$0")/../.." && pwd)
# From the repository's root, so the panel's path field shows a path within it.
cd "$root"
pdflab=${1:-$root/build/release/app/pdflab}
seconds=${2:-20}
scene=assets/scenes/cornell_book.json

start_viewer "$pdflab" --scene "$scene" --strategy "mix:cosine=0.5,light=0.5"
sleep "$seconds"
# The Sampling section: the w slider, the curve, the button, auto weight.
import -window "$wid" "$root/docs/view_weight_curve.png"
curve=$(layout_py "'%dx%d+%d+0' % (d['items']['panel']['w'], d['items']['sampling.auto_weight']['y'] + d['items']['sampling.auto_weight']['h'] + 6, d['items']['panel']['x'])")
convert "$root/docs/view_weight_curve.png" -crop "$curve" +repage "$root/docs/view_weight_curve.png"
echo "wrote docs/view_weight_curve.png"
for _ in 1 2 3 4; do send_key v; sleep 0.3; done
sleep 2
import -window "$wid" "$root/docs/view_best_weight.png"
echo "wrote docs/view_best_weight.png"
send_key v
sleep 2
import -window "$wid" "$root/docs/view_technique_share.png"
echo "wrote docs/view_technique_share.png"
quit_viewer
