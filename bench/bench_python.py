"""The Python module's overhead against the command line for one render.

Renders the same image (the book's box, the book's mixture, one seed) with
`pdflab render --out x.pfm` and with pdflab.render(...).save("x.pfm"),
alternately, so that both see the same load on the machine, and prints each
pair's ratio (module / command line) and their median. The command line's time
is its whole process (start, scene, render, PFM); the module's is Scene.load,
render and save in a warm interpreter. The render's own seconds (what the
command line prints, film.seconds) are compared too. Both images must be the
same bits. So is the CPU time each spent (all its threads), which the
machine's other load disturbs less than the wall clock.

    PYTHONPATH=build/release/python /usr/bin/python3 bench/bench_python.py [--spp N] [--pairs K]

--spp defaults to what takes about one second here (measured first).
"""

import argparse
import hashlib
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import pdflab

here = os.path.dirname(os.path.abspath(__file__))
source = os.path.dirname(here)
parser = argparse.ArgumentParser()
parser.add_argument("--binary", default=os.path.join(source, "build", "release", "app", "pdflab"))
parser.add_argument("--scene", default=os.path.join(source, "assets", "scenes", "cornell_book.json"))
parser.add_argument("--strategy", default="mix:cosine=0.5,light=0.5")
parser.add_argument("--size", type=int, default=300)
parser.add_argument("--spp", type=int, default=0, help="0: what takes about --seconds")
parser.add_argument("--seconds", type=float, default=1.0)
parser.add_argument("--pairs", type=int, default=10)
parser.add_argument("--threads", type=int, default=0)
args = parser.parse_args()

work = tempfile.mkdtemp()
common = ["--scene", args.scene, "--strategy", args.strategy, "--width", str(args.size), "--height", str(args.size),
          "--seed", "7", "--threads", str(args.threads), "--quiet"]


def cpu(who):
    usage = resource.getrusage(who)
    return usage.ru_utime + usage.ru_stime


def module_run(spp, out):
    cpu_start, start = cpu(resource.RUSAGE_SELF), time.perf_counter()
    film = pdflab.render(pdflab.Scene.load(args.scene), args.strategy, spp=spp, width=args.size, height=args.size,
                         seed=7, threads=args.threads, progress=False)
    film.save(out)
    return time.perf_counter() - start, film.seconds, cpu(resource.RUSAGE_SELF) - cpu_start


def cli_run(spp, out):
    cpu_start, start = cpu(resource.RUSAGE_CHILDREN), time.perf_counter()
    done = subprocess.run([args.binary, "render", *common, "--spp", str(spp), "--out", out], check=True,
                          stdout=subprocess.PIPE, text=True)
    elapsed = time.perf_counter() - start
    # "N spp, WxH, S s, ..." : the render's own seconds.
    return elapsed, float(done.stdout.split(", ")[2].split()[0]), cpu(resource.RUSAGE_CHILDREN) - cpu_start


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


spp = args.spp
if spp == 0:
    _, seconds, _ = module_run(8, os.path.join(work, "probe.pfm"))
    spp = max(1, round(8 * args.seconds / seconds))
print("%s, %dx%d, %s, %d spp, %s threads; %d pairs, alternating (the first of each pair alternates too)" %
      (os.path.basename(args.scene), args.size, args.size, args.strategy, spp, args.threads or "all", args.pairs))
ratios, render_ratios, cpu_ratios, cli_times, module_times = [], [], [], [], []
for k in range(args.pairs):
    a, b = os.path.join(work, "cli.pfm"), os.path.join(work, "module.pfm")
    if k % 2 == 0:
        t_cli, r_cli, c_cli = cli_run(spp, a)
        t_module, r_module, c_module = module_run(spp, b)
    else:
        t_module, r_module, c_module = module_run(spp, b)
        t_cli, r_cli, c_cli = cli_run(spp, a)
    assert digest(a) == digest(b), "the module's image differs from the command line's"
    cli_times.append(t_cli)
    module_times.append(t_module)
    ratios.append(t_module / t_cli)
    render_ratios.append(r_module / r_cli)
    cpu_ratios.append(c_module / c_cli)
    print("pair %2d: command line %.3f s (render %.2f s, CPU %.2f s), module %.3f s (render %.3f s, CPU %.2f s): "
          "ratio %.4f, renders %.4f, CPU %.4f" % (k + 1, t_cli, r_cli, c_cli, t_module, r_module, c_module,
                                                  t_module / t_cli, r_module / r_cli, c_module / c_cli))
print("median: command line %.3f s, module %.3f s; ratio module / command line: median %.4f, range %.4f..%.4f" %
      (statistics.median(cli_times), statistics.median(module_times), statistics.median(ratios), min(ratios),
       max(ratios)))
print("the renders' own seconds, module / command line: median %.4f, range %.4f..%.4f" %
      (statistics.median(render_ratios), min(render_ratios), max(render_ratios)))
print("CPU time, module / command line: median %.4f, range %.4f..%.4f" %
      (statistics.median(cpu_ratios), min(cpu_ratios), max(cpu_ratios)))
print("same bits in every pair; load average %s" % " ".join(open("/proc/loadavg").read().split()[:3]))
