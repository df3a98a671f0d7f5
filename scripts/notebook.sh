#!/usr/bin/env bash
# Installs what is missing, builds the Python module (Release) and opens the
# notebooks in docs/notebooks/ in Jupyter, with `import pdflab` working.
# Extra arguments go to Jupyter (e.g. --no-browser --port 8899).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/configure.sh release >/dev/null
cmake --build --preset release -j"$(nproc)" --target pdflab_python
export PYTHONPATH="$PWD/build/release/python${PYTHONPATH:+:$PYTHONPATH}"
args=(--notebook-dir=docs/notebooks)
[ "$(id -u)" -ne 0 ] || args+=(--allow-root)  # Jupyter refuses to run as root without it
# Debian's Jupyter, numpy and matplotlib belong to its own interpreter.
exec /usr/bin/python3 -m notebook "${args[@]}" "$@"
