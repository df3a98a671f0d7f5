"""pdflab.render and pdflab.Film against `pdflab render`: the same bits, the
same files, the GIL released while rendering, Ctrl+C between passes, and the
command line's messages for bad input."""

import json
import re
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import pdflab
from conftest import SOURCE_DIR, cli, cli_error, scene_file

BOOK = scene_file("cornell_book")


def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return np.flipud(data.reshape(height, width, 3))  # PFM rows run bottom to top


@pytest.mark.parametrize("strategy", ["cosine", "mix:cosine=0.5,light=0.5", "nee-mis+sobol", "fastest",
                                      "light-sa+rr:2", "mix:cosine-power:20=0.3,specular-objects=0.7"])
def test_render_gives_the_bits_of_the_command_line(tmp_path, strategy):
    args = dict(spp=6, seed=3, width=24, height=20, first_sample=2)
    done = cli("render", "--scene", BOOK, "--strategy", strategy, "--spp", 6, "--seed", 3, "--width", 24,
               "--height", 20, "--first-sample", 2, "--threads", 1, "--quiet", "--out", tmp_path / "cli.pfm")
    assert done.returncode == 0, done.stderr
    if pdflab.strategy(strategy)["unbiased"]:
        film = pdflab.render(BOOK, strategy, threads=2, progress=False, **args)
    else:  # said, as the command line notes it
        with pytest.warns(UserWarning, match=re.escape("'%s' is biased" % strategy)):
            film = pdflab.render(BOOK, strategy, threads=2, progress=False, **args)
    film.save(str(tmp_path / "module.pfm"))
    assert (tmp_path / "module.pfm").read_bytes() == (tmp_path / "cli.pfm").read_bytes()
    assert np.array_equal(film.mean, read_pfm(tmp_path / "cli.pfm"))
    assert film.mean.shape == (20, 24, 3) and film.mean.dtype == np.float32
    assert film.spp == 6 and (film.count == 6).all() and not film.interrupted
    assert film.first_sample == 2 and film.seed == 3


def test_every_format_the_command_line_writes(tmp_path):
    common = ["--scene", BOOK, "--strategy", "mix:cosine=0.5,light=0.5", "--spp", 4, "--seed", 5, "--width", 20,
              "--height", 16, "--quiet"]
    film = pdflab.render(BOOK, "mix:cosine=0.5,light=0.5", spp=4, seed=5, width=20, height=16, progress=False)
    for ext in ["png", "pfm", "hdr", "exr"]:
        done = cli("render", *common, "--out", tmp_path / ("cli." + ext))
        assert done.returncode == 0, done.stderr
        film.save(str(tmp_path / ("module." + ext)))
        assert (tmp_path / ("module." + ext)).read_bytes() == (tmp_path / ("cli." + ext)).read_bytes(), ext
    # The film file holds the time the render took, so it is compared read back.
    assert cli("render", *common, "--film-out", tmp_path / "cli.film").returncode == 0
    film.save(str(tmp_path / "module.film"))
    a, b = pdflab.Film.load(str(tmp_path / "cli.film")), pdflab.Film.load(str(tmp_path / "module.film"))
    for name in ["sums", "squares", "count", "drop_mask", "mean", "variance"]:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert (a.strategy, a.samples_text, a.scene_file, a.max_depth) == (b.strategy, b.samples_text, b.scene_file,
                                                                       b.max_depth)
    # A module's film continues on the command line.
    done = cli("render", "--resume", tmp_path / "module.film", "--spp", 8, "--quiet")
    assert done.returncode == 0, done.stderr
    assert pdflab.Film.load(str(tmp_path / "module.film")).spp == 8


def test_arrays_are_views_of_the_film():
    film = pdflab.render(BOOK, "cosine", spp=3, width=16, height=12, progress=False)
    for name in ["count", "sums", "squares", "drop_mask", "mean", "variance"]:
        a, b = getattr(film, name), getattr(film, name)
        assert np.shares_memory(a, b), name  # no copy per access
        assert not a.flags.writeable, name
    assert film.sums.base is not None
    mean = film.sums / film.count[..., None]
    assert np.allclose(film.mean, mean, rtol=1e-6, atol=0)
    variance = (film.squares / 3 - mean * mean).clip(min=0) / 2
    assert np.allclose(film.variance, variance, rtol=1e-9, atol=1e-12)
    del film  # the arrays keep the film alive
    assert np.isfinite(mean).all()


def test_render_by_time_stops_between_passes():
    film = pdflab.render(BOOK, "cosine", seconds=0.3, width=32, height=32, threads=1, progress=False)
    assert film.time_up and not film.interrupted
    assert film.seconds >= 0.3 and film.spp > 0
    assert (film.count == film.spp).all()


def test_the_gil_is_released_while_rendering(monkeypatch):
    # Polled once a second: a render that kept the GIL while it waits would stop
    # the other thread for that long at a time.
    monkeypatch.setattr(pdflab, "_POLL_QUIET", 1.0)
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())

    other = threading.Thread(target=count)
    other.start()
    start = time.perf_counter()
    try:
        film = pdflab.render(BOOK, "mix:cosine=0.5,light=0.5", seconds=2.5, width=64, height=64, threads=1,
                             progress=False)
    finally:
        end = time.perf_counter()
        stop.set()
        other.join()
    during = np.array([t for t in ticks if start < t < end])
    assert film.seconds >= 2.5
    assert len(during) > 10000
    assert np.diff(during).max() < 0.25, "the other thread stood still for %.3f s" % np.diff(during).max()


