"""Shared set-up of the Python module's tests: the pdflab binary they compare
with, the shipped scenes, and a reference cache of their own."""

import os
import subprocess
import sys

import pytest

SOURCE_DIR = os.environ.get("PDFLAB_SOURCE_DIR", os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
BINARY = os.environ.get("PDFLAB_BINARY", os.path.join(SOURCE_DIR, "build", "release", "app", "pdflab"))
if not os.environ.get("PYTHONPATH"):
    sys.path.insert(0, os.path.join(SOURCE_DIR, "build", "release", "python"))


def scene_file(name):
    return os.path.join(SOURCE_DIR, "assets", "scenes", name + ".json")


def cli(*args, timeout=300):
    """Runs the pdflab binary; returns the finished process (output as text)."""
    return subprocess.run([BINARY, *map(str, args)], capture_output=True, text=True, timeout=timeout)


def cli_error(*args):
    """The message of a command the binary refuses as bad input (status 2): what follows 'pdflab: error: '."""
    done = cli(*args)
    assert done.returncode == 2, (args, done.returncode, done.stderr)
    first = done.stderr.splitlines()[0]
    assert first.startswith("pdflab: error: "), done.stderr
    return first[len("pdflab: error: "):]


@pytest.fixture(autouse=True)
def reference_cache(tmp_path, monkeypatch):
    """Each test its own reference cache (the module and the binary both read $PDFLAB_REFERENCE_CACHE)."""
    cache = tmp_path / "cache"
    monkeypatch.setenv("PDFLAB_REFERENCE_CACHE", str(cache))
    return cache
