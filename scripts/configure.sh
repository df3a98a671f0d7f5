#!/usr/bin/env bash
# cmake --preset PRESET [ARGS...]: a fresh build folder is generated for Ninja
# where it is installed (scripts/install_deps.sh installs it), which compiles a
# target's files while the libraries it links are still being built, where
# Make waits for them to be linked first; a folder already configured keeps
# the generator it was made with (cmake refuses to change it).
set -euo pipefail
preset=$1
shift
generator=()
binary_dir=$(dirname "$0")/../build/$preset
if [ ! -f "$binary_dir/CMakeCache.txt" ] && command -v ninja >/dev/null; then generator=(-G Ninja); fi
cmake --preset "$preset" "${generator[@]}" "$@"
