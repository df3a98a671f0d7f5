#!/usr/bin/env python3
"""Veach's table: the relMSE of each plate (and of each plate-light pair) of
assets/scenes/veach_mis.json under each estimator, from renders that
`pdflab render` wrote as .pfm and a reference `pdflab reference --out` wrote.

  scripts/veach_table.py REFERENCE.pfm LABEL=RUN.pfm[,RUN.pfm...] ...

relMSE is pdflab's (renderer/metrics/metrics.h): the mean over the region's
pixels and channels of (x - r)^2 / (r^2 + 0.01), averaged over a label's runs
(seeds). The regions are the plates' bands of rows in the 384x288 image (the
scene's; their rows are where the camera sees each plate's centre line, less
two rows each side) and, for the pairs, the quarter of the width that holds
one light's highlight. Pure Python: no numpy needed."""
import struct
import sys

EPS = 1e-2
# (name, alpha, first row, last row) top-down, from the scene's geometry.
PLATES = [("top, alpha 0.005", 130, 153), ("alpha 0.025", 160, 182), ("alpha 0.07", 195, 217), ("bottom, alpha 0.2", 237, 261)]
LIGHTS = ["r 0.03", "r 0.1", "r 0.3", "r 0.9"]


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind != b"PF":
            raise SystemExit(f"{path}: not a colour PFM")
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = f.read()
    fmt = ("<" if scale < 0 else ">") + "f" * (w * h * 3)
    values = struct.unpack(fmt, data[: w * h * 12])
    # PFM rows run bottom to top: flip to top-down.
    rows = [values[(h - 1 - y) * w * 3 : (h - y) * w * 3] for y in range(h)]
    return w, h, rows


def rel_mse(img, ref, y0, y1, x0, x1):
    total, n = 0.0, 0
    for y in range(y0, y1 + 1):
        a, r = img[y], ref[y]
        for i in range(3 * x0, 3 * x1):
            d = a[i] - r[i]
            total += d * d / (r[i] * r[i] + EPS)
            n += 1
    return total / n


def main():
    w, h, ref = read_pfm(sys.argv[1])
    labels = []
    for arg in sys.argv[2:]:
        label, runs = arg.split("=", 1)
        labels.append((label, [read_pfm(p)[2] for p in runs.split(",")]))
    quarter = w // 4
    plate_table = {}
    pair_table = {}
    for label, runs in labels:
        for pi, (name, y0, y1) in enumerate(PLATES):
            plate_table[(label, pi)] = sum(rel_mse(r, ref, y0, y1, 0, w) for r in runs) / len(runs)
            for li in range(4):
                pair_table[(label, pi, li)] = sum(rel_mse(r, ref, y0, y1, li * quarter, (li + 1) * quarter) for r in runs) / len(runs)
    names = [l for l, _ in labels]
    print("| plate | " + " | ".join(names) + " |")
    print("|---|" + "---|" * len(names))
    for pi, (name, _, _) in enumerate(PLATES):
        best = min(plate_table[(l, pi)] for l in names)
        cells = [("**%.3g**" if plate_table[(l, pi)] == best else "%.3g") % plate_table[(l, pi)] for l in names]
        print(f"| {name} | " + " | ".join(cells) + " |")
    print()
    print("| plate, light | " + " | ".join(names) + " | power / best single |")
    print("|---|" + "---|" * (len(names) + 1))
    for pi, (name, _, _) in enumerate(PLATES):
        for li, light in enumerate(LIGHTS):
            vals = {l: pair_table[(l, pi, li)] for l in names}
            best = min(vals.values())
            cells = [("**%.3g**" if vals[l] == best else "%.3g") % vals[l] for l in names]
            singles = [vals[l] for l in names[:2]]
            ratio = vals[names[-1]] / min(singles)
            print(f"| {name}, {light} | " + " | ".join(cells) + f" | {ratio:.2f} |")


if __name__ == "__main__":
    main()
