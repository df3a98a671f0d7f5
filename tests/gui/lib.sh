# Sourced by the GUI tests. inside_xvfb re-runs the calling script inside a
# fresh Xvfb server, unless it already runs there; exit 77 (ctest's
# SKIP_RETURN_CODE) only when xvfb-run itself is missing: any other missing
# tool is a failure, so a broken setup cannot pass as "skipped".
#   inside_xvfb SCREEN "TOOL..." "$0" "$@"; shift   # the shift drops --inside
inside_xvfb() {
  local screen=$1 tools=$2 script=$3
  shift 3
  [ "${1:-}" = "--inside" ] && return 0
  if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "SKIP: xvfb-run is not installed (Debian: apt-get install xvfb xauth)"
    exit 77
  fi
  local tool
  for tool in $tools; do
    command -v "$tool" >/dev/null 2>&1 || { echo "FAIL: $tool is missing (xdotool, imagemagick)"; exit 1; }
  done
  exec xvfb-run -a -s "-screen 0 $screen" bash "$script" --inside "$@"
}

# fail WHY: ends the test, also from inside $(...) (a subshell would only end itself).
fail() {
  echo "FAIL: $*" >&2
  [ "$BASHPID" = "$$" ] || kill -TERM $$
  exit 1
}

# The viewer loads the cached reference of its scene by itself: the tests never
# see the user's cache (a test that wants one sets its own folder).
export PDFLAB_REFERENCE_CACHE="${PDFLAB_REFERENCE_CACHE:-$(mktemp -u -t pdflab-no-cache-XXXXXX)}"

# alive PID WHAT: the viewer is still running after WHAT.
alive() { kill -0 "$1" 2>/dev/null || fail "the viewer quit after $2"; }

# find_window: waits for the viewer's window and sets wid.
find_window() {
  wid=$(timeout 30 xdotool search --sync --name '^pdflab' | head -1)
  [ -n "$wid" ] || fail "no viewer window"
}
# focus_window: find_window, then gives it the keyboard and sets WIDTH and HEIGHT.
focus_window() {
  find_window
  sleep 1
  xdotool windowfocus --sync "$wid"
  eval "$(xdotool getwindowgeometry --shell "$wid")"
}

# start_viewer PDFLAB ARG...: the viewer in the background ($viewer, killed if
# the script ends before quit_viewer), its window focused (wid, WIDTH, HEIGHT)
# and the pointer parked in the corner, away from the panel's tooltips. It
# writes its layout to $layout (--layout-json) and keeps its remembered
# settings in $viewer_config (a fresh folder per start unless the test sets
# one). Environment assignments before it reach the viewer.
viewer_config=
layout=
gui_tmp=      # the reports and settings folders of this script's viewers, removed at exit
viewer_starts=0
start_viewer() {
  # The last viewer's window must be gone, or the search could find it.
  for _ in $(seq 50); do xdotool search --name '^pdflab' >/dev/null 2>&1 || break; sleep 0.1; done
  [ -n "$gui_tmp" ] || gui_tmp=$(mktemp -d -t pdflab-gui-XXXXXX)
  viewer_starts=$((viewer_starts + 1))
  layout=$gui_tmp/layout-$viewer_starts.json
  local config=${viewer_config:-$gui_tmp/config-$viewer_starts}
  mkdir -p "$config"
  PDFLAB_CONFIG_DIR="$config" "$@" --layout-json "$layout" &
  viewer=$!
  focus_window
  xdotool mousemove 2 2
  await_layout 'True'
}
viewer=
at_exit=  # more to do when the script ends (e.g. remove a temporary folder)
trap '[ -z "$viewer" ] || kill "$viewer" 2>/dev/null || true; eval "$at_exit"; [ -z "$gui_tmp" ] || rm -rf "$gui_tmp"' EXIT

# quit_viewer: Ctrl+Q, and Ctrl+Q again ("quit anyway") when it asks first (a
# render of more than a few seconds, unsaved); waits for the exit status,
# which must be 0.
quit_viewer() {
  send_key ctrl+q
  for _ in $(seq 10); do kill -0 "$viewer" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "$viewer" 2>/dev/null; then send_key ctrl+q; fi
  local pid=$viewer
  viewer=
  wait "$pid" || fail "viewer exited with status $?"
}

# Sends keys to the viewer window. XSendEvent (xdotool key --window) is
# refused with BadWindow by some windows once they have gone full screen or
# opened a popup under Xvfb; then the keys go through XTEST to the focused window.
send_key() {
  xdotool key --window "$wid" "$@" 2>/dev/null && return 0
  xdotool windowfocus --sync "$wid" 2>/dev/null || true
  xdotool key "$@"
}

