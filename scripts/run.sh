#!/usr/bin/env bash
# Installs what is missing, builds (Release) and starts the viewer on the default scene.
# Extra arguments go to pdflab (e.g. --scene assets/scenes/small_light.json).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/configure.sh release >/dev/null
cmake --build --preset release -j"$(nproc)" --target pdflab
exec build/release/app/pdflab "$@"