def test_ctrl_c_between_passes_returns_the_partial_film(tmp_path):
    script = r"""
import json, sys
import numpy as np
import pdflab
print("rendering", flush=True)
film = pdflab.render(sys.argv[1], "cosine", spp=1 << 30, width=64, height=64, threads=1, progress=False)
print(json.dumps({"spp": film.spp, "interrupted": film.interrupted, "counts": sorted(set(film.count.ravel().tolist())),
                  "finite": bool(np.isfinite(film.mean).all()), "target": film.target_spp}), flush=True)
film.save(sys.argv[2])
"""
    child = subprocess.Popen([sys.executable, "-c", script, BOOK, str(tmp_path / "partial.pfm")],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=os.environ.copy())
    try:
        assert child.stdout.readline().strip() == "rendering"
        time.sleep(1.5)
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=120)
    finally:
        child.kill()
    assert child.returncode == 0, err
    result = json.loads(out.splitlines()[-1])
    assert result["interrupted"] and result["finite"] and result["target"] == 1 << 30
    assert 0 < result["spp"] < 1 << 30
    assert result["counts"] == [result["spp"]]  # whole passes only
    assert "interrupted at %d of %d spp" % (result["spp"], 1 << 30) in err
    assert read_pfm(tmp_path / "partial.pfm").shape == (64, 64, 3)


def test_bad_input_raises_value_error_with_the_command_lines_message(tmp_path):
    def module_error(call):
        with pytest.raises(ValueError) as e:
            call()
        assert isinstance(e.value, pdflab.InputError)
        return str(e.value)

    out = str(tmp_path / "x.pfm")
    render = ["render", "--scene", BOOK, "--spp", 1]
    # An unknown technique.
    assert module_error(lambda: pdflab.render(BOOK, "cosin", spp=1)) == \
        cli_error(*render, "--strategy", "cosin", "--out", out)
    # A scene file that is not there, and one that is not JSON.
    missing = str(tmp_path / "missing.json")
    assert module_error(lambda: pdflab.Scene.load(missing)) == \
        cli_error("render", "--scene", missing, "--strategy", "cosine", "--spp", 1, "--out", out)
    broken = tmp_path / "broken.json"
    broken.write_text('{"name": "x", "camera": {"width": 10,,}}')
    assert module_error(lambda: pdflab.Scene.load(str(broken))) == \
        cli_error("render", "--scene", broken, "--strategy", "cosine", "--spp", 1, "--out", out)
    # A size over the pixel budget.
    assert module_error(lambda: pdflab.render(BOOK, "cosine", spp=1, width=8192, height=8192)) == \
        cli_error(*render, "--strategy", "cosine", "--width", 8192, "--height", 8192, "--out", out)
    # A light technique in a scene without a light.
    dark = json.load(open(BOOK))
    dark["objects"] = [o for o in dark["objects"] if o["material"] != "light"]
    for o in dark["objects"]:
        o.pop("importance", None)
    (tmp_path / "dark.json").write_text(json.dumps(dark))
    assert module_error(lambda: pdflab.render(pdflab.Scene.from_dict(dark, str(tmp_path / "dark.json")), "light",
                                              spp=1)) == \
        cli_error("render", "--scene", tmp_path / "dark.json", "--strategy", "light", "--spp", 1, "--out", out)
    # Image files: an unknown format, a folder that is not there.
    film = pdflab.render(BOOK, "cosine", spp=1, width=8, height=8, progress=False)
    for bad in [str(tmp_path / "x.bmp"), str(tmp_path / "no" / "x.pfm")]:
        assert module_error(lambda: film.save(bad)) == cli_error(*render, "--strategy", "cosine", "--out", bad)
        assert not os.path.exists(bad)
    # A camera value the scene loader refuses, as it refuses it in a file.
    scene = pdflab.Scene.load(BOOK)
    wide = json.load(open(BOOK))
    wide["camera"]["vfov"] = 200
    (tmp_path / "wide.json").write_text(json.dumps(wide))
    message = module_error(lambda: setattr(scene.camera, "vfov", 200))
    assert message.replace(BOOK, "FILE") == \
        cli_error("render", "--scene", tmp_path / "wide.json", "--strategy", "cosine", "--spp", 1, "--out",
                  out).replace(str(tmp_path / "wide.json"), "FILE")
    assert scene.camera.vfov == 40  # a refused value changes nothing


def test_scene_properties_and_dicts():
    scene = pdflab.Scene.load(BOOK)
    assert scene.path == BOOK and scene.size == (600, 600) and scene.max_depth == 50
    same = pdflab.Scene.from_dict(scene.to_dict())
    assert same.content_hash == scene.content_hash and same.path is None
    scene.width, scene.height = 40, 30
    assert scene.size == (40, 30) and scene.content_hash == same.content_hash  # size is keyed apart
    scene.camera.lookfrom = [278, 278, -700]
    assert scene.camera.lookfrom == [278, 278, -700] and scene.content_hash != same.content_hash
    assert scene.edited and not same.edited
    moved = pdflab.render(scene, "cosine", spp=2, progress=False)
    assert (moved.width, moved.height) == (40, 30)
    same.camera = {"lookfrom": [278, 278, -700], "width": 40, "height": 30}
    again = pdflab.render(same, "cosine", spp=2, progress=False)
    assert np.array_equal(moved.mean, again.mean)
    assert pdflab.scene_path("cornell_book") == os.path.join(SOURCE_DIR, "assets", "scenes", "cornell_book.json") \
        or os.path.samefile(pdflab.scene_path("cornell_book"), BOOK)
    assert "small_light" in pdflab.scenes()
