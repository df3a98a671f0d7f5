"""The techniques on numpy arrays, the chi-square check and the 1D lab."""

import math

import numpy as np
import pytest

import pdflab
from conftest import cli, scene_file

BOOK = scene_file("cornell_book")


def test_the_technique_table_is_the_command_lines():
    table = pdflab.techniques()
    names = [t["name"] for t in table]
    assert names[:5] == ["cosine", "uniform-hemisphere", "uniform-sphere", "light", "light-sa"]
    help_text = cli("render", "--help").stdout
    for t in table:
        assert t["name"] in help_text and t["pdf"] in help_text
        assert t["unbiased_alone"] == pdflab.strategy(t["name"])["unbiased"]
    assert {t["name"]: t["unbiased_alone"] for t in table}["light"] is False
    assert {t["name"]: t["unbiased_alone"] for t in table}["cosine"] is True
    assert pdflab.strategy("mix:cosine=1,light=3")["weights"] == {"cosine": 0.25, "light": 0.75}


def test_cosine_samples_are_the_books_inverse_cdf():
    # The renderer's numbers are floats: u is rounded to float32 as it takes them.
    u = np.random.default_rng(7).random((2000, 2)).astype(np.float32).astype(np.float64)
    normal = np.array([0.0, 0.0, 1.0])
    directions, density, technique = pdflab.sample("cosine", normal, u)
    assert directions.shape == (2000, 3) and density.shape == (2000,) and (technique == 0).all()
    # The cosine lobe by its inverse CDF: cos(theta) = sqrt(1 - u1), phi = 2 pi u2.
    theta_cos = np.sqrt(1.0 - u[:, 0])
    expected = np.stack([np.sqrt(u[:, 0]) * np.cos(2 * np.pi * u[:, 1]),
                         np.sqrt(u[:, 0]) * np.sin(2 * np.pi * u[:, 1]), theta_cos], axis=1)
    assert np.allclose(directions, expected, atol=2e-6)
    assert np.allclose(density, theta_cos / np.pi, rtol=1e-5, atol=1e-7)
    assert np.allclose(pdflab.pdf("cosine", normal, directions), density, rtol=1e-6, atol=1e-7)
    # Any normal: the lobe turns with it.
    tilted = np.array([0.0, 0.6, 0.8])
    d, p, _ = pdflab.sample("cosine", tilted, u)
    assert np.allclose(d @ tilted, theta_cos, atol=2e-6)


def test_light_techniques_aim_from_a_point_of_the_scene():
    scene = pdflab.Scene.load(BOOK)
    origin, normal = np.array([278.0, 0.5, 278.0]), np.array([0.0, 1.0, 0.0])  # the floor's centre, facing up
    u = np.random.default_rng(3).random((500, 3))
    d, p, t = pdflab.sample("light", normal, u, origin=origin, scene=scene)
    assert (p > 0).all() and (t == 3).all()
    assert np.allclose(pdflab.pdf("light", normal, d, origin=origin, scene=scene), p, rtol=1e-4)
    mix = pdflab.sample("mix:cosine=0.5,light=0.5", normal, np.random.default_rng(4).random((4000, 4)),
                        origin=origin, scene=scene)
    assert set(np.unique(mix[2])) == {0, 3} and abs((mix[2] == 0).mean() - 0.5) < 0.05
    with pytest.raises(ValueError):
        pdflab.sample("light", normal, u)  # nothing to aim at without the scene
    with pytest.raises(ValueError, match="not a unit vector"):
        pdflab.pdf("cosine", [0.0, 0.0, 2.0], [0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match=r"not in \[0, 1\)"):
        pdflab.sample("cosine", normal, np.array([[0.5, 1.0]]))


def test_chi_square_at_a_pixel_and_at_a_point():
    scene = pdflab.Scene.load(BOOK)
    result = pdflab.chi_square("mix:cosine=0.5,light=0.5", (300, 500), scene=scene, samples=40000)
    assert result["passed"] and result["p_value"] > 0.01 and result["observed"].shape == (16, 32)
    assert result["observed"].sum() + result["empty_samples"] == 40000
    assert abs(result["integral"] - 1.0) < 1e-3
    point = pdflab.chi_square("cosine-power:20", (0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), samples=40000)
    assert point["passed"]
    with pytest.raises(ValueError, match="two directions"):
        pdflab.chi_square("nee-mis", (300, 500), scene=scene)


def test_the_1d_lab():
    lab = pdflab.lab
    assert [p["key"] for p in lab.pdfs()] == ["uniform", "linear", "quadratic", "mismatched"]
    u = np.linspace(0.0, 0.999, 101)
    for p in lab.pdfs():
        x = lab.inverse_cdf(p["key"], u)
        assert np.allclose(lab.cdf(p["key"], x), u, atol=1e-9)
    square = {f["key"]: f["exact"] for f in lab.integrands()}["square"]
    assert square == pytest.approx(8 / 3)
    est = lab.estimate("square", "uniform", n=20000, seed=3)
    assert abs(est["estimate"] - square) < 4 * est["standard_error"]
    assert est["running_estimate"][-1] == est["estimate"] and len(est["values"]) == 20000
    # A typed f(x) and a Python function give the built-in's values.
    typed = lab.estimate("x^2", "uniform", n=1000, seed=3)
    python = lab.estimate(lambda x: x * x, "uniform", n=1000, seed=3)
    builtin = lab.estimate("square", "uniform", n=1000, seed=3)
    assert typed["estimate"] == builtin["estimate"] == python["estimate"]
    # Importance sampling by the quadratic pdf: x^2 / (3 x^2 / 8) is constant, no variance at all.
    exact = lab.estimate("square", "quadratic", n=100, seed=1)
    assert exact["estimate"] == pytest.approx(square) and exact["standard_error"] < 1e-6
    assert lab.has_finite_variance("square", "linear") and not lab.has_finite_variance("cosine", "linear")
    assert lab.exact_integral("sin(pi*x)^2") == pytest.approx(1.0, abs=1e-8)
    with pytest.raises(ValueError, match="sin"):
        lab.f("sin(x", [0.5])
    assert abs(lab.estimate_pi(10000, stratified=True) - math.pi) < 0.01
