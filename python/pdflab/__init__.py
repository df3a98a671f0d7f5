"""pdflab in Python: the renderer library of the pdflab command line and viewer.

    import pdflab
    scene = pdflab.Scene.load(pdflab.scene_path("cornell_book"))
    film = pdflab.render(scene, "mix:cosine=0.5,light=0.5", spp=64, width=200, height=200)
    film.mean            # H x W x 3 float32: the values `pdflab render --out x.pfm` writes
    ref = pdflab.reference(scene, spp=1024, width=200, height=200)   # into the reference cache
    pdflab.relmse(film, ref)                                         # noise-corrected, with its interval

Bad input raises ValueError (pdflab.InputError) with the command line's message.
README.md's section "Python and notebooks" has the whole list.
"""

from . import _pdflab
from ._pdflab import (  # noqa: F401  (the public names)
    Camera,
    Film,
    InputError,
    IoError,
    Reference,
    Scene,
    __version__,
    asset_dir,
    chi_square,
    lab,
    pdf,
    reference_cache_dir,
    sample,
    scene_path,
    scenes,
    strategy,
    strategy_help,
    techniques,
    tonemap,
)
from ._progress import Progress
from ._rows import Rows

__all__ = [
    "Camera", "Film", "InputError", "IoError", "Reference", "RelMSE", "Rows", "Scene", "__version__",
    "asset_dir", "chi_square", "lab", "pdf", "predict_weights", "reference", "reference_cache_dir", "relmse",
    "render", "sample", "scene_path", "scenes", "strategy", "strategy_help", "sweep", "techniques", "tonemap",
]

def _image(self, transfer="gamma2", exposure=1.0):
    """The mean as 8-bit RGB (H x W x 3 uint8), tone-mapped as the PNG writer does: for plt.imshow."""
    return tonemap(self.mean, transfer, exposure)


Film.image = _image
Reference.image = _image

_warned = {}  # the warnings given, each once (warnings.warn_explicit's registry)

# How often a render is looked at: as the command line polls a quiet render,
# and as often as its progress bar is drawn.
_POLL_QUIET = 0.1
_POLL_PROGRESS = 0.2


def _scene(scene):
    """A Scene from a Scene or a path."""
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, str):
        return Scene.load(scene)
    import os
    if isinstance(scene, os.PathLike):
        return Scene.load(os.fspath(scene))
    raise TypeError("scene: give a pdflab.Scene or the path of a scene file, not %r" % (scene,))


def render(scene, strategy, spp=None, *, seconds=None, seed=1, width=None, height=None, threads=0, first_sample=0,
           rr=None, progress=None):
    """Renders `scene` with `strategy` and returns the Film.

    As `pdflab render --scene S --strategy STRATEGY --spp N [--seed K] [--width W --height H] [--threads T]
    [--first-sample K] [--rr=D]`: the same arguments give the same bits, for any thread count. `seconds`
    stops at a time instead (or first, with spp); the film then holds the passes that ended in time.
    `progress`: None shows a bar in a notebook or on a terminal, True always, False never.

    Ctrl+C (a notebook's interrupt) stops the render between passes: the film of the passes that ended is
    returned, with film.interrupted set. The GIL is released while the workers render.
    """
    handle = _pdflab._Render(_scene(scene), strategy, spp, seconds, seed, width, height, threads, first_sample,
                             rr or 0)
    if not handle.unbiased:
        # As the command line's note, once per strategy: "pdflab.render: UserWarning: strategy ... is biased".
        import warnings
        warnings.warn_explicit("strategy '%s' is biased: its pdf is zero for directions that miss the importance "
                               "targets, so it omits indirect light" % handle.strategy, UserWarning, "pdflab.render",
                               0, registry=_warned)
    bar = Progress("render", progress)
    interrupted = False
    try:
        poll = _POLL_PROGRESS if bar.shown else _POLL_QUIET
        while not handle.wait(poll):
            bar.update(_render_status(handle.stats()))
    except KeyboardInterrupt:
        interrupted = True
    film = handle.finish(interrupted)
    bar.close(_film_status(film))
    if interrupted:
        import sys
        print("pdflab: interrupted at %d of %s spp; the film holds them" %
              (film.spp, film.target_spp if film.target_spp else "?"), file=sys.stderr)
    return film


def _render_status(st):
    if st["target_spp"]:
        target = "%d/%d spp" % (st["spp"], st["target_spp"])
    else:
        target = "%d spp" % st["spp"]
    left = st["seconds"] * (1.0 - st["progress"]) / st["progress"] if st["progress"] > 0 else 0.0
    return st["progress"], "%s  %.1f s  %.2f M samples/s  ~%.0f s left" % (
        target, st["seconds"], st["samples_per_second"] * 1e-6, left)


def _film_status(film):
    return 1.0, "%d spp, %dx%d, %.2f s, %.3f M samples/s, %d threads, %d samples dropped%s" % (
        film.spp, film.width, film.height, film.seconds, film.samples_per_second * 1e-6, film.threads,
        film.dropped["total"], " (interrupted)" if film.interrupted else "")


