#!/usr/bin/env bash
# GUI test of the viewer's layout under Xvfb, from its own layout report
# (--layout-json): at 1280x720 with --ui-scale 1.5 and 2 and at 1920x1080 the
# side panel keeps to its share of the window, and the boxes over the image
# (badges, the view's legend, the convergence plot, the pixel inspector, the
# split's A and B boxes and its controls) overlap neither each other nor the
# image's middle; the 1D and 2D labs fit the window. The panel's controls stay where
# they are while the w slider is dragged and the curve recomputes (their
# rectangles, and screenshots of the section below); the panel resizes by its
# edge, hides by its button and by Tab, and the window size, panel width and
# open sections come back in the next run.
#   gui_layout.sh PDFLAB SCENE ARTIFACT_DIR [DOCS_DIR]
# With DOCS_DIR the projector layout (1280x720, --ui-scale 2, the split) is
# saved there as view_projector.png.
# Exit 77 only when xvfb-run itself is missing.
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1920x1080x24" "xdotool import identify compare convert" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3 docs=${4:-}
rm -rf "$art"
mkdir -p "$art"

# drag_splitter DX: drags the panel's edge DX pixels to the left. The pointer
# rests on the edge before the button goes down, and between steps, so that a
# slow frame on a loaded machine still sees the press on the edge.
drag_splitter() {
  local x y dx
  read -r x y <<<"$(centre panel.splitter)"
  xdotool mousemove "$x" "$y"
  sleep 0.4
  xdotool mousedown 1
  sleep 0.4
  for dx in $(seq 10 10 "$1"); do xdotool mousemove "$((x - dx))" "$y"; sleep 0.08; done
  sleep 0.4
  xdotool mouseup 1
}
# image_centre: "x y" of the image's middle, from the report.
image_centre() { layout_py "'%d %d' % (d['image']['x'] + d['image']['w'] / 2, d['image']['y'] + d['image']['h'] / 2)"; }

