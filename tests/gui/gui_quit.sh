#!/usr/bin/env bash
# GUI test of Esc and quitting under Xvfb, driven with xdotool: Esc with a
# drop-down open and with a text field being edited leaves the viewer running
# (and closes the one, cancels the other); Ctrl+Q after a render of more than
# a few seconds asks first (Esc cancels, Ctrl+Q again quits); the pixel probe
# follows a strategy switch (key 2) without a new click.
#   gui_quit.sh PDFLAB SCENE ARTIFACT_DIR
# Exit 77 only when xvfb-run itself is missing.
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x800x24" "xdotool import identify compare convert" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3
rm -rf "$art"
mkdir -p "$art"

start_viewer "$pdflab" --scene "$scene" --strategy cosine
sleep 0.5
px=$((WIDTH - 400))  # the side panel's left edge
# The panel's top rows: the strategy drop-down, then (below what it covers
# when open) the scene path field.
panel_top="390x300+$px+0"
shot panel "$panel_top"

echo "== Esc with a drop-down open"
xdotool mousemove "$((px + 120))" 43 click 1
await_changed "$art/panel.png" dropdown "$panel_top" 0.03
send_key Escape
xdotool mousemove 2 2
await_changed "$art/dropdown.png" dropdown_closed "$panel_top" 0.03
alive "$viewer" "Esc with a drop-down open"

echo "== Esc while editing a text field"
field="300x22+$((px + 8))+201"
shot field_before "$field"
xdotool mousemove "$((px + 200))" 212 click 1
sleep 0.2
send_key End
xdotool type --window "$wid" "xyz"
await_changed "$art/field_before.png" field_typing "$field" 0.005
send_key Escape
xdotool mousemove 2 2
# Cancelled: the field shows the path it had (the caret gone).
await_same "$art/field_before.png" field_after "$field" 0.02
alive "$viewer" "Esc in a text field"

echo "== the pixel probe follows a strategy switch"
# The image is centred left of the panel.
size=$((px < HEIGHT ? px : HEIGHT))
left=$(((px - size) / 2)) top=$(((HEIGHT - size) / 2))
send_key p
sleep 0.3
xdotool mousemove "$((left + size * 30 / 100))" "$((top + size * 88 / 100))" click 1
xdotool mousemove 2 2
sleep 1
# The probe window's legend (counts per technique, light samples per target).
legend="230x150+$((WIDTH - 250))+60"
shot probe_cosine "$legend"
send_key 2   # preset: light only
await_changed "$art/probe_cosine.png" probe_light "$legend" 0.02
shot probe_window
send_key Escape  # leaves probe mode, closes the probe
await_changed "$art/probe_window.png" probe_left "" 0.02
alive "$viewer" "Esc in probe mode"

echo "== Ctrl+Q after a long unsaved render asks first"
sleep 6
send_key ctrl+q
sleep 1
alive "$viewer" "Ctrl+Q after an unsaved render (it must ask first)"
shot asking
send_key Escape   # cancel
await_changed "$art/asking.png" cancelled "" 0.02
alive "$viewer" "Esc in the quit question"
send_key ctrl+q
sleep 1
alive "$viewer" "Ctrl+Q (asking again)"
send_key ctrl+q   # quit anyway
for _ in $(seq 50); do kill -0 "$viewer" 2>/dev/null || break; sleep 0.1; done
kill -0 "$viewer" 2>/dev/null && fail "Ctrl+Q twice did not quit"
pid=$viewer viewer=
wait "$pid" || fail "viewer exited with status $?"

echo "== a short render quits at once"
start_viewer "$pdflab" --scene "$scene" --strategy cosine
send_key ctrl+q
for _ in $(seq 50); do kill -0 "$viewer" 2>/dev/null || break; sleep 0.1; done
kill -0 "$viewer" 2>/dev/null && fail "Ctrl+Q after one second asked instead of quitting"
pid=$viewer viewer=
wait "$pid" || fail "viewer exited with status $?"
echo "PASS"
