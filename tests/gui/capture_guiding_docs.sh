#!/usr/bin/env bash
# Regenerates docs/guiding_viewer.png: the viewer on the door scene with path
# guiding (nee-mis continued by cosine and `guided`), its statistics section
# open on the training's figures, under Xvfb.
#   tests/gui/capture_guiding_docs.sh [PDFLAB] [SECONDS]
set -euo pipefail
source "$(dirname "$0")/lib.sh"
inside_xvfb "1400x900x24" "xdotool import" "$0" "$@"
shift
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
pdflab=${1:-$root/build/release/app/pdflab}
seconds=${2:-20}
start_viewer "$pdflab" --scene assets/scenes/door_ajar.json --strategy "nee-mis+mix:cosine=0.5,guided=0.5+sobol+rr:10"
# The statistics section (the third header) opened.
click section.2
sleep "$seconds"
mkdir -p "$root/docs"
import -window "$wid" "$root/docs/guiding_viewer.png"
quit_viewer
echo "wrote $root/docs/guiding_viewer.png"