# shot NAME [GEOMETRY]: the window, or a crop of it, as $art/NAME.png.
shot() {
  import -window "$wid" "$art/$1.png"
  [ -z "${2:-}" ] || convert "$art/$1.png" -crop "$2" +repage "$art/$1.png"
}
# stddev IMAGE: its standard deviation, 0..1 (0: one flat colour).
stddev() { identify -format "%[fx:standard_deviation]" "$1"; }
# rmse A B: the root-mean-square difference of two images, 0..1.
rmse() { (compare -metric RMSE "$1" "$2" null: 2>&1 || true) | sed -n 's/.*(\(.*\)).*/\1/p'; }
# changed A B [FLOOR] / same A B [CEILING]: two captures differ by more than
# FLOOR / by at most CEILING (RMSE, default 0.01).
changed() {
  local d; d=$(rmse "$1" "$2"); echo "$(basename "$1") -> $(basename "$2"): RMSE $d"
  awk -v d="$d" -v f="${3:-0.01}" 'BEGIN { exit !(d > f) }' || fail "$2 did not change from $1"
}
same() {
  local d; d=$(rmse "$1" "$2"); echo "$(basename "$1") vs $(basename "$2"): RMSE $d"
  awk -v d="$d" -v f="${3:-0.01}" 'BEGIN { exit !(d <= f) }' || fail "$2 differs from $1"
}
# await_changed REF NAME GEOMETRY [FLOOR] / await_same REF NAME GEOMETRY
# [CEILING]: shoots NAME (GEOMETRY "" for the whole window) until it differs
# from / matches the capture REF, for up to 10 s, then checks it as changed /
# same do. A loaded machine redraws late; these wait only as long as it takes.
await_changed() { await_ changed "$@"; }
await_same() { await_ same "$@"; }
await_() {
  local check=$1 ref=$2 name=$3 geometry=$4 limit=${5:-0.01} end=$((SECONDS + 10)) d
  while :; do
    shot "$name" "$geometry"
    d=$(rmse "$ref" "$art/$name.png")
    if [ "$check" = changed ]; then awk -v d="$d" -v f="$limit" 'BEGIN { exit !(d > f) }' && break
    else awk -v d="$d" -v f="$limit" 'BEGIN { exit !(d <= f) }' && break; fi
    [ "$SECONDS" -lt "$end" ] || break
    sleep 0.2
  done
  "$check" "$ref" "$art/$name.png" "$limit"
}
# json_field FILE KEY...: a value of a JSON file (KEYs go down nested objects).
json_field() {
  /usr/bin/python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
for k in sys.argv[2:]: d = d[k]
print(d)' "$@"
}

# The viewer's own layout report ($layout, from --layout-json): rectangles of
# the panel, the image, the overlays and named controls, in window coordinates.
# layout_py EXPRESSION: evaluates EXPRESSION with d = the report (Python); prints it.
layout_py() {
  /usr/bin/python3 - "$layout" "$1" <<'PY'
import json, sys
try:
    d = json.load(open(sys.argv[1]))
except (OSError, ValueError):
    sys.exit(3)
print(eval(sys.argv[2], {"d": d}))
PY
}
# await_layout CONDITION: waits (up to 20 s) until the Python CONDITION on d holds.
await_layout() {
  local end=$((SECONDS + 20))
  while :; do
    [ "$(layout_py "bool($1)" 2>/dev/null)" = True ] && return 0
    [ "$SECONDS" -lt "$end" ] || fail "the layout never showed: $1"
    sleep 0.2
  done
}
# item NAME: "x y w h" of a named control (integers), once the report has it.
item() {
  await_layout "'$1' in d['items']"
  layout_py "' '.join(str(int(round(d['items']['$1'][k]))) for k in ('x', 'y', 'w', 'h'))"
}
# centre NAME: "x y" of a named control's centre.
centre() {
  local x y w h
  read -r x y w h <<<"$(item "$1")"
  echo "$((x + w / 2)) $((y + h / 2))"
}
# click NAME: a mouse click on a named control (the pointer then parked in the corner).
click() {
  local x y
  read -r x y <<<"$(centre "$1")"
  xdotool mousemove "$x" "$y"
  sleep 0.15
  xdotool click 1
  sleep 0.15
  xdotool mousemove 2 2
}
# crop_of NAME: an ImageMagick geometry for a named control's rectangle.
crop_of() {
  local x y w h
  read -r x y w h <<<"$(item "$1")"
  echo "${w}x${h}+${x}+${y}"
}
# reveal NAME: scrolls the side panel until the control lies inside its
# visible part (the sections scroll under the panel's head).
reveal() {
  local i x y w h top bottom
  for i in $(seq 40); do
    read -r x y w h <<<"$(item "$1")"
    read -r top bottom <<<"$(layout_py "'%d %d' % (d['items']['panel.sections']['y'], d['items']['panel.sections']['y'] + d['items']['panel.sections']['h'])")"
    if [ "$y" -ge "$top" ] && [ $((y + h)) -le "$bottom" ]; then return 0; fi
    read -r px _ <<<"$(centre panel)"
    xdotool mousemove "$px" "$(((top + bottom) / 2))"
    if [ "$y" -lt "$top" ]; then xdotool click 4; else xdotool click 5; fi
    sleep 0.25
  done
  fail "could not scroll $1 into view"
}
# no_overlaps: the report's overlays overlap neither each other nor the image's middle (keep_out).
no_overlaps() {
  /usr/bin/python3 - "$layout" <<'PY' || fail "overlays overlap (see above)"
import json, sys
d = json.load(open(sys.argv[1]))
def box(r): return (r["x"], r["y"], r["x"] + r["w"], r["y"] + r["h"])
def meet(a, b): return a[0] < b[2] - 0.5 and b[0] < a[2] - 0.5 and a[1] < b[3] - 0.5 and b[1] < a[3] - 0.5
over = [w for w in d["windows"] if w["role"] == "overlay"]
keep = box(d["keep_out"])
bad = False
for i, a in enumerate(over):
    if meet(box(a), keep): print("over the image's middle:", a["name"], box(a), keep); bad = True
    for b in over[i + 1:]:
        if meet(box(a), box(b)): print("overlap:", a["name"], box(a), b["name"], box(b)); bad = True
print("overlays:", ", ".join("%s %dx%d+%d+%d" % (w["name"], w["w"], w["h"], w["x"], w["y"]) for w in over),
      "| keep-out %dx%d+%d+%d" % (d["keep_out"]["w"], d["keep_out"]["h"], d["keep_out"]["x"], d["keep_out"]["y"]))
sys.exit(1 if bad else 0)
PY
}
