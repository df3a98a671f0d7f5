#!/usr/bin/env bash
# Regenerates docs/probe_bsdf_lobe.png: the pixel probe on Veach's scene
# (assets/scenes/veach_mis.json) with Veach's estimator, clicked on a glossy
# plate, where the material's own (bsdf) lobe shows beside the light lobe.
#   tests/gui/capture_probe_docs.sh [PDFLAB] [SECONDS] [X% Y%]
# X% and Y% place the click in the image (default 60 58: the alpha 0.025
# plate, where the third light is reflected).
set -euo pipefail
source "$(dirname "$0")/lib.sh"
inside_xvfb "1600x1000x24" "xdotool import" "$0" "$@"
shift
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
pdflab=${1:-$root/build/release/app/pdflab}
seconds=${2:-8}
px=${3:-60} py=${4:-58}

start_viewer "$pdflab" --scene assets/scenes/veach_mis.json --strategy "nee-mis+bsdf" --window 1600x1000
read -r left top w h <<<"$(layout_py "'%d %d %d %d' % (d['image']['x'], d['image']['y'], d['image']['w'], d['image']['h'])")"
sleep "$seconds"
send_key p
sleep 0.5
xdotool mousemove "$((left + w * px / 100))" "$((top + h * py / 100))" click 1
xdotool mousemove 2 2
sleep 2
import -window "$wid" "$root/docs/probe_bsdf_lobe.png"
echo "wrote docs/probe_bsdf_lobe.png"
send_key p
quit_viewer
