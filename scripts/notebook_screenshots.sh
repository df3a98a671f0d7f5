#!/usr/bin/env bash
# Remakes the pictures of the notebooks in docs/ (notebook_*.png): runs
# docs/notebooks/*.ipynb headlessly (the assignment with a worked answer, the
# one its test hands in), turns sections of them into HTML pages with Jupyter's
# nbconvert, and photographs each page in headless Chromium (installed from
# Debian when missing). Needs the module built (bash scripts/test.sh or
# scripts/notebook.sh build it).
#   bash scripts/notebook_screenshots.sh [OUT_DIR]   # default: docs
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-docs}
python=/usr/bin/python3
[ -x "$python" ] || python=python3
module=build/release/python
[ -f "$module/pdflab/__init__.py" ] || { echo "notebook_screenshots.sh: build the module first (bash scripts/notebook.sh)" >&2; exit 2; }
if ! command -v chromium >/dev/null; then
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends chromium
fi
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export PYTHONPATH="$PWD/$module" PDFLAB_REFERENCE_CACHE="$work/cache" PYDEVD_DISABLE_FILE_VALIDATION=1

"$python" - "$work" <<'EOF'
import os, re, sys
import nbformat
from nbconvert import HTMLExporter
from nbconvert.preprocessors import ExecutePreprocessor
sys.path.insert(0, "tests/python")
from test_notebooks import SOLUTION

work = sys.argv[1]

def run(name, answer=None):
    nb = nbformat.read(os.path.join("docs", "notebooks", name + ".ipynb"), as_version=4)
    for cell in nb.cells:
        if answer and "answer" in cell.metadata.get("tags", []):
            cell.source = answer
    ExecutePreprocessor(timeout=600, kernel_name="python3").preprocess(nb, {"metadata": {"path": work}})
    return nb

def heading(cell):
    return cell.source.splitlines()[0] if cell.cell_type == "markdown" and cell.source else ""

def page(nb, first, last, path):
    """The cells from the heading starting with `first` up to the one starting with `last` (None: the end)."""
    start = next(i for i, c in enumerate(nb.cells) if heading(c).startswith(first))
    end = next((i for i, c in enumerate(nb.cells) if last and i > start and heading(c).startswith(last)), len(nb.cells))
    part = nbformat.v4.new_notebook(cells=nb.cells[start:end], metadata=nb.metadata)
    body, _ = HTMLExporter().from_notebook_node(part)
    # No MathJax: nothing here is typeset, and its loading notice would show over the page.
    body = re.sub(r"<!-- Load mathjax -->.*?<!-- End of mathjax configuration -->", "", body, flags=re.S)
    with open(path, "w") as f:
        f.write(body)

tour = run("tour")
page(tour, "# A tour", "## A reference", os.path.join(work, "tour_render.html"))
page(tour, "## Convergence", "## The techniques", os.path.join(work, "tour_convergence.html"))
page(tour, "## Where should", None, os.path.join(work, "tour_weight.html"))
page(run("assignment", SOLUTION), "## Your work", None, os.path.join(work, "assignment.html"))
EOF

for name in tour_render tour_convergence tour_weight assignment; do
  chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1100,4000 \
    --screenshot="$work/$name.png" "file://$work/$name.html" >/dev/null 2>&1
  # The page's own height: the blank below it trimmed, a margin kept.
  convert "$work/$name.png" -trim +repage -bordercolor white -border 16 "$out/notebook_$name.png"
  echo "$out/notebook_$name.png"
done
