#!/usr/bin/env bash
# Code that tools can read: Universal Ctags, run from the project's root as
# anyone would (`ctags -R`), finds the definitions in the lane-generic .inc
# files (.ctags.d/pdflab.ctags maps them to C++). 77: ctags is not installed.
set -u
root=$1
command -v ctags >/dev/null || { echo "skipped: ctags is not installed"; exit 77; }
ctags --version 2>/dev/null | grep -q "Universal Ctags" || { echo "skipped: not Universal Ctags"; exit 77; }
cd "$root" || exit 1
tags=$(ctags -R -f - 2>/dev/null) || { echo "ctags failed"; exit 1; }
status=0
expect() {  # NAME FILE [SCOPE]
  local scope=${3:-}
  if ! printf '%s\n' "$tags" | awk -F'\t' -v n="$1" -v f="$2" -v s="$scope" \
      '$1 == n && $2 == f && (s == "" || index($0, s) > 0) { found = 1 } END { exit !found }'; then
    echo "not found: $1 in $2 ${scope:+($scope)}"
    status=1
  fi
}
expect sample_mixture renderer/sampling/mixture.inc
expect mixture_pdf renderer/sampling/mixture.inc
expect sample renderer/sampling/techniques/cosine_power.inc struct:CosinePower
expect pdf renderer/sampling/techniques/uniform_cone.inc struct:UniformCone
expect PathTracer renderer/integrator/path.inc
expect bounce renderer/integrator/path.inc PathTracer
expect next_event renderer/integrator/path.inc PathTracer
expect BlockScheduler renderer/integrator/schedule.inc
expect sample_quad_area renderer/sampling/leaf_math.inc
# Nothing from the build folders.
if printf '%s\n' "$tags" | awk -F'\t' '$2 ~ /^build\//' | grep -q .; then
  echo "indexed a build folder"
  status=1
fi
[ $status = 0 ] && echo "ctags finds the lane-generic definitions"
exit $status
