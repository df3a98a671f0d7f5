#!/usr/bin/env bash
# GUI test of Esc and quitting under Xvfb, driven with xdotool: Esc with a
# drop-down open and with a text field being edited leaves the viewer running
# (and closes the one, cancels the other); keys typed into a text field are
# text, never shortcuts; the pixel probe follows a strategy switch (key 2)
# without a new click; Ctrl+Q after a render of more than a few seconds asks
# first, and each of the question's buttons works by the mouse (Cancel, Quit
# anyway, Save screenshot then quit); a film saved with Ctrl+S counts as saved.
#   gui_quit.sh PDFLAB SCENE ARTIFACT_DIR
# Exit 77 only when xvfb-run itself is missing.
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x800x24" "xdotool import identify compare convert" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3
rm -rf "$art"
mkdir -p "$art/shots"
export PDFLAB_SCREENSHOT_DIR="$art/shots"

start_viewer "$pdflab" --scene "$scene" --strategy cosine
sleep 0.5
panel_top=$(layout_py "'%dx%d+%d+0' % (d['items']['panel']['w'], d['items']['scene.path']['y'] + 40, d['items']['panel']['x'])")
shot panel "$panel_top"

echo "== Esc with a drop-down open"
click sampling.strategy
await_changed "$art/panel.png" dropdown "$panel_top" 0.03
send_key Escape
await_changed "$art/dropdown.png" dropdown_closed "$panel_top" 0.03
alive "$viewer" "Esc with a drop-down open"

echo "== Esc while editing a text field"
field=$(crop_of scene.path)
shot field_before "$field"
reveal scene.path
click scene.path
sleep 0.2
send_key End
xdotool type --window "$wid" "xyz"
await_changed "$art/field_before.png" field_typing "$field" 0.005
send_key Escape
# Cancelled: the field shows the path it had (the caret gone).
await_same "$art/field_before.png" field_after "$field" 0.02
alive "$viewer" "Esc in a text field"

echo "== keys typed into a text field are text, not shortcuts"
# Typed into the scene path field: "nee-mis" has -, s and m in it (zoom out,
# split screen, make a reference), then 4 (a preset), v (a view), space (pause).
reveal scene.path
click scene.path
sleep 0.2
xdotool type --window "$wid" " nee-mis 4v "
sleep 0.5
send_key Escape
sleep 0.5
await_layout "d['split'] == False"
[ "$(layout_py "d['view']")" = image ] || fail "a v typed into a field changed the view"
[ "$(layout_py "d['items'].get('measure.reference_progress') is None")" = True ] || fail "an m typed into a field made a reference"
send_key F12
for _ in $(seq 100); do ls "$art"/shots/*.json >/dev/null 2>&1 && break; sleep 0.1; done
sleep 0.3
json=$(ls "$art"/shots/*.json | head -1)
[ "$(json_field "$json" strategy)" = cosine ] || fail "a 4 typed into a field changed the strategy: $(json_field "$json" strategy)"
rm -f "$art"/shots/*
alive "$viewer" "typing into a field"

echo "== the pixel probe follows a strategy switch"
read -r ix iy iw ih <<<"$(layout_py "' '.join(str(int(d['image'][k])) for k in ('x', 'y', 'w', 'h'))")"
send_key p
sleep 0.3
xdotool mousemove "$((ix + iw * 30 / 100))" "$((iy + ih * 88 / 100))" click 1
xdotool mousemove 2 2
sleep 1
# The probe window's legend (counts per technique, light samples per target).
legend=$(layout_py "[ '%dx%d+%d+%d' % (w['w'] - 20, 150, w['x'] + 10, w['y'] + 50) for w in d['windows'] if w['name'].startswith('Pixel probe')][0]")
shot probe_cosine "$legend"
send_key 2   # preset: light only
await_changed "$art/probe_cosine.png" probe_light "$legend" 0.02
shot probe_window
send_key Escape  # leaves probe mode, closes the probe
await_changed "$art/probe_window.png" probe_left "" 0.02
alive "$viewer" "Esc in probe mode"

echo "== Ctrl+Q after a long unsaved render asks first; its buttons work by the mouse"
sleep 6
send_key ctrl+q
await_layout "d['quit_asking'] and 'quit.cancel' in d['items']"
alive "$viewer" "Ctrl+Q after an unsaved render (it must ask first)"
shot asking
click quit.cancel
await_layout "not d['quit_asking']"
alive "$viewer" "Cancel clicked in the quit question"
send_key ctrl+q
await_layout "d['quit_asking'] and 'quit.cancel' in d['items']"
send_key Escape   # Esc cancels too
await_layout "not d['quit_asking']"
send_key ctrl+q
await_layout "d['quit_asking'] and 'quit.quit' in d['items']"
click quit.quit
for _ in $(seq 50); do kill -0 "$viewer" 2>/dev/null || break; sleep 0.1; done
kill -0 "$viewer" 2>/dev/null && fail "clicking Quit anyway did not quit"
pid=$viewer viewer=
wait "$pid" || fail "viewer exited with status $?"

echo "== Save screenshot, then quit, by the mouse"
start_viewer "$pdflab" --scene "$scene" --strategy cosine
sleep 6.5
send_key ctrl+q
await_layout "d['quit_asking'] and 'quit.save' in d['items']"
click quit.save
for _ in $(seq 100); do kill -0 "$viewer" 2>/dev/null || break; sleep 0.1; done
kill -0 "$viewer" 2>/dev/null && fail "clicking Save screenshot, then quit did not quit"
pid=$viewer viewer=
wait "$pid" || fail "viewer exited with status $?"
ls "$art"/shots/*.png >/dev/null 2>&1 || fail "Save screenshot, then quit saved no screenshot"
echo "saved before quitting: $(ls "$art"/shots/)"

echo "== a film saved with Ctrl+S counts as saved"
start_viewer "$pdflab" --scene "$scene" --strategy cosine
sleep 6.5
send_key ctrl+s
for _ in $(seq 50); do ls "$art"/shots/*.film >/dev/null 2>&1 && break; sleep 0.1; done
ls "$art"/shots/*.film >/dev/null 2>&1 || fail "Ctrl+S saved no film"
send_key space   # paused: nothing new to lose after the save
sleep 0.5
send_key ctrl+q
for _ in $(seq 50); do kill -0 "$viewer" 2>/dev/null || break; sleep 0.1; done
kill -0 "$viewer" 2>/dev/null && fail "Ctrl+Q after Ctrl+S asked as if nothing was saved"
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
