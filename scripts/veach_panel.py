#!/usr/bin/env python3
"""Four renders of the same size side by side, 2 x 2, as one PNG (the book's
gamma-2 transfer, as `pdflab render --out x.png`): the Veach figure.

  scripts/veach_panel.py OUT.png TOP_LEFT.pfm TOP_RIGHT.pfm BOTTOM_LEFT.pfm BOTTOM_RIGHT.pfm

Pure Python (struct, zlib): no numpy or PIL needed."""
import math
import struct
import sys
import zlib

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from veach_table import read_pfm  # noqa: E402

GAP = 4


def byte(x):
    x = 0.0 if not x > 0.0 else min(1.0, x)
    return int(255.999 * math.sqrt(x))


def png(path, w, h, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def main():
    out, paths = sys.argv[1], sys.argv[2:6]
    images = [read_pfm(p) for p in paths]
    w, h = images[0][0], images[0][1]
    W, H = 2 * w + GAP, 2 * h + GAP
    rows = [[255] * (3 * W) for _ in range(H)]
    for k, (_, _, img) in enumerate(images):
        ox, oy = (k % 2) * (w + GAP), (k // 2) * (h + GAP)
        for y in range(h):
            row = rows[oy + y]
            src = img[y]
            for i in range(3 * w):
                row[3 * ox + i] = byte(src[i])
    png(out, W, H, rows)


if __name__ == "__main__":
    main()
