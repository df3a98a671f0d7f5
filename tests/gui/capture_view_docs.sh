#!/usr/bin/env bash
# Regenerates docs/view_zoom.png (the wheel's zoom with the pixel inspector)
# and docs/view_presentation.png (presentation mode, full screen): the book's
# scene under Xvfb after it has rendered for a while.
#   tests/gui/capture_view_docs.sh [PDFLAB] [SECONDS]
set -euo pipefail
source "$(dirname "$0")/lib.sh"
inside_xvfb "1400x900x24" "xdotool import" "$0" "$@"
shift
root=$(cd "$(dirname "$0")/../.." && pwd)
# From the repository's root, so the panel's path field shows a path within it.
cd "$root"
pdflab=${1:-$root/build/release/app/pdflab}
seconds=${2:-20}
scene=assets/scenes/cornell_book.json

start_viewer "$pdflab" --scene "$scene" --strategy "mix:cosine=0.5,light=0.5"
read -r left top size <<<"$(layout_py "'%d %d %d' % (d['image']['x'], d['image']['y'], d['image']['w'])")"
sleep "$seconds"
# The glass sphere: zoom in about it, the inspector reads the pixel under the cursor.
mx=$((left + size * 58 / 100)) my=$((top + size * 77 / 100))
xdotool mousemove "$mx" "$my"
for _ in $(seq 4); do xdotool click 4; sleep 0.05; done
sleep 1
import -window "$wid" "$root/docs/view_zoom.png"
echo "wrote docs/view_zoom.png"
quit_viewer

start_viewer "$pdflab" --scene "$scene" --strategy "mix:cosine=0.5,light=0.5" --presentation
sleep "$seconds"
import -window root "$root/docs/view_presentation.png"
echo "wrote docs/view_presentation.png"
quit_viewer
