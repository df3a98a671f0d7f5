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
# [k*N/K, (k+1)*N/K). A part renders to DIR/partial-FIRST.film and becomes
# DIR/part-FIRST.film only when it is whole; the merge refuses anything but
# the whole [0, N) (merge --expect-spp). When a part fails the others go on,
# DIR is kept and the command to continue is printed: the same command with
# --parts DIR renders only what is missing, resuming the partial films.
# DIR defaults to a new temporary folder, removed after a successful merge.
# With --sshlogin (GNU parallel's syntax, e.g. "alice@m1,alice@m2,:"), each
# machine runs one part at a time on all its cores (--threads to change),
# every job starts in this folder, so relative paths work, and every machine
# must see this folder, pdflab and the scene at the same paths (a shared
# folder, e.g. NFS); DIR then defaults to a new folder in this one.
# PDFLAB names the binary (default: build/release/app/pdflab).
set -euo pipefail

usage() {
  sed -n '2,23p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}

invocation=("$0" "$@")
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
[ -z "$threads" ] || [[ "$threads" =~ ^[0-9]+$ ]] || { echo "render_parallel.sh: --threads must be an integer >= 0" >&2; exit 2; }
[ -n "$out" ] || [ -n "$film_out" ] || { echo "render_parallel.sh: give --out, --film-out or both" >&2; exit 2; }
command -v parallel >/dev/null || { echo "render_parallel.sh: GNU parallel is not installed (apt-get install parallel)" >&2; exit 2; }

here=$(cd "$(dirname "$0")/.." && pwd)
pdflab=${PDFLAB:-$here/build/release/app/pdflab}
[ -x "$pdflab" ] || { echo "render_parallel.sh: no pdflab binary at $pdflab (build it, or set PDFLAB)" >&2; exit 2; }

# Local jobs share this machine's cores; a machine reached by ssh runs one part
# at a time on all of its own (job slots asked for in LOGINS, N/login, are
# dropped: several parts on one machine would each take every core).
if [ -n "$sshlogin" ]; then
  logins=()
  IFS=',' read -r -a given <<<"$sshlogin"
  for login in "${given[@]}"; do
    if [[ "$login" =~ ^[0-9]+/(.*)$ ]]; then
      echo "render_parallel.sh: note: '$login': one part at a time per machine, on all its cores" >&2
      login=${BASH_REMATCH[1]}
    fi
    logins+=("$login")
  done
  sshlogin=$(IFS=','; echo "${logins[*]}")
fi
if [ -z "$threads" ]; then
  if [ -z "$sshlogin" ]; then
    threads=$(( $(nproc) / jobs ))
    [ "$threads" -ge 1 ] || threads=1
  else
    threads=0
  fi
fi

temporary_parts=""
if [ -z "$parts" ]; then
  if [ -z "$sshlogin" ]; then
    parts=$(mktemp -d "${TMPDIR:-/tmp}/pdflab-parts-XXXXXX")
  else
    parts=$(mktemp -d "$PWD/pdflab-parts-XXXXXX")  # here: the machines share this folder, not /tmp
  fi
  temporary_parts=$parts
fi
mkdir -p "$parts"

# A parts folder belongs to one render: the same samples, parts and options.
# Another render's parts would be resumed or merged as this one's.
layout="spp=$spp jobs=$jobs render:$(printf ' %q' "${render_args[@]}")"
if [ -f "$parts/layout" ]; then
  if [ "$(cat "$parts/layout")" != "$layout" ]; then
    echo "render_parallel.sh: '$parts' holds the parts of another render ($(cat "$parts/layout")); give another --parts folder" >&2
    exit 2
  fi
else
  printf '%s\n' "$layout" >"$parts/layout.tmp.$$" && mv -f "$parts/layout.tmp.$$" "$parts/layout"
fi

starts=() counts=()
for ((k = 0; k < jobs; k++)); do
  first=$(( k * spp / jobs ))
  end=$(( (k + 1) * spp / jobs ))
  starts+=("$first")
  counts+=("$(( end - first ))")
done

# The same command with --parts: it renders only what is missing.
print_continue() {
  echo "render_parallel.sh: what the parts rendered is in $parts (partial-*.film: stopped early); continue with:" >&2
  local cont=("${invocation[@]}")
  [ -z "$temporary_parts" ] || cont=("$0" --parts "$parts" "${invocation[@]:1}")
  printf ' %q' "${cont[@]}" >&2
  echo >&2
}
trap 'echo >&2; print_continue; exit 130' INT TERM

# One part, run by bash on whichever machine GNU parallel chooses: in this
# folder, a whole part is kept, a partial one resumed (pdflab checks that it
# is this render's: scene, strategy, seed, size, first sample), a missing one
# rendered; only a part that reached its count takes its final name.
# shellcheck disable=SC2016 # expanded by the job's shell
part_job='dir=$1 pdflab=$2 parts=$3 first=$4 count=$5 threads=$6; shift 6;
cd "$dir" 2>/dev/null || { echo "render_parallel.sh: $(hostname): no folder $dir here (every machine must see it at the same path)" >&2; exit 3; };
whole=$parts/part-$first.film; partial=$parts/partial-$first.film;
[ -f "$whole" ] && exit 0;
if [ -f "$partial" ]; then "$pdflab" render --resume "$partial" "$@" --first-sample "$first" --spp "$count" --threads "$threads" --quiet || exit;
else "$pdflab" render "$@" --first-sample "$first" --spp "$count" --film-out "$partial" --threads "$threads" --quiet || exit; fi;
mv -f "$partial" "$whole"'
part_job=${part_job//$'\n'/ }

parallel_args=(--will-cite --line-buffer -q)
if [ -n "$sshlogin" ]; then
  parallel_args+=(--sshlogin "$sshlogin" --jobs 1)
else
  parallel_args+=(--jobs "$jobs")
fi
# -q hands each argument over unchanged (no shell word splitting of paths).
# Every part runs even when one fails: what the others render is kept.
failed=0
parallel "${parallel_args[@]}" \
  bash -c "$part_job" pdflab-part "$PWD" "$pdflab" "$parts" '{1}' '{2}' "$threads" "${render_args[@]}" \
  ::: "${starts[@]}" :::+ "${counts[@]}" || failed=$?

missing=()
for first in "${starts[@]}"; do [ -f "$parts/part-$first.film" ] || missing+=("$first"); done
if [ ${#missing[@]} -gt 0 ]; then
  echo "render_parallel.sh: ${#missing[@]} of $jobs parts did not finish (first samples: ${missing[*]}; GNU parallel status $failed)." >&2
  print_continue
  exit 1
fi

merge_args=(--expect-spp "$spp")
[ -z "$out" ] || merge_args+=(--out "$out")
[ -z "$film_out" ] || merge_args+=(--film-out "$film_out")
films=()
for first in "${starts[@]}"; do films+=("$parts/part-$first.film"); done
"$pdflab" merge "${films[@]}" "${merge_args[@]}" || {
  echo "render_parallel.sh: the merge failed; the parts are kept in $parts" >&2
  exit 1
}
[ -z "$temporary_parts" ] || rm -rf "$temporary_parts"
