#!/usr/bin/env bash
# GUI test of looking closely, under Xvfb: the pixel inspector's value (copied
# with Ctrl+C) equals the pixel of the PFM that F12 saves; the wheel zooms in
# with square (nearest-neighbour) pixels; Z shows the image at 1:1, pixel for
# pixel the PNG that F12 saved; F fits it again.
#   gui_navigation.sh PDFLAB SCENE ARTIFACT_DIR
# Exit 77 only when xvfb-run itself is missing.
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x800x24" "xdotool import identify compare convert xclip" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3
rm -rf "$art"
mkdir -p "$art/shots"
colours() { identify -format "%k" "$1"; }

PDFLAB_SCREENSHOT_DIR="$art/shots" start_viewer "$pdflab" --scene "$scene" --strategy cosine
"$pdflab" render --scene "$scene" --strategy cosine --spp 1 --out "$art/size.png" --quiet >/dev/null
read -r iw ih <<<"$(identify -format '%w %h' "$art/size.png")"
read -r area left top size <<<"$(layout_py "'%d %d %d %d' % (d['image_area']['w'], d['image']['x'], d['image']['y'], d['image']['w'])")"
windowed_width=$WIDTH
echo "window ${WIDTH}x${HEIGHT}, image ${iw}x${ih} fitted at $left,$top size $size"
sleep 1
send_key space   # pause: the image on screen stays what F12 saves
sleep 1

echo "== the inspector's value is the saved PFM's"
# A floor pixel: (30, 88) of the image.
mx=$((left + (30 * size + size / 2) / iw)) my=$((top + (88 * size + size / 2) / ih))
xdotool mousemove "$mx" "$my"
sleep 0.5
send_key ctrl+c
sleep 0.3
xclip -o -selection clipboard >"$art/inspector.txt"
cat "$art/inspector.txt"; echo
read -r px py <<<"$(sed -n 's/^pixel (\([0-9]*\), \([0-9]*\)).*/\1 \2/p' "$art/inspector.txt")"
shown=$(sed -n 's/^RGB  //p' "$art/inspector.txt")
[ -n "$px" ] && [ -n "$shown" ] || fail "the inspector copied nothing readable"
send_key F12
for _ in $(seq 100); do ls "$art"/shots/*.json >/dev/null 2>&1 && break; sleep 0.1; done
sleep 0.5
pfm=$(ls "$art"/shots/*.pfm) png=$(ls "$art"/shots/*.png)
saved=$(/usr/bin/python3 - "$pfm" "$px" "$py" <<'PY'
import array, sys
data = open(sys.argv[1], "rb").read()
kind, dims, scale, pixels = data.split(b"\n", 3)
w, h = map(int, dims.split())
a = array.array("f"); a.frombytes(pixels[: w * h * 12])
if float(scale) > 0: a.byteswap()
x, y = int(sys.argv[2]), int(sys.argv[3])
i = 3 * ((h - 1 - y) * w + x)  # PFM rows run bottom to top
print(" ".join("%g" % v for v in a[i : i + 3]))
PY
)
echo "pixel ($px, $py): inspector '$shown', PFM '$saved'"
[ "$shown" = "$saved" ] || fail "the inspector shows '$shown', the saved PFM has '$saved'"
awk -v s="$saved" 'BEGIN { split(s, c, " "); exit !(c[1] + c[2] + c[3] > 0) }' || fail "pick a lit pixel: $saved"

echo "== the wheel zooms in about the cursor, pixels stay square"
shot fitted "60x60+$((mx - 30))+$((my - 30))"
for _ in $(seq 8); do xdotool click 4; sleep 0.05; done
sleep 0.5
shot zoomed "60x60+$((mx - 30))+$((my - 30))"
fitted=$(colours "$art/fitted.png") zoomed=$(colours "$art/zoomed.png")
echo "colours in 60x60 around the cursor: fitted $fitted, zoomed $zoomed"
# About 19 screen pixels per image pixel now: a 60x60 crop spans at most 5x5
# image pixels (a few more colours where the cursor's crosshair sits).
[ "$zoomed" -le 40 ] || fail "zoomed in, the crop has $zoomed colours: not square pixels"
[ "$fitted" -gt "$zoomed" ] || fail "the wheel did not zoom in"
# The same image point under the cursor: the inspector still reads the same pixel.
send_key ctrl+c
sleep 0.3
xclip -o -selection clipboard | grep -q "^pixel ($px, $py)" || fail "zooming moved the pixel under the cursor"

echo "== Z: one screen pixel per image pixel, the saved PNG exactly"
xdotool mousemove 2 2
send_key z
sleep 0.5
x0=$(((area - iw) / 2)) y0=$(((HEIGHT - ih) / 2))
shot actual "${iw}x${ih}+$x0+$y0"
d=$(rmse "$art/actual.png" "$png")
echo "1:1 crop vs the saved PNG: RMSE $d"
awk -v d="$d" 'BEGIN { exit !(d < 0.004) }' || fail "at 1:1 the screen is not the saved image (RMSE $d)"

echo "== F fits again"
send_key f
sleep 0.5
shot fit_again "60x60+$((mx - 30))+$((my - 30))"
d=$(rmse "$art/fitted.png" "$art/fit_again.png")
echo "fitted vs fitted again: RMSE $d"
awk -v d="$d" 'BEGIN { exit !(d < 0.01) }' || fail "F did not restore the fitted view"
echo "== F11: presentation mode, the whole screen and no panel; Esc leaves it"
shot windowed
send_key F11
sleep 1.5
eval "$(xdotool getwindowgeometry --shell "$wid")"
echo "presentation: ${WIDTH}x${HEIGHT}"
[ "$WIDTH" = 1280 ] && [ "$HEIGHT" = 800 ] || fail "F11 did not fill the screen (${WIDTH}x${HEIGHT})"
shot presentation
# No panel: the right edge shows the image area's dark background, not the panel's controls.
convert "$art/presentation.png" -crop 220x500+1055+150 +repage "$art/presentation_right.png"
sd=$(identify -format "%[fx:standard_deviation]" "$art/presentation_right.png")
echo "right edge in presentation: stddev $sd"
awk -v s="$sd" 'BEGIN { exit !(s < 0.02) }' || fail "the side panel still shows in presentation mode"
send_key Escape
sleep 1.5
alive "$viewer" "Esc in presentation mode"
eval "$(xdotool getwindowgeometry --shell "$wid")"
[ "$WIDTH" = "$windowed_width" ] || fail "Esc did not leave presentation mode (${WIDTH}x${HEIGHT})"
quit_viewer
echo "PASS"
