#!/usr/bin/env bash
# GUI test of path guiding in the viewer under Xvfb, on the door scene made
# small: the guiding-tree view (--view guiding-tree) draws the S-tree's leaves
# over the image once a guided strategy has trained, and falls back to the
# image, with a legend saying why, for a strategy without `guided`; the pixel
# probe draws the clicked point's quadtree, its cells in more than one colour;
# a cosine/guided mixture gets its predicted efficiency curve once trained.
#   gui_guiding.sh PDFLAB SCENE ARTIFACT_DIR
# Exit 77 only when xvfb-run is missing (see gui_smoke.sh).
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x800x24" "xdotool import identify compare convert" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3
rm -rf "$art"
mkdir -p "$art"

# The scene at 160x120, so that its training passes take a moment on a loaded machine.
/usr/bin/python3 - "$scene" "$art/door.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["camera"]["width"], d["camera"]["height"] = 160, 120
json.dump(d, open(sys.argv[2], "w"))
PY
guided="nee-mis+mix:cosine=0.5,guided:3=0.5"
legend_up() { await_layout "any(w['name'] == '##view legend' for w in d['windows'])"; }

echo "== no guided: the image, and the legend says why"
start_viewer "$pdflab" --scene "$art/door.json" --strategy nee-mis --view guiding-tree
legend_up
sleep 3
crop=$(layout_py "'%dx%d+%d+%d' % (d['image']['w'] - 20, d['image']['h'] - 20, d['image']['x'] + 10, d['image']['y'] + 10)")
send_key space  # paused: the two captures below see the same image
sleep 1
shot plain_tree "$crop"
send_key v      # the last view: the next is the image
sleep 1.5
shot plain_image "$crop"
same "$art/plain_image.png" "$art/plain_tree.png" 0.01
quit_viewer

echo "== guided: the leaves over the image"
start_viewer "$pdflab" --scene "$art/door.json" --strategy "$guided" --view guiding-tree
legend_up
sleep 6  # three training passes of 1, 2 and 4 spp, then the render
send_key space
sleep 1
shot tree "$crop"
send_key v
sleep 1.5
shot image "$crop"
changed "$art/image.png" "$art/tree.png" 0.05
read -r tree_sd image_sd <<<"$(identify -format "%[fx:standard_deviation] " "$art/tree.png" "$art/image.png")"
echo "colour spread: tree $tree_sd, image $image_sd"

echo "== the probe: the quadtree of a floor point's leaf"
read -r left top w h <<<"$(layout_py "'%d %d %d %d' % (d['image']['x'], d['image']['y'], d['image']['w'], d['image']['h'])")"
send_key p
sleep 0.5
xdotool mousemove "$((left + w * 35 / 100))" "$((top + h * 88 / 100))" click 1
xdotool mousemove 2 2
await_layout "'probe.quadtree' in d['items']"
# Down to the probe's lower part, where the tree is.
read -r px py <<<"$(layout_py "[ '%d %d' % (w['x'] + w['w'] // 2, w['y'] + w['h'] // 2) for w in d['windows'] if w['name'].startswith('Pixel probe')][0]")"
xdotool mousemove "$px" "$py"
for _ in $(seq 30); do xdotool click 5; sleep 0.03; done
xdotool mousemove 2 2
sleep 1.5
read -r qx qy qw qh <<<"$(item probe.quadtree)"
echo "quadtree at ${qw}x${qh}+${qx}+${qy}"
[ "$qy" -ge 0 ] && [ $((qy + qh)) -le "$HEIGHT" ] || fail "the quadtree is not on screen after scrolling"
shot quadtree "${qw}x${qh}+${qx}+${qy}"
read -r mean sd <<<"$(identify -format "%[fx:mean] %[fx:standard_deviation]" "$art/quadtree.png")"
echo "quadtree: mean=$mean sd=$sd"
awk -v m="$mean" -v s="$sd" 'BEGIN { exit !(m > 0.03 && s > 0.05) }' || fail "the quadtree looks blank or flat"
shot probe
quit_viewer

echo "== a cosine/guided mixture: the predicted curve once training is over"
start_viewer "$pdflab" --scene "$art/door.json" --strategy "mix:cosine=0.5,guided:3=0.5"
curve=$(crop_of sampling.curve)
shot curve_early "$curve"  # the curve waits for the training passes
sleep 8
await_changed "$art/curve_early.png" curve "$curve" 0.02
quit_viewer
echo "gui_guiding: ok"
