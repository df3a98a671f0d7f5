#!/usr/bin/env bash
# Regenerates the measuring figures in docs/: the noise heat map, the
# difference to a reference, its relative squared error with the panel's
# metric and range controls, the drop overlay, the convergence plot with a
# pinned curve, and the nee-mis note. The book's scene at 400x400 under Xvfb.
#   tests/gui/capture_measure_docs.sh [PDFLAB] [SECONDS_PER_STRATEGY]
set -euo pipefail
source "$(dirname "$0")/lib.sh"
inside_xvfb "1400x900x24" "xdotool import" "$0" "$@"
shift
root=$(cd "$(dirname "$0")/../.." && pwd)
pdflab=${1:-$root/build/release/app/pdflab}
seconds=${2:-20}

# The scene within the repository (its build folder), from the root, so the
# panel's path field shows a path within it.
cd "$root"
mkdir -p build/docs-scenes
at_exit='rm -rf build/docs-scenes'
scene=build/docs-scenes/cornell_400.json
sed -e 's/"width": 600, "height": 600/"width": 400, "height": 400/' assets/scenes/cornell_book.json >"$scene"
grep -q '"width": 400' "$scene" || { echo "could not resize the scene"; exit 1; }
echo "reference: nee-mis, 256 spp"
"$pdflab" render --scene "$scene" --strategy nee-mis --spp 256 --seed 7 --out build/docs-scenes/ref.pfm --quiet

start() { start_viewer "$pdflab" --scene "$scene" --strategy "$1" --reference build/docs-scenes/ref.pfm; }
stop() { quit_viewer; }
shot() { import -window "$wid" "$root/docs/$1"; echo "wrote docs/$1"; }

mkdir -p "$root/docs"
# Convergence: cosine, pinned, then the book's mixture, pinned, then nee-mis (key 4) against both.
start cosine
sleep "$seconds"
send_key k
send_key 3
sleep "$seconds"
send_key k
send_key v
sleep 2
shot view_heatmap.png
send_key v
sleep 2
shot view_difference.png
# The relative squared error (E four times from the signed error), with the
# panel scrolled down to the view's metric and range.
for _ in 1 2 3 4; do send_key e; done
reveal section.4
click section.4
reveal display.range_max
sleep 2
shot view_metric.png
send_key v
send_key v   # back to the image
send_key g   # the plot on (it starts hidden)
send_key 4
sleep "$seconds"
sleep 1
shot convergence_plot.png
stop

# The nee-mis note is in the panel; the plot and views stay out of the way.
start_viewer "$pdflab" --scene "$scene" --strategy nee-mis:balance
click sampling.nee_why
sleep 4
shot nee_mis_note.png
stop

# The drop overlay: the tiny-target test scene, whose light pdf overflows.
start_viewer "$pdflab" --scene tests/gui/tiny_target.json --strategy "mix:cosine=0.5,light=0.5"
sleep 2
send_key v
send_key v
send_key v
sleep 2
shot view_drops.png
stop
