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

fail() { echo "FAIL: $*"; exit 1; }

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
# and the pointer parked in the corner, away from the panel's tooltips.
# Environment assignments before it reach the viewer.
start_viewer() {
  # The last viewer's window must be gone, or the search could find it.
  for _ in $(seq 50); do xdotool search --name '^pdflab' >/dev/null 2>&1 || break; sleep 0.1; done
  "$@" &
  viewer=$!
  focus_window
  xdotool mousemove 2 2
}
viewer=
at_exit=  # more to do when the script ends (e.g. remove a temporary folder)
trap '[ -z "$viewer" ] || kill "$viewer" 2>/dev/null || true; eval "$at_exit"' EXIT

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
