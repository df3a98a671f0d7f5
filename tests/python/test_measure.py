"""References, relMSE, the sweep and the weight prediction against the
command line's: the same cache, the same figures."""

import csv
import io
import json
import os
import signal
import subprocess
import sys
import time
import types

import numpy as np
import pytest

import pdflab
from conftest import cli, cli_error, scene_file

BOOK = scene_file("cornell_book")
SMALL = scene_file("small_light")


def test_relmse_equals_the_command_lines_figure(tmp_path):
    ref_path = tmp_path / "ref.pfm"
    done = cli("reference", "--scene", BOOK, "--width", 32, "--height", 24, "--spp", 64, "--quiet", "--out", ref_path)
    assert done.returncode == 0, done.stderr
    stats = tmp_path / "stats.json"
    done = cli("render", "--scene", BOOK, "--strategy", "mix:cosine=0.5,light=0.5", "--spp", 8, "--width", 32,
               "--height", 24, "--reference", ref_path, "--quiet", "--out", tmp_path / "x.pfm", "--stats-json", stats)
    assert done.returncode == 0, done.stderr
    want = json.loads(stats.read_text())
    film = pdflab.render(BOOK, "mix:cosine=0.5,light=0.5", spp=8, width=32, height=24, progress=False)
    for reference in [str(ref_path), pdflab.Reference.load(str(ref_path)), "auto"]:
        got = pdflab.relmse(film, reference)
        assert float(got) == want["relmse"]
        assert got.interval == want["relmse_interval"] and got.raw == want["relmse_raw"]
        assert got.reference_share == want["reference_share"]
        assert got.reference_corrected and 0 < got.interval < abs(got.value)
        # The CLI printed the same figure with its interval.
        assert "relMSE %.4g +- %.2g (95%%)" % (got.value, got.interval) in done.stdout


def test_reference_shares_the_command_lines_cache(tmp_path):
    scene = pdflab.Scene.load(BOOK)
    ref = pdflab.reference(scene, spp=32, width=24, height=24, progress=False)
    assert ref.path.startswith(pdflab.reference_cache_dir()) and ref.spp == 32 and ref.has_variance
    assert ref.mean.shape == (24, 24, 3) and ref.variance.shape == (24, 24, 3)
    # The command line's reference of the same scene, size and goal is the same image...
    done = cli("reference", "--scene", BOOK, "--width", 24, "--height", 24, "--spp", 32, "--quiet",
               "--cache-dir", tmp_path / "cli-cache", "--out", tmp_path / "cli.pfm")
    assert done.returncode == 0, done.stderr
    assert np.array_equal(ref.mean, pdflab.Reference.load(str(tmp_path / "cli.pfm")).mean)
    # ... and it finds the module's in the cache (auto), and the module finds it again.
    done = cli("render", "--scene", BOOK, "--strategy", "cosine", "--spp", 2, "--width", 24, "--height", 24,
               "--reference", "auto", "--out", tmp_path / "x.pfm")
    assert done.returncode == 0 and "using the cached reference " + ref.path in done.stderr, done.stderr
    cached = pdflab.reference(scene, width=24, height=24)
    assert cached.path == ref.path and np.array_equal(cached.mean, ref.mean)
    # None at another size: the message of a command that needs one.
    with pytest.raises(ValueError) as e:
        pdflab.reference(scene, width=20, height=24)
    assert str(e.value) == cli_error("bench", "--scene", BOOK, "--strategies", "cosine", "--spp", 1, "--reference",
                                     "auto", "--width", 20, "--height", 24, "--csv", tmp_path / "b.csv")
    assert "make one with: pdflab reference" in str(e.value)


def test_relmse_refuses_what_the_command_line_refuses(tmp_path):
    ref_path = tmp_path / "ref.pfm"
    assert cli("render", "--scene", BOOK, "--strategy", "cosine", "--spp", 4, "--seed", 5, "--width", 16, "--height",
               16, "--quiet", "--out", ref_path, "--stats-json", tmp_path / "ref.json").returncode == 0
    film = pdflab.render(BOOK, "cosine", spp=2, seed=5, width=16, height=16, progress=False)
    with pytest.raises(ValueError) as e:
        pdflab.relmse(film, str(ref_path))
    assert str(e.value) == cli_error("render", "--scene", BOOK, "--strategy", "cosine", "--spp", 2, "--seed", 5,
                                     "--width", 16, "--height", 16, "--reference", ref_path, "--out",
                                     tmp_path / "x.pfm")
    small = pdflab.render(BOOK, "cosine", spp=2, seed=6, width=12, height=16, progress=False)
    with pytest.raises(ValueError) as e:
        pdflab.relmse(small, str(ref_path))
    assert str(e.value) == cli_error("render", "--scene", BOOK, "--strategy", "cosine", "--spp", 2, "--seed", 6,
                                     "--width", 12, "--height", 16, "--reference", ref_path, "--out",
                                     tmp_path / "x.pfm")


