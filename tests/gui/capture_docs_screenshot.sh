#!/usr/bin/env bash
# Regenerates docs/viewer.png: the viewer on the book's scene under Xvfb,
# captured after it has rendered for a while.
#   tests/gui/capture_docs_screenshot.sh [PDFLAB] [SECONDS]
set -euo pipefail
source "$(dirname "$0")/lib.sh"
inside_xvfb "1400x900x24" "xdotool import" "$0" "$@"
shift
root=$(cd "$(dirname "$0")/../.." && pwd)
# From the repository's root, so the panel's path field shows a path within it.
cd "$root"
pdflab=${1:-$root/build/release/app/pdflab}
seconds=${2:-30}
start_viewer "$pdflab" --scene assets/scenes/cornell_book.json --strategy "mix:cosine=0.5,light=0.5"
sleep "$seconds"
mkdir -p "$root/docs"
import -window "$wid" "$root/docs/viewer.png"
quit_viewer
echo "wrote $root/docs/viewer.png"
