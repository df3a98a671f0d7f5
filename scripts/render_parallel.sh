#!/usr/bin/env bash
# Renders one image as K disjoint sample ranges with GNU parallel (local job
# slots, or other machines with --sshlogin) and merges them with pdflab merge.
# The result is the same estimate as one render of all the samples
# (docs/distributed.md).
#
#   scripts/render_parallel.sh --jobs K --spp N --out REF.exr [--film-out ALL.film]
#       [--parts DIR] [--sshlogin LOGINS] [--threads T] -- RENDER_OPTIONS...
#
# RENDER_OPTIONS are given to every `pdflab render` (--scene, --strategy,
# --seed, --width, --height, ...). Range k of K covers the sample indices
# [k*N/K, (k+1)*N/K). Each part is a film in DIR (default: a new temporary
# folder, removed afterwards), so a failed part can be rendered again alone.
# With --sshlogin (GNU parallel's syntax, e.g. "4/alice@m1,4/alice@m2,:"),
# every machine must see pdflab, the scene and DIR at the same paths (a shared
# folder). PDFLAB names the binary (default: build/release/app/pdflab).
set -euo pipefail

usage() {
  sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}

jobs="" spp="" out="" film_out="" parts="" sshlogin="" threads=""
while [ $# -gt 0 ]; do
  case "$1" in
    --jobs) jobs=${2:?}; shift 2 ;;
    --spp) spp=${2:?}; shift 2 ;;
    --out) out=${2:?}; shift 2 ;;
    --film-out) film_out=${2:?}; shift 2 ;;
    --parts) parts=${2:?}; shift 2 ;;
    --sshlogin) sshlogin=${2:?}; shift 2 ;;
    --threads) threads=${2:?}; shift 2 ;;
    --) shift; break ;;
    *) echo "render_parallel.sh: unknown option '$1'" >&2; usage ;;
  esac
done
render_args=("$@")

is_count() { [[ "$1" =~ ^[1-9][0-9]*$ ]]; }
is_count "$jobs" || { echo "render_parallel.sh: --jobs must be a positive integer" >&2; exit 2; }
is_count "$spp" || { echo "render_parallel.sh: --spp must be a positive integer" >&2; exit 2; }
[ "$spp" -ge "$jobs" ] || { echo "render_parallel.sh: --spp ($spp) must be at least --jobs ($jobs)" >&2; exit 2; }
[ -n "$out" ] || [ -n "$film_out" ] || { echo "render_parallel.sh: give --out, --film-out or both" >&2; exit 2; }
command -v parallel >/dev/null || { echo "render_parallel.sh: GNU parallel is not installed (apt-get install parallel)" >&2; exit 2; }

here=$(cd "$(dirname "$0")/.." && pwd)
pdflab=${PDFLAB:-$here/build/release/app/pdflab}
[ -x "$pdflab" ] || { echo "render_parallel.sh: no pdflab binary at $pdflab (build it, or set PDFLAB)" >&2; exit 2; }

# Local jobs share this machine's cores; remote ones use all of theirs.
if [ -z "$threads" ]; then
  if [ -z "$sshlogin" ]; then
    threads=$(( $(nproc) / jobs ))
    [ "$threads" -ge 1 ] || threads=1
  else
    threads=0
  fi
fi

cleanup_parts=""
if [ -z "$parts" ]; then
  parts=$(mktemp -d "${TMPDIR:-/tmp}/pdflab-parts-XXXXXX")
  cleanup_parts=$parts
fi
mkdir -p "$parts"
trap '[ -z "$cleanup_parts" ] || rm -rf "$cleanup_parts"' EXIT

starts=() counts=()
for ((k = 0; k < jobs; k++)); do
  first=$(( k * spp / jobs ))
  end=$(( (k + 1) * spp / jobs ))
  starts+=("$first")
  counts+=("$(( end - first ))")
done

parallel_args=(--will-cite --halt now,fail=1 --line-buffer -q)
if [ -n "$sshlogin" ]; then
  parallel_args+=(--sshlogin "$sshlogin")
else
  parallel_args+=(--jobs "$jobs")
fi
# -q hands each argument over unchanged (no shell word splitting of paths).
parallel "${parallel_args[@]}" \
  "$pdflab" render "${render_args[@]}" --threads "$threads" --quiet \
  --first-sample '{1}' --spp '{2}' --film-out "$parts/part-{1}.film" \
  ::: "${starts[@]}" :::+ "${counts[@]}"

merge_args=()
[ -z "$out" ] || merge_args+=(--out "$out")
[ -z "$film_out" ] || merge_args+=(--film-out "$film_out")
films=()
for first in "${starts[@]}"; do films+=("$parts/part-$first.film"); done
"$pdflab" merge "${films[@]}" "${merge_args[@]}"
