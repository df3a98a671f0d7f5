#!/usr/bin/env bash
# Regenerates docs/probe_bsdf_lobe.png: the pixel probe on Veach's scene
# (assets/scenes/veach_mis.json) with Veach's estimator, clicked on a glossy
# plate, where the material's own (bsdf) lobe shows beside the light lobe.
#   tests/gui/capture_probe_docs.sh [PDFLAB] [SECONDS] [X% Y%]
# X% and Y% place the click in the image (default 60 58: the alpha 0.025
# plate, where the third light is reflected).
# PROBE_SCENE, PROBE_STRATEGY, PROBE_OUT (a path under docs/) take another
# scene, strategy and picture (PROBE_WAIT: the seconds to wait for the
# probe after the click, default 2). docs/probe_many_lights.png (docs/many_lights.md) is
#   PROBE_WAIT=20 PROBE_SCENE=assets/scenes/many_lights.json PROBE_STRATEGY=nee-mis+lights:tree \
#   PROBE_OUT=docs/probe_many_lights.png tests/gui/capture_probe_docs.sh "" 8 50 80
# docs/probe_guided.png (docs/guiding.md) is
#   PROBE_WAIT=8 PROBE_SCROLL=6 PROBE_SCENE=assets/scenes/door_ajar.json \
#   PROBE_STRATEGY="nee-mis+mix:cosine=0.5,guided=0.5+sobol+rr:10" PROBE_OUT=docs/probe_guided.png \
#   tests/gui/capture_probe_docs.sh "" 25 35 88
# (probe_guided_partition.png at 50 8 and probe_guided_wall.png at 75 45 with
# PROBE_SCROLL=10, probe_guided_tree.png at 35 88 with PROBE_SCROLL=16)
# and docs/probe_light_choice.png (the README's starved box) is
#   PROBE_WAIT=8 PROBE_SCENE=assets/scenes/starved_light.json PROBE_STRATEGY=nee-mis \
#   PROBE_OUT=docs/probe_light_choice.png tests/gui/capture_probe_docs.sh "" 10 30 88
set -euo pipefail
source "$(dirname "$0")/lib.sh"
inside_xvfb "1600x1000x24" "xdotool import" "$0" "$@"
shift
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
pdflab=${1:-}
[ -n "$pdflab" ] || pdflab=$root/build/release/app/pdflab
seconds=${2:-8}
px=${3:-60} py=${4:-58}

scene=${PROBE_SCENE:-assets/scenes/veach_mis.json}
strategy=${PROBE_STRATEGY:-nee-mis+bsdf}
out=${PROBE_OUT:-docs/probe_bsdf_lobe.png}

start_viewer "$pdflab" --scene "$scene" --strategy "$strategy" --window 1600x1000
read -r left top w h <<<"$(layout_py "'%d %d %d %d' % (d['image']['x'], d['image']['y'], d['image']['w'], d['image']['h'])")"
sleep "$seconds"
send_key p
sleep 0.5
xdotool mousemove "$((left + w * px / 100))" "$((top + h * py / 100))" click 1
xdotool mousemove 2 2
sleep "${PROBE_WAIT:-2}"  # the probe's figures are made before it shows
# PROBE_SCROLL: wheel clicks down over the probe's window, to show its lower part.
if [ "${PROBE_SCROLL:-0}" -gt 0 ]; then
  xdotool mousemove "$((left + w - 200))" 300
  for _ in $(seq "$PROBE_SCROLL"); do xdotool click 5; sleep 0.05; done
  sleep 0.5
  xdotool mousemove 2 2
  sleep 0.3
fi
import -window "$wid" "$root/$out"
echo "wrote $out"
send_key p
quit_viewer
