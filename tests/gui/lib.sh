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
# quit_viewer WID PID: Ctrl+Q, and Ctrl+Q again ("quit anyway") when it asks
# first (a render of more than a few seconds, unsaved); waits for the exit
# status, which must be 0.
quit_viewer() {
  xdotool key --window "$1" ctrl+q
  for _ in $(seq 10); do kill -0 "$2" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "$2" 2>/dev/null; then xdotool key --window "$1" ctrl+q; fi
  wait "$2" || fail "viewer exited with status $?"
}
# focus_window: waits for the viewer's window, gives it the keyboard and sets
# wid, WIDTH and HEIGHT.
focus_window() {
  wid=$(timeout 30 xdotool search --sync --name '^pdflab' | head -1)
  [ -n "$wid" ] || fail "no viewer window"
  sleep 1
  xdotool windowfocus --sync "$wid"
  eval "$(xdotool getwindowgeometry --shell "$wid")"
}

# Sends keys to the viewer window. XSendEvent (xdotool key --window) is
# refused with BadWindow by some windows once they have gone full screen or
# opened a popup under Xvfb; then the keys go through XTEST to the focused window.
send_key() {
  xdotool key --window "$wid" "$@" 2>/dev/null && return 0
  xdotool windowfocus --sync "$wid" 2>/dev/null || true
  xdotool key "$@"
}

