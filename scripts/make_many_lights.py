#!/usr/bin/env python3
"""Writes assets/scenes/many_lights.json: a room lit by many small emitters.

A closed room 10 wide, 4 high and 12 deep (x, y, z; the camera stands inside
near the wall at z = 0) with a table, a sofa and a shelf, lit by strings of
bulbs hung in sagging arcs across the ceiling (small spheres, warm and cool,
of powers that vary over a factor of ten) and a few bright lamps (larger
spheres on stands and one panel on the ceiling, emitting downwards). Every
emitter is a light nee-mis may choose: with hundreds of them a choice by power
alone sends most light samples to bulbs far from the point, which a light
tree (`light_choice`, docs/many_lights.md) avoids.

The bulbs' powers and colours come from a fixed pseudo-random sequence, so the
file is the same on every run.

    python3 scripts/make_many_lights.py [OUT.json] [--strings N] [--bulbs N]
"""
import argparse
import json
import math
import random

ROOM = (10.0, 4.0, 12.0)


def quad(q, u, v, material):
    return {"type": "quad", "q": list(q), "u": list(u), "v": list(v), "material": material}


def box(lo, hi, material):
    return {"type": "box", "min": list(lo), "max": list(hi), "material": material}


def sphere(c, r, material):
    return {"type": "sphere", "center": [round(x, 4) for x in c], "radius": r, "material": material}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default="assets/scenes/many_lights.json")
    ap.add_argument("--strings", type=int, default=6, help="strings of bulbs across the room")
    ap.add_argument("--bulbs", type=int, default=80, help="bulbs on each string")
    args = ap.parse_args()
    rng = random.Random(37)
    W, H, D = ROOM

    materials = {
        "wall": {"type": "lambertian", "albedo": [0.72, 0.70, 0.66]},
        "floor": {"type": "lambertian", "albedo": [0.45, 0.33, 0.24]},
        "ceiling": {"type": "lambertian", "albedo": [0.80, 0.80, 0.80]},
        "blue": {"type": "lambertian", "albedo": [0.15, 0.22, 0.45]},
        "wood": {"type": "lambertian", "albedo": [0.50, 0.32, 0.18]},
        "stand": {"type": "lambertian", "albedo": [0.20, 0.20, 0.20]},
        "lamp": {"type": "diffuse_light", "emit": [60.0, 52.0, 40.0]},
        "panel": {"type": "diffuse_light", "emit": [12.0, 12.0, 13.0]},
    }
    # Bulb materials: a handful of colours, each in a few powers (a factor of ten apart at most).
    colours = [(1.0, 0.78, 0.45), (1.0, 0.62, 0.30), (0.75, 0.85, 1.0), (1.0, 0.9, 0.75)]
    levels = [6.0, 15.0, 30.0, 60.0]
    for ci, c in enumerate(colours):
        for li, level in enumerate(levels):
            materials[f"bulb{ci}{li}"] = {"type": "diffuse_light", "emit": [round(level * x, 3) for x in c]}

    objects = [
        quad((0, 0, 0), (0, 0, D), (W, 0, 0), "floor"),      # floor, facing up
        quad((0, H, 0), (W, 0, 0), (0, 0, D), "ceiling"),    # ceiling, facing down
        quad((0, 0, D), (0, H, 0), (W, 0, 0), "wall"),       # back wall, facing -z
        quad((0, 0, 0), (W, 0, 0), (0, H, 0), "wall"),       # front wall (behind the camera), facing +z
        quad((0, 0, 0), (0, H, 0), (0, 0, D), "blue"),       # left wall, facing +x
        quad((W, 0, 0), (0, 0, D), (0, H, 0), "wall"),       # right wall, facing -x
        box((3.5, 0.0, 6.0), (6.5, 0.75, 7.6), "wood"),      # table
        box((0.4, 0.0, 2.5), (1.3, 0.9, 6.5), "blue"),       # sofa along the left wall
        box((8.8, 0.0, 8.0), (9.8, 2.2, 11.5), "wood"),      # shelf by the right wall
    ]
    # Lamps: bright spheres on stands, and one panel on the ceiling over the table.
    for x, z in [(1.0, 9.5), (9.0, 2.5), (2.0, 1.5)]:
        objects.append(box((x - 0.05, 0.0, z - 0.05), (x + 0.05, 1.5, z + 0.05), "stand"))
        objects.append(sphere((x, 1.65, z), 0.15, "lamp"))
    objects.append(quad((4.5, H - 0.01, 6.4), (1.0, 0, 0), (0, 0, 0.8), "panel"))  # u x v points down

    # Strings of bulbs: each hangs from wall to wall across x, sagging in the middle.
    bulbs = 0
    for s in range(args.strings):
        z = 1.0 + (D - 2.0) * (s + 0.5) / args.strings
        sag = 0.5 + 0.3 * rng.random()
        for b in range(args.bulbs):
            t = (b + 0.5) / args.bulbs
            x = 0.3 + (W - 0.6) * t
            y = H - 0.15 - sag * 4.0 * t * (1.0 - t)
            zz = z + 0.25 * math.sin(2.0 * math.pi * t * 3.0 + s)
            material = f"bulb{rng.randrange(len(colours))}{rng.randrange(len(levels))}"
            objects.append(sphere((x, y, zz), 0.03, material))
            bulbs += 1

    scene = {
        "name": "A room lit by many lights",
        "description": f"A room lit by {bulbs} bulbs on {args.strings} strings and four lamps "
                       "(scripts/make_many_lights.py). Choosing the emitter by power sends most light samples "
                       "to bulbs far from the point; the light tree, this scene's light choice, chooses by power, "
                       "distance and orientation.",
        "camera": {"width": 160, "height": 120, "vfov": 62, "lookfrom": [5.0, 1.7, 0.4], "lookat": [5.0, 1.9, 8.0],
                   "vup": [0, 1, 0], "max_depth": 5},
        # Hundreds of small lights: the scene asks for the light tree (a strategy's +lights:power overrides it).
        "light_choice": "tree",
        "materials": materials,
        "objects": objects,
    }
    with open(args.out, "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
