#!/usr/bin/env bash
# GUI test of the view modes under Xvfb: the viewer on a scene that drops
# samples, with a reference, switched through every view mode with the V key.
# Each mode's image area must be non-blank and differ from every other mode's.
#   gui_views.sh PDFLAB SCENE ARTIFACT_DIR
# Exit 77 only when xvfb-run is missing (see gui_smoke.sh).
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x800x24" "xdotool import identify compare convert" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3
rm -rf "$art"
mkdir -p "$art"
stddev() { identify -format "%[fx:standard_deviation]" "$1"; }
# Normalised RMSE between two images of the same size, 0..1.
difference() { { compare -metric RMSE "$1" "$2" null: 2>&1 || true; } | sed -E 's/.*\((.*)\).*/\1/'; }

echo "== a reference at the scene's size, and one at another size"
"$pdflab" render --scene "$scene" --strategy cosine --spp 64 --out "$art/reference.pfm" --quiet
"$pdflab" render --scene "$scene" --strategy cosine --spp 4 --width 32 --height 32 --out "$art/small.pfm" --quiet

echo "== a bad reference is bad input: status 2, no window"
set +e
"$pdflab" --scene "$scene" --reference "$art/missing.pfm" 2>"$art/bad_reference.txt"
[ $? -eq 2 ] || fail "missing reference: expected status 2"
set -e
cat "$art/bad_reference.txt"

# The strategy drops samples on this scene (its pdf overflows for the tiny target).
"$pdflab" --scene "$scene" --strategy "mix:cosine=0.5,light=0.5" --reference "$art/reference.pfm" &
viewer=$!
trap 'kill $viewer 2>/dev/null || true' EXIT
wid=$(timeout 30 xdotool search --sync --name '^pdflab' | head -1)
[ -n "$wid" ] || fail "no viewer window"
xdotool mousemove 5 5
sleep 3
sleep 1
# The image sits centred in the area left of the 400-pixel panel.
read -r ww wh <<<"$(xdotool getwindowgeometry "$wid" | awk '/Geometry/ { split($2, g, "x"); print g[1], g[2] }')"
area=$((ww - 400))
side=$(( area < wh ? area : wh ))
crop="$((side - 40))x$((side - 40))+$((20 + (area - side) / 2))+$((20 + (wh - side) / 2))"
echo "window ${ww}x${wh}, image crop $crop"

modes=(image heatmap difference drops)
for i in "${!modes[@]}"; do
  [ "$i" -eq 0 ] || send_key v
  sleep 1.5
  import -window "$wid" "$art/window_${modes[$i]}.png"
  convert "$art/window_${modes[$i]}.png" -crop "$crop" +repage "$art/${modes[$i]}.png"
done
send_key v   # back to the image
quit_viewer "$wid" "$viewer"
trap - EXIT

for m in "${modes[@]}"; do
  sd=$(stddev "$art/$m.png")
  echo "$m: stddev $sd"
  awk -v s="$sd" 'BEGIN { exit !(s > 0.02) }' || fail "$m view looks blank"
done
for a in "${modes[@]}"; do
  for b in "${modes[@]}"; do
    [[ "$a" < "$b" ]] || continue
    d=$(difference "$art/$a.png" "$art/$b.png")
    echo "$a vs $b: $d"
    awk -v d="$d" 'BEGIN { exit !(d > 0.02) }' || fail "$a and $b views look the same"
  done
done

echo "== a reference of another size: the viewer says so and offers the reference's size"
"$pdflab" --scene "$scene" --strategy cosine --reference "$art/small.pfm" &
viewer=$!
trap 'kill $viewer 2>/dev/null || true' EXIT
wid=$(timeout 30 xdotool search --sync --name '^pdflab' | head -1)
xdotool mousemove 5 5
sleep 3
import -window "$wid" "$art/window_mismatch.png"
quit_viewer "$wid" "$viewer"
trap - EXIT
echo "PASS"
