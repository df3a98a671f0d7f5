#!/usr/bin/env bash
# GUI test of the camera under Xvfb: in camera mode (O) a drag orbits the
# camera, which restarts the render (another image, the sidecar's camera
# moved); Home goes back to the scene's camera and, at the same spp and seed,
# the very same image, bit for bit.
#   gui_camera.sh PDFLAB SCENE ARTIFACT_DIR
# Exit 77 only when xvfb-run itself is missing.
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x800x24" "xdotool import cmp" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3
rm -rf "$art"
mkdir -p "$art/shots"
# save N: F12, wait for the Nth sidecar; prints the stem of the new files.
save() {
  send_key F12
  for _ in $(seq 100); do [ "$(ls "$art"/shots/*.json 2>/dev/null | wc -l)" -ge "$1" ] && break; sleep 0.1; done
  sleep 0.3
  local json; json=$(ls -t "$art"/shots/*.json | head -1)
  echo "${json%.json}"
}

# 16 spp and stop: every image below is complete and comparable.
PDFLAB_SCREENSHOT_DIR="$art/shots" start_viewer "$pdflab" --scene "$scene" --strategy cosine --spp 16
read -r cx cy <<<"$(layout_py "'%d %d' % (d['image']['x'] + d['image']['w'] / 2, d['image']['y'] + d['image']['h'] / 2)")"
sleep 2
first=$(save 1)
echo "scene's camera: $(json_field "$first.json" camera)"
[ "$(json_field "$first.json" camera moved)" = False ] || fail "the camera was moved before any drag"

echo "== O, then a drag orbits the camera and restarts the render"
send_key o
sleep 0.3
xdotool mousemove "$cx" "$cy" mousedown 1
for dx in 10 20 30 40; do xdotool mousemove "$((cx + dx))" "$((cy + dx / 4))"; sleep 0.1; done
xdotool mouseup 1
xdotool mousemove 2 2
sleep 3
orbited=$(save 2)
echo "orbited camera: $(json_field "$orbited.json" camera)"
[ "$(json_field "$orbited.json" camera moved)" = True ] || fail "the sidecar does not show the moved camera"
[ "$(json_field "$orbited.json" spp)" = 16 ] || fail "the orbited render did not finish its 16 spp"
if cmp -s "$first.pfm" "$orbited.pfm"; then fail "orbiting did not change the image"; fi

echo "== Home: the scene's camera, the same image bit for bit"
send_key Home
sleep 3
reset=$(save 3)
[ "$(json_field "$reset.json" camera moved)" = False ] || fail "Home did not restore the scene's camera"
cmp "$first.pfm" "$reset.pfm" || fail "after Home the image differs from the first"
echo "first and reset PFMs are identical"
quit_viewer
echo "PASS"
