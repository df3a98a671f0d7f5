#!/usr/bin/env python3
"""Writes the sun-and-sky environment map that assets/scenes/sun_sky.json uses.

A lat-long map (docs/environment.md: row 0 is the zenith, +y; column x covers
azimuth 2 pi x / W to 2 pi (x + 1) / W from +x towards +z) of a sky whose
radiance goes from a blue zenith to a bright horizon, a dark ground below the
horizon, and a small, very bright sun: a disc of angular radius SUN_RADIUS
degrees whose texels hold the disc's share of their solid angle times its
radiance (so the map's power is the sun's, at any resolution). Written as a
Radiance .hdr (RGBE, run-length scanlines) with the standard library alone.

    python3 scripts/make_sky.py [OUT.hdr] [--width W] [--sun-radius DEG]
"""
import argparse
import math
import struct

SUN_ELEVATION = 35.0   # degrees above the horizon
SUN_AZIMUTH = 60.0     # degrees from +x towards +z
SUN_RADIUS = 0.8       # degrees (the real sun's is 0.27)
SUN_RADIANCE = (22000.0, 20000.0, 17000.0)
ZENITH = (0.18, 0.32, 0.75)
HORIZON = (0.85, 0.9, 1.0)
GROUND = (0.06, 0.055, 0.05)


def direction(theta, phi):
    s = math.sin(theta)
    return (s * math.cos(phi), math.cos(theta), s * math.sin(phi))


def sky(theta):
    elevation = math.pi / 2 - theta
    if elevation < 0.0:
        return GROUND
    t = math.pow(1.0 - elevation / (math.pi / 2), 3.0)  # 0 at the zenith, 1 at the horizon
    return tuple(z + (h - z) * t for z, h in zip(ZENITH, HORIZON))


def make(width, height, sun_radius_deg):
    el, az = math.radians(SUN_ELEVATION), math.radians(SUN_AZIMUTH)
    sun = direction(math.pi / 2 - el, az)
    cos_sun = math.cos(math.radians(sun_radius_deg))
    near = math.cos(math.radians(sun_radius_deg) + 2.0 * math.pi / height + 2.0 * math.pi / width)
    rows = []
    sub = 16
    for y in range(height):
        row = []
        for x in range(width):
            theta = math.pi * (y + 0.5) / height
            phi = 2.0 * math.pi * (x + 0.5) / width
            c = sky(theta)
            d = direction(theta, phi)
            if sum(a * b for a, b in zip(d, sun)) > near:
                # The disc's share of the texel's solid angle, by sub x sub
                # points uniform in (cos theta, phi) (uniform in solid angle).
                z0, z1 = math.cos(math.pi * y / height), math.cos(math.pi * (y + 1) / height)
                inside = 0
                for i in range(sub):
                    z = z0 + (z1 - z0) * (i + 0.5) / sub
                    r = math.sqrt(max(0.0, 1.0 - z * z))
                    for j in range(sub):
                        p = 2.0 * math.pi * (x + (j + 0.5) / sub) / width
                        if r * math.cos(p) * sun[0] + z * sun[1] + r * math.sin(p) * sun[2] >= cos_sun:
                            inside += 1
                f = inside / (sub * sub)
                c = tuple(a * (1.0 - f) + s * f for a, s in zip(c, SUN_RADIANCE))
            row.append(c)
        rows.append(row)
    return rows


def rgbe(c):
    m = max(c)
    if m < 1e-32:
        return (0, 0, 0, 0)
    mantissa, exponent = math.frexp(m)
    scale = mantissa * 256.0 / m
    return (int(c[0] * scale), int(c[1] * scale), int(c[2] * scale), exponent + 128)


def write_hdr(path, rows):
    height, width = len(rows), len(rows[0])
    out = bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
    out += ("-Y %d +X %d\n" % (height, width)).encode()
    for row in rows:
        pixels = [rgbe(c) for c in row]
        out += struct.pack("BBBB", 2, 2, width >> 8, width & 255)
        for channel in range(4):
            values = [p[channel] for p in pixels]
            for start in range(0, width, 128):  # literal runs of at most 128
                chunk = values[start:start + 128]
                out.append(len(chunk))
                out += bytes(chunk)
    with open(path, "wb") as f:
        f.write(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="assets/environments/sun_sky.hdr")
    parser.add_argument("--width", type=int, default=256, help="texels around (the height is half)")
    parser.add_argument("--sun-radius", type=float, default=SUN_RADIUS, help="the sun's angular radius, degrees")
    args = parser.parse_args()
    if args.width < 8 or args.width % 2:
        parser.error("--width must be an even number >= 8")
    write_hdr(args.out, make(args.width, args.width // 2, args.sun_radius))


if __name__ == "__main__":
    main()
