#!/usr/bin/env bash
# Regenerates docs/viewer.png: the viewer on the book's scene under Xvfb,
# captured after it has rendered for a while.
#   tests/gui/capture_docs_screenshot.sh [PDFLAB] [SECONDS]
# SHOT_SCENE, SHOT_STRATEGY and SHOT_OUT (a path under docs/) take another
# scene, strategy and picture; SHOT_OPEN names a control to click first (a
# panel section, as the layout names it). docs/guiding_viewer.png
# (docs/guiding.md: the door scene with path guiding, the statistics section
# open on the training's figures) is
#   SHOT_SCENE=assets/scenes/door_ajar.json SHOT_STRATEGY="nee-mis+mix:cosine=0.5,guided=0.5+sobol+rr:10" \
#   SHOT_OPEN=section.2 SHOT_OUT=docs/guiding_viewer.png tests/gui/capture_docs_screenshot.sh "" 15
# SHOT_VIEW starts in a view mode; docs/guiding_tree.png (the S-tree over the
# image) is the same with SHOT_VIEW=guiding-tree, no SHOT_OPEN, and 25 seconds.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
inside_xvfb "1400x900x24" "xdotool import" "$0" "$@"
shift
root=$(cd "$(dirname "$0")/../.." && pwd)
# From the repository's root, so the panel's path field shows a path within it.
cd "$root"
pdflab=${1:-}
[ -n "$pdflab" ] || pdflab=$root/build/release/app/pdflab
seconds=${2:-30}
out=${SHOT_OUT:-docs/viewer.png}
start_viewer "$pdflab" --scene "${SHOT_SCENE:-assets/scenes/cornell_book.json}" \
  --strategy "${SHOT_STRATEGY:-mix:cosine=0.5,light=0.5}" ${SHOT_VIEW:+--view "$SHOT_VIEW"}
[ -z "${SHOT_OPEN:-}" ] || click "$SHOT_OPEN"
sleep "$seconds"
mkdir -p "$(dirname "$root/$out")"
import -window "$wid" "$root/$out"
quit_viewer
echo "wrote $root/$out"
