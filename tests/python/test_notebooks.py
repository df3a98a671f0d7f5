"""The assignment's autograder grades: a worked answer passes, a wrong one
fails. (Both notebooks as shipped are executed by ctest's notebook_* tests.)"""

import os

import nbformat
import pytest

from conftest import SOURCE_DIR

NOTEBOOKS = os.path.join(SOURCE_DIR, "docs", "notebooks")

# What a student might hand in: the efficiency over four seeds per weight,
# pooled as the sweep pools it (the mean relMSE x spp over the mean time per sample).
SOLUTION = """
weights = np.round(np.arange(0.2, 0.95, 0.1), 2)
efficiency = []
for w in weights:
    films = [pdflab.render(scene, mixture(w), spp=32, seed=seed) for seed in (11, 12, 13, 14)]
    per_sample = np.mean([float(pdflab.relmse(f, reference)) * f.spp for f in films])
    seconds_per_sample = np.mean([f.seconds / f.spp for f in films])
    efficiency.append(1 / (per_sample * seconds_per_sample))
best_weight = float(weights[int(np.argmax(efficiency))])
print("efficiency", dict(zip(weights.tolist(), np.round(efficiency, 1))), "best", best_weight)
"""

WRONG = """
try:
    grade(0.05)
except AssertionError as wrong:
    print("REJECTED:", wrong)
else:
    raise SystemExit("the autograder passed a wrong weight")
"""


def text_of(cell):
    return "".join(o.get("text", "") for o in cell.outputs if o.output_type == "stream")


def test_the_autograder_passes_an_answer_and_fails_a_wrong_one(tmp_path):
    nbconvert = pytest.importorskip("nbconvert.preprocessors")
    nb = nbformat.read(os.path.join(NOTEBOOKS, "assignment.ipynb"), as_version=4)
    answer = [c for c in nb.cells if "answer" in c.metadata.get("tags", [])]
    graders = [c for c in nb.cells if "autograder" in c.metadata.get("tags", [])]
    assert len(answer) == 1 and len(graders) == 1
    assert "best_weight = None" in answer[0].source  # shipped unanswered
    answer[0].source = SOLUTION
    nb.cells.append(nbformat.v4.new_code_cell(WRONG))
    nbconvert.ExecutePreprocessor(timeout=600, kernel_name="python3").preprocess(nb, {"metadata": {"path": str(tmp_path)}})
    assert "PASS" in text_of(graders[0]), text_of(graders[0])
    assert "REJECTED: 0.05 is far from the predicted best" in text_of(nb.cells[-1]), text_of(nb.cells[-1])