for config in "1280x720 1.5" "1280x720 2" "1920x1080 1"; do
  read -r size ui_scale <<<"$config"
  name="${size}_${ui_scale}"
  echo "== $size at --ui-scale $ui_scale"
  start_viewer "$pdflab" --scene "$scene" --strategy "mix:cosine=0.5,light=0.5" --window "$size" --ui-scale "$ui_scale"
  w=${size%x*} h=${size#*x}
  await_layout "d['window']['width'] == $w and d['window']['height'] == $h"
  # The panel: at most 45% of the window, and wholly inside it.
  layout_py "'panel %dx%d at %d' % (d['items']['panel']['w'], d['items']['panel']['h'], d['items']['panel']['x'])"
  [ "$(layout_py "d['items']['panel']['w'] <= 0.45 * $w + 1 and d['items']['panel']['x'] + d['items']['panel']['w'] <= $w + 1")" = True ] ||
    fail "the panel takes more than its share of the window"
  sleep 2
  no_overlaps
  shot "${name}_image"

  echo "-- the convergence plot and the pixel inspector over the image"
  # Where the plot has no room beside the image's middle, it says so, and
  # hiding the panel (Tab) makes the room.
  hidden=no
  send_key g
  sleep 1
  if [ "$(layout_py "'Convergence (G)' in d['left_out']")" = True ]; then
    echo "no room for the plot beside the panel: $(layout_py "[m for m in d['messages']][:1]") / Tab"
    await_layout "any(w['name'] == '##hint' for w in d['windows'])"
    send_key Tab
    hidden=yes
  fi
  read -r cx cy <<<"$(image_centre)"
  xdotool mousemove "$((cx + 3))" "$((cy + 3))"   # the inspector reads the pixel under the cursor
  await_layout "any(w['name'] == '##inspector' for w in d['windows']) and any(w['name'] == 'Convergence (G)' for w in d['windows'])"
  sleep 1
  no_overlaps
  shot "${name}_plot"
  echo "-- the heat map with its legend, and the plot"
  send_key v
  await_layout "any(w['name'] == '##view legend' for w in d['windows']) and any(w['name'] == 'Convergence (G)' for w in d['windows'])"
  sleep 1
  no_overlaps
  shot "${name}_heatmap"
  xdotool mousemove 2 2
  send_key g
  [ "$hidden" = no ] || send_key Tab
  for _ in 1 2 3 4 5; do send_key v; done   # back to the image

  echo "-- the split screen: A, B and its controls"
  send_key s
  await_layout "d['split'] and all(any(w['name'] == n for w in d['windows']) for n in ('##split_a', '##split_b', '##split_controls'))"
  sleep 2
  no_overlaps
  [ "$(layout_py "d['left_out']")" = "[]" ] || fail "left out of the split for want of room: $(layout_py "d['left_out']")"
  shot "${name}_split"
  if [ -n "$docs" ] && [ "$config" = "1280x720 2" ]; then
    sleep 8
    import -window "$wid" "$docs/view_projector.png"
    echo "wrote $docs/view_projector.png"
  fi
  send_key s

  echo "-- the 1D lab fits the window"
  send_key l
  await_layout "any(w['name'].startswith('1D lab') for w in d['windows'])"
  sleep 1
  layout_py "[ '%dx%d+%d+%d' % (x['w'], x['h'], x['x'], x['y']) for x in d['windows'] if x['name'].startswith('1D lab')][0]"
  [ "$(layout_py "all(x['x'] >= 0 and x['y'] >= 0 and x['x'] + x['w'] <= $w and x['y'] + x['h'] <= $h for x in d['windows'] if x['name'].startswith('1D lab'))")" = True ] ||
    fail "the 1D lab does not fit the window"
  shot "${name}_lab"
  send_key l

  echo "-- the 2D lab fits the window"
  send_key d
  await_layout "any(w['name'].startswith('2D lab') for w in d['windows'])"
  sleep 0.3
  [ "$(layout_py "all(x['x'] >= 0 and x['y'] >= 0 and x['x'] + x['w'] <= $w and x['y'] + x['h'] <= $h for x in d['windows'] if x['name'].startswith('2D lab'))")" = True ] ||
    fail "the 2D lab does not fit the window"
  shot "${name}_lab2d"
  send_key d
  quit_viewer
done

echo "== the panel holds still while w is dragged and the curve recomputes"
start_viewer "$pdflab" --scene "$scene" --strategy "mix:cosine=0.5,light=0.5" --window 1920x1080
await_layout "'sampling.curve' in d['items'] and 'scene.camera' in d['items']"
sleep 4   # a first curve
controls="preset.1 preset.5 sampling.strategy sampling.w sampling.curve sampling.use_best sampling.auto_weight scene.combo scene.depth scene.stop_seconds scene.camera section.3"
rects() { for c in $controls; do echo "$c $(item "$c")"; done; }
rects >"$art/rects_before.txt"
# Below the curve: the Scene and render section, whose labels do not change.
read -r _ sy _ _ <<<"$(item scene.combo)"
read -r px _ pw _ <<<"$(item panel)"
read -r _ ey _ eh <<<"$(item scene.camera)"
scene_rows="$((pw - 30))x$((ey + eh - sy))+$((px + 10))+$sy"
shot scene_before "$scene_rows"
curve=$(crop_of sampling.curve)
read -r wx wy ww wh <<<"$(item sampling.w)"
xdotool mousemove "$((wx + ww / 2))" "$((wy + wh / 2))"
sleep 0.4
xdotool mousedown 1
sleep 0.4
for dx in 10 25 40 60 80 60 40; do
  xdotool mousemove "$((wx + ww / 2 + dx))" "$((wy + wh / 2))"
  sleep 0.3
done
sleep 0.3
rects >"$art/rects_during.txt"
shot scene_during "$scene_rows"
shot curve_during "$curve"
xdotool mouseup 1
xdotool mousemove 2 2
sleep 0.5
rects >"$art/rects_after.txt"
shot scene_after "$scene_rows"
diff "$art/rects_before.txt" "$art/rects_during.txt" || fail "controls moved while w was dragged"
diff "$art/rects_before.txt" "$art/rects_after.txt" || fail "controls moved after w was dragged"
same "$art/scene_before.png" "$art/scene_during.png" 0.01
same "$art/scene_before.png" "$art/scene_after.png" 0.01
# The curve's box is not empty while it recomputes: the last curve, greyed.
sd=$(stddev "$art/curve_during.png")
echo "curve box while dragging: stddev $sd"
awk -v s="$sd" 'BEGIN { exit !(s > 0.05) }' || fail "the curve's box went blank while w was dragged"

echo "== the panel resizes by its edge, hides by its button and by Tab"
width0=$(layout_py "int(d['items']['panel']['w'])")
drag_splitter 140
xdotool mousemove 2 2
await_layout "d['items']['panel']['w'] >= $width0 + 120"
width1=$(layout_py "int(d['items']['panel']['w'])")
echo "panel width: $width0, dragged to $width1"
click panel.hide
await_layout "d['panel_hidden'] and 'panel' not in d['items'] and d['image_area']['w'] == d['window']['width']"
shot hidden
send_key Tab
await_layout "not d['panel_hidden'] and 'panel' in d['items']"
send_key Tab
await_layout "d['panel_hidden']"
click panel.show
await_layout "not d['panel_hidden'] and int(d['items']['panel']['w']) == $width1"
# Two sections changed, to be remembered: Scene and render closed, Display opened.
click section.1
await_layout "'scene.combo' not in d['items']"
reveal section.4
click section.4
await_layout "'display.view' in d['items']"
quit_viewer

echo "== the next run comes back as it was left"
viewer_config=$art/remembered
start_viewer "$pdflab" --scene "$scene" --window 1500x900
await_layout "'section.1' in d['items']"
drag_splitter 100
xdotool mousemove 2 2
await_layout "d['items']['panel']['w'] >= 480"
remembered_width=$(layout_py "int(d['items']['panel']['w'])")
click section.1
await_layout "'scene.combo' not in d['items']"
quit_viewer
start_viewer "$pdflab" --scene "$scene"
await_layout "d['window']['width'] == 1500 and d['window']['height'] == 900" ||
  fail "the window's size was not remembered"
await_layout "abs(d['items']['panel']['w'] - $remembered_width) <= 1"
await_layout "'scene.combo' not in d['items'] and 'sampling.strategy' in d['items']"
echo "window 1500x900, panel $remembered_width wide and Scene and render closed, as left"
quit_viewer
viewer_config=
echo "PASS"