def test_sweep_rows_are_the_command_lines_csv(tmp_path, monkeypatch):
    ref = pdflab.reference(SMALL, spp=64, width=24, height=24, progress=False)
    rows = pdflab.sweep(SMALL, "cosine,light", "0.25:0.75:0.25", spp=4, seeds=2, reference=ref, frame=False)
    done = cli("sweep", "--scene", SMALL, "--vary", "cosine,light", "--weights", "0.25:0.75:0.25", "--spp", 4,
               "--seeds", 2, "--reference", ref.path, "--quiet", "--csv", tmp_path / "cli.csv")
    assert done.returncode == 0, done.stderr
    want = list(csv.DictReader(io.StringIO((tmp_path / "cli.csv").read_text())))
    assert rows.columns == list(want[0].keys())
    assert [r["weight"] for r in rows] == [0.25, 0.5, 0.75]
    for got, row in zip(rows, want):
        assert got["strategy"] == row["strategy"] and got["spp"] == int(row["spp"]) == 4
        assert got["unbiased"] is True and isinstance(got["best"], bool)
        # Equal samples, equal seeds: the images and their errors are the command line's.
        for column in ["relmse", "relmse_lo", "relmse_hi", "relmse_per_sample", "predicted_relmse_per_sample"]:
            assert "%.6g" % got[column] == row[column], column
    assert sum(r["best"] for r in rows) == 1
    assert "best weight of cosine" in rows.summary and "best weight of cosine" in done.stdout
    # With pandas installed, a DataFrame of the same rows and the summary in its attrs.
    made = []

    class DataFrame:
        def __init__(self, data, columns=None):
            self.data, self.columns, self.attrs = data, columns, {}
            made.append(self)

    monkeypatch.setitem(sys.modules, "pandas", types.SimpleNamespace(DataFrame=DataFrame))
    frame = pdflab.sweep(SMALL, "cosine,light", "0.25:0.75:0.25", spp=1, seeds=1, reference=ref)
    assert frame is made[0] and frame.columns == rows.columns and len(frame.data) == 3
    assert "best weight of cosine" in frame.attrs["summary"]


def test_predict_weights(tmp_path):
    ref = pdflab.reference(SMALL, spp=64, width=24, height=24, progress=False)
    rows = pdflab.predict_weights(SMALL, "cosine,light", spp=8, reference=ref, grid=21, frame=False)
    assert [round(r["weight"], 9) for r in rows] == [round(0.05 * i, 9) for i in range(21)]
    assert rows[10]["strategy"] == "mix:cosine=0.5,light=0.5"
    assert 0.0 <= rows.best_weight <= 1.0 and rows.pilot_weight == 0.5 and rows.paths == 24 * 24 * 8
    inner = [r for r in rows if 0.1 <= r["weight"] <= 0.9]
    assert all(r["efficiency"] > 0 and r["relative_variance"] > 0 for r in inner)
    best = max(rows, key=lambda r: r["efficiency"])
    assert best["weight"] == rows.best_weight
    # Light sampling alone is biased here: nothing there to predict.
    assert rows[0]["efficiency"] == 0 or not np.isfinite(rows[0]["relative_variance"])
    with pytest.raises(ValueError, match=r"inside \[0\.05, 0\.95\]"):
        pdflab.predict_weights(SMALL, "cosine,light", weight=0.01, reference=ref)
    with pytest.raises(ValueError) as e:
        pdflab.predict_weights(SMALL, "cosine,lite", reference=ref)
    assert "lite" in str(e.value)


@pytest.mark.parametrize("call", ["sweep", "predict_weights"])
def test_ctrl_c_stops_a_sweep_and_a_prediction(tmp_path, call):
    # Each would take minutes: a sweep of 3 weights x 2 seeds at 60 s a run, a
    # pilot of 2^24 spp. Ctrl+C raises KeyboardInterrupt within a poll, and the
    # process's stdout is its own again (the sweep's table is captured).
    script = r"""
import os, sys, time
import pdflab
ref = pdflab.reference(sys.argv[1], spp=16, width=16, height=16, progress=False)
print("measuring", flush=True)
try:
    if sys.argv[2] == "sweep":
        pdflab.sweep(sys.argv[1], "cosine,light", "0.25:0.75:0.25", seconds=60, seeds=2, reference=ref, threads=1)
    else:
        pdflab.predict_weights(sys.argv[1], "cosine,light", spp=1 << 24, reference=ref, threads=1)
    print("finished", flush=True)
except KeyboardInterrupt:
    print("interrupted", flush=True)
    os.write(1, b"stdout is back\n")
"""
    child = subprocess.Popen([sys.executable, "-c", script, SMALL, call], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=os.environ.copy())
    try:
        assert child.stdout.readline().strip() == "measuring"
        time.sleep(1.0)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=120)
        waited = time.monotonic() - sent
    finally:
        child.kill()
    assert child.returncode == 0, err
    assert out.split() == ["interrupted", "stdout", "is", "back"], (out, err)
    assert waited < 60, waited