def reference(scene, *, spp=None, seconds=None, target_relmse=None, strategy=None, seed_stream=0, width=None,
              height=None, max_depth=None, threads=0, cache_dir=None, out=None, rr=None, progress=None):
    """A converged reference of `scene` at its size (or width x height) and depth.

    With a goal (exactly one of spp, seconds, target_relmse) it renders one as `pdflab reference` does (an
    unbiased strategy, default the book's mixture; seeds reserved for references) and stores it in the cache
    (`cache_dir`, default $PDFLAB_REFERENCE_CACHE, else the user's cache folder), and in `out` (a .pfm) when
    given. Without a goal it is the cached one, as `--reference auto` finds it (ValueError when there is none,
    saying how to make one). Ctrl+C stops a render and raises KeyboardInterrupt (nothing is stored).
    """
    scene = _scene(scene)
    if spp is None and seconds is None and target_relmse is None:
        return _pdflab._cached_reference(scene, width, height, max_depth, cache_dir or "")
    build = _pdflab._ReferenceBuild(scene, spp, seconds, target_relmse, strategy or "", seed_stream, width, height,
                                    max_depth, threads, cache_dir or "", out or "", rr or 0)
    bar = Progress("reference", progress)
    import time
    try:
        while True:
            p = build.poll()
            if p["reached"]:
                break
            bar.update((p["fraction"], "%d spp  %.1f s  ~%.0f s left" % (p["spp"], p["seconds"], p["seconds_left"])))
            time.sleep(_POLL_PROGRESS if bar.shown else _POLL_QUIET / 2)
    except KeyboardInterrupt:
        bar.close((0.0, "stopped"))
        del build  # stops the workers
        raise
    ref = build.finish()
    bar.close((1.0, "%d spp, %.2f s, est. relMSE %.3g -> %s" % (ref.spp, ref.seconds, ref.estimated_relmse, ref.path)))
    return ref


class RelMSE(float):
    """relMSE against a reference, corrected for the reference's own noise: a float (the corrected value) with
    interval (95% half width), raw, reference_share, efficiency = 1 / (relMSE * seconds) and the rest of the
    figures `pdflab render --reference` prints (its --stats-json holds the same numbers)."""

    def __new__(cls, figures):
        self = super().__new__(cls, figures["value"])
        self.__dict__.update(figures)
        return self

    def __repr__(self):
        return "RelMSE(%.4g +- %.2g (95%%), raw %.4g, reference's share %.1f%%, efficiency %.4g)" % (
            self.value, self.interval, self.raw, 100.0 * self.reference_share, self.efficiency)


def relmse(film, reference, *, cache_dir=None):
    """relMSE of `film` against `reference` (a Reference, a .pfm/.exr path, or "auto": the cached reference of the
    film's scene at its size), corrected for the reference's own noise, with its 95% interval: the figure
    `pdflab render --reference` prints for the same render."""
    return RelMSE(_pdflab._relmse(film, reference, cache_dir or ""))


def _reference_option(reference):
    if isinstance(reference, Reference):
        return reference.path
    return str(reference)


def _table(rows, frame):
    """Rows as they are, or a pandas DataFrame when pandas is installed (frame=None) or asked for (True)."""
    if frame is False:
        return rows
    try:
        import pandas
    except ImportError:
        if frame:
            raise
        return rows
    return rows.to_frame(pandas)


def sweep(scene, vary, weights, *, strategy=None, seconds=None, spp=None, reference="auto", width=None, height=None,
          cache_dir=None, seeds=3, seed=2, threads=0, rr=None, auto=False, cpu_time=False, plot=None, map=None,
          frame=None, echo=False, progress=False):
    """Efficiency against the mixture weight of two techniques: `pdflab sweep` run in this process.

    vary "A,B", weights "LO:HI:STEP" (A's share of the pair), the rest as the command's options. Returns its CSV's
    rows (the columns of `pdflab sweep --csv`, numbers as numbers): a pandas DataFrame when pandas is installed,
    else a list of dicts (frame=False: always the list). The command's summary (best weight, predicted best, cost
    model) is in rows.summary (a DataFrame: .attrs["summary"]); echo=True prints it. progress=True writes a line
    per run on stderr, as the command does off a terminal. Ctrl+C stops the run in flight and raises
    KeyboardInterrupt (the rows so far are dropped).
    """
    scene = _scene(scene)
    csv_text, summary = _pdflab._sweep(scene, vary, weights, strategy or "", seconds, spp,
                                       _reference_option(reference), width, height, cache_dir or "", seeds, seed,
                                       threads, rr or 0, auto, cpu_time, plot or "", map or "", not progress)
    if echo:
        print(summary, end="")
    return _table(Rows.parse_csv(csv_text, summary), frame)


def predict_weights(scene, vary, *, strategy=None, weight=0.5, spp=16, seed=2, reference="auto", width=None,
                    height=None, cache_dir=None, grid=101, threads=0, rr=None, frame=None):
    """The efficiency of every mixture of two techniques predicted from paths drawn at one weight.

    Renders `spp` samples per pixel at A's share `weight` of the pair `vary` "A,B" (the others of `strategy` keep
    their weights), replays those very paths through the one-path tracer and reweights them to each of `grid`
    weights in [0, 1] (docs/measuring.md), priced by the render's time per sample. Rows: weight, strategy,
    relative_variance (of one sample per pixel), rays_per_sample, efficiency, largest_share (the largest path's
    share of the second moment; above 0.1 the prediction there is unreliable). rows.best_weight (a DataFrame:
    .attrs) is the predicted best; the other figures are attributes too. Ctrl+C during the pilot render stops it
    and raises KeyboardInterrupt (the replay of its paths, a few seconds at most, runs to its end first).
    """
    scene = _scene(scene)
    p = _pdflab._predict_weights(scene, vary, strategy or "", weight, spp, seed, _reference_option(reference), width,
                                 height, cache_dir or "", grid, threads, rr or 0)
    columns = ["weight", "strategy", "relative_variance", "rays_per_sample", "efficiency", "largest_share"]
    rows = Rows([dict(zip(columns, values)) for values in zip(*(p[c] for c in columns))])
    for key, value in p.items():
        if key not in columns:
            rows.attrs[key] = value
    return _table(rows, frame)
