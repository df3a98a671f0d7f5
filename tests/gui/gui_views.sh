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
start_viewer "$pdflab" --scene "$scene" --strategy "mix:cosine=0.5,light=0.5" --reference "$art/reference.pfm"
sleep 3
# The image as the viewer's layout report places it, less a margin.
crop=$(layout_py "'%dx%d+%d+%d' % (d['image']['w'] - 40, d['image']['h'] - 40, d['image']['x'] + 20, d['image']['y'] + 20)")
echo "window ${WIDTH}x${HEIGHT}, image crop $crop"

modes=(image heatmap difference drops)
for i in "${!modes[@]}"; do
  [ "$i" -eq 0 ] || send_key v
  sleep 1.5
  import -window "$wid" "$art/window_${modes[$i]}.png"
  convert "$art/window_${modes[$i]}.png" -crop "$crop" +repage "$art/${modes[$i]}.png"
done
# Back to the image: past the two weight views (best weight, technique share;
# gui_weights.sh checks them) and path guiding's tree (gui_guiding.sh).
for _ in 1 2 3 4; do send_key v; sleep 0.2; done

echo "== the heat map's error metric (E) and its range (the panel)"
send_key space   # paused: every change below is the control's doing
sleep 1
# look NAME: the image area and the colour bar's window.
look() {
  sleep 1.5
  shot "window_$1"
  convert "$art/window_$1.png" -crop "$crop" +repage "$art/$1.png"
  legend=$(layout_py "[ '%dx%d+%d+%d' % (w['w'], w['h'], w['x'], w['y']) for w in d['windows'] if w['name'] == '##view legend'][0]")
  convert "$art/window_$1.png" -crop "$legend" +repage "$art/$1_legend.png"
}
send_key v
look heat_fixed    # the relative standard error on the fixed 0.001..10
send_key e
look heat_relsq    # the relative variance, on its automatic range
changed "$art/heat_fixed.png" "$art/heat_relsq.png" 0.02
changed "$art/heat_fixed_legend.png" "$art/heat_relsq_legend.png" 0.01
send_key shift+e
look heat_auto     # the relative standard error again, on an automatic range
changed "$art/heat_fixed.png" "$art/heat_auto.png" 0.02
changed "$art/heat_fixed_legend.png" "$art/heat_auto_legend.png" 0.01
# The Display section opened, and scrolled to its range controls.
reveal section.4
click section.4
reveal display.auto_range
shot panel_end
click display.auto_range   # auto range: off
look heat_set      # set by hand where the automatic range was: nothing jumps
same "$art/heat_auto.png" "$art/heat_set.png" 0.01
changed "$art/heat_auto_legend.png" "$art/heat_set_legend.png" 0.002  # "range: as set in the panel"
reveal display.range_max
read -r mx my mw mh <<<"$(item display.range_max)"
xdotool mousemove "$((mx + mw / 12))" "$((my + mh / 2))" click 1   # the max slider, near its low end
xdotool mousemove 2 2
look heat_low_max  # a lower top: more pixels at the bright end
changed "$art/heat_set.png" "$art/heat_low_max.png" 0.02
changed "$art/heat_set_legend.png" "$art/heat_low_max_legend.png" 0.01
read -r mean_set <<<"$(identify -format "%[fx:mean]" "$art/heat_set.png")"
read -r mean_low <<<"$(identify -format "%[fx:mean]" "$art/heat_low_max.png")"
echo "heat map mean brightness: $mean_set, with the lower top $mean_low"
awk -v a="$mean_set" -v b="$mean_low" 'BEGIN { exit !(b > a) }' || fail "a lower top did not brighten the heat map"
quit_viewer

for m in "${modes[@]}"; do
  sd=$(stddev "$art/$m.png")
  echo "$m: stddev $sd"
  awk -v s="$sd" 'BEGIN { exit !(s > 0.02) }' || fail "$m view looks blank"
done
for a in "${modes[@]}"; do
  for b in "${modes[@]}"; do
    [[ "$a" < "$b" ]] || continue
    d=$(rmse "$art/$a.png" "$art/$b.png")
    echo "$a vs $b: $d"
    awk -v d="$d" 'BEGIN { exit !(d > 0.02) }' || fail "$a and $b views look the same"
  done
done

echo "== a reference of another size: the viewer says so and offers the reference's size"
start_viewer "$pdflab" --scene "$scene" --strategy cosine --reference "$art/small.pfm"
sleep 2
shot window_mismatch
quit_viewer
echo "PASS"
