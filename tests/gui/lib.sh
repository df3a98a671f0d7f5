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
