#!/usr/bin/env bash
# Regenerates docs/viewer.png: the viewer on the book's scene under Xvfb,
# captured after it has rendered for a while.
#   tests/gui/capture_docs_screenshot.sh [PDFLAB] [SECONDS]
set -euo pipefail
source "$(dirname "$0")/lib.sh"
root=$(cd "$(dirname "$0")/../.." && pwd)
pdflab=${1:-$root/build/release/app/pdflab}
seconds=${2:-30}
if [ "${INSIDE_XVFB:-}" != 1 ]; then
  INSIDE_XVFB=1 exec xvfb-run -a -s "-screen 0 1400x900x24" bash "$0" "$pdflab" "$seconds"
fi
"$pdflab" --scene "$root/assets/scenes/cornell_book.json" --strategy "mix:cosine=0.5,light=0.5" &
viewer=$!
wid=$(timeout 30 xdotool search --sync --name '^pdflab' | head -1)
# Park the pointer away from the panel so no tooltip shows.
xdotool mousemove 5 5
sleep "$seconds"
mkdir -p "$root/docs"
import -window "$wid" "$root/docs/viewer.png"
quit_viewer "$wid" "$viewer"
echo "wrote $root/docs/viewer.png"
