#!/usr/bin/env bash
# GUI test of the teaching views under Xvfb, driven with xdotool: split screen
# (S, then dragging the divider), pixel probe (P, a click, C for chi-square)
# the 1D lab (L, then a bad and a good f(x) typed) and the 2D lab (D: a
# coarser resolution from its table, rows picked on the map, log bars). Each view is
# captured; each capture must be non-blank and differ from the one before it.
#   gui_teaching.sh PDFLAB SCENE ARTIFACT_DIR [DOCS_DIR]
# With DOCS_DIR the views are rendered longer and saved there as
# view_split.png, view_probe.png, view_lab1d.png (with a typed f(x)) and
# lab2d.png (the sky at 64 x 32, the sun's row, log bars).
# Exit 77 only when xvfb-run itself is missing.
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1400x900x24" "xdotool import identify compare convert" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3 docs=${4:-}
rm -rf "$art"
mkdir -p "$art"
settle=2 lab2d_settle=0.5
[ -n "$docs" ] && settle=12 lab2d_settle=12

# not_blank FILE: some brightness and some structure.
not_blank() {
  read -r mean sd <<<"$(identify -format "%[fx:mean] %[fx:standard_deviation]" "$1")"
  echo "$(basename "$1"): mean=$mean sd=$sd"
  awk -v m="$mean" -v s="$sd" 'BEGIN { exit !(m > 0.02 && s > 0.02) }' || fail "$1 looks blank"
}

start_viewer "$pdflab" --scene "$scene" --strategy "mix:cosine=0.5,light=0.5"
sleep 2
shot base
not_blank "$art/base.png"

# Where the (square) image is, from the viewer's layout report.
read -r left top size <<<"$(layout_py "'%d %d %d' % (d['image']['x'], d['image']['y'], d['image']['w'])")"
cx=$((left + size / 2)) cy=$((top + size / 2))

echo "== split screen"
send_key s
sleep "$settle"
shot split
not_blank "$art/split.png"
changed "$art/base.png" "$art/split.png"
# Drag the divider from the middle towards the left.
xdotool mousemove "$cx" "$cy" mousedown 1
for dx in 20 40 60 80 100; do xdotool mousemove "$((cx - dx))" "$cy"; sleep 0.1; done
xdotool mouseup 1
xdotool mousemove 2 2
sleep 1
shot split_dragged
changed "$art/split.png" "$art/split_dragged.png"
[ -n "$docs" ] && cp "$art/split_dragged.png" "$docs/view_split.png"
send_key s
sleep 1

echo "== pixel probe"
send_key p
sleep 0.5
# A pixel of the floor, left of the image's centre, low down.
xdotool mousemove "$((left + size * 30 / 100))" "$((top + size * 88 / 100))" click 1
xdotool mousemove 2 2
sleep 1
shot probe
not_blank "$art/probe.png"
changed "$art/split_dragged.png" "$art/probe.png"
send_key c
sleep 0.3
# The check runs in the background (a fraction of a second here) while the
# window keeps drawing.
sleep 3
shot probe_chi
changed "$art/probe.png" "$art/probe_chi.png"
[ -n "$docs" ] && cp "$art/probe_chi.png" "$docs/view_probe.png"
send_key p
sleep 0.5

echo "== 1D lab"
send_key l
sleep "$settle"
shot lab
not_blank "$art/lab.png"
changed "$art/probe_chi.png" "$art/lab.png"
sleep 1
shot lab_later
# The running estimate keeps drawing samples: the plots move.
changed "$art/lab.png" "$art/lab_later.png"

echo "== 1D lab: f(x) typed as an expression"
# Ctrl held across frames, then A: the field's text selected, to be typed over.
select_all() {
  xdotool keydown --window "$wid" ctrl
  sleep 0.15
  send_key a
  sleep 0.15
  xdotool keyup --window "$wid" ctrl
  sleep 0.15
}
# red_line FILE: the fraction of red pixels in the band under the lab's first
# row, where a refused expression is named (one or two rows down: the row's
# controls wrap in a narrow window).
red_line() { convert "$1" -crop 680x40+14+60 +repage -fx "r > 0.8 && g < 0.55 ? 1 : 0" -format "%[fx:mean]" info:; }
# The f(x) field, right of the drop-down in the lab's first row.
xdotool mousemove 250 48 click 1
sleep 0.2
select_all
xdotool type --window "$wid" "sin(pi*"
send_key Return
xdotool mousemove 2 2
sleep 1
alive "$viewer" "a bad expression"
shot lab_bad
changed "$art/lab_later.png" "$art/lab_bad.png"
awk -v r="$(red_line "$art/lab_bad.png")" 'BEGIN { exit !(r > 0.004) }' || fail "no message for a bad expression"
xdotool mousemove 250 48 click 1
sleep 0.2
select_all
xdotool type --window "$wid" "sin(pi*x)^2"
send_key Return
xdotool mousemove 2 2
sleep "$settle"
shot lab_typed
not_blank "$art/lab_typed.png"
changed "$art/lab_bad.png" "$art/lab_typed.png"
awk -v r="$(red_line "$art/lab_typed.png")" 'BEGIN { exit !(r < 0.001) }' || fail "sin(pi*x)^2 was refused"
[ -n "$docs" ] && cp "$art/lab_typed.png" "$docs/view_lab1d.png"

echo "== 2D lab"
send_key l
send_key d
await_layout "'lab2d' in d and d['lab2d']['width'] == 256 and d['lab2d']['samples'] > 0"
sleep 0.3
shot lab2d
not_blank "$art/lab2d.png"
changed "$art/lab_typed.png" "$art/lab2d.png"
# The sun's texel is drawn at about its share of the light: the 2D histogram
# agrees with the pdf, and no sample falls where the pdf is zero.
awk -v p="$(layout_py "d['lab2d']['chi_square_p']")" 'BEGIN { exit !(p > 1e-6) }' || fail "the 2D lab's chi-square rejects its sampler"
[ "$(layout_py "d['lab2d']['zero_cell_hits']")" = 0 ] || fail "2D lab: samples where the pdf is zero"
# A coarser resolution from the table, then a row picked three eighths of the way down the map.
click lab2d.level.64
await_layout "d['lab2d']['width'] == 64 and d['lab2d']['height'] == 32"
read -r mx my mw mh <<<"$(item lab2d.map)"
# click_at X Y: the pointer rests there a moment before the click (a loaded machine's frame sees it arrive).
click_at() {
  xdotool mousemove "$1" "$2"
  sleep 0.15
  xdotool click 1
  sleep 0.15
  xdotool mousemove 2 2
}
click_at "$((mx + mw / 2))" "$((my + mh * 3 / 8 + 2))"
await_layout "d['lab2d']['row'] == 12"
# Back up to the sun's row (9 of 32): its conditional CDF jumps at the sun's column.
click_at "$((mx + mw / 2))" "$((my + mh * 19 / 64))"
await_layout "d['lab2d']['row'] == 9"
# The plots' probabilities on a log scale: the sky's rows and columns show beside the sun's.
click lab2d.log_bars
await_layout "d['lab2d']['log_bars']"
sleep "$lab2d_settle"
shot lab2d_sun
changed "$art/lab2d.png" "$art/lab2d_sun.png"
[ -n "$docs" ] && cp "$art/lab2d_sun.png" "$docs/lab2d.png"

quit_viewer
echo "PASS"
