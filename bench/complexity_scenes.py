#!/usr/bin/env python3
"""Scenes for the complexity benchmark (bench/complexity.py, docs/complexity.md).

Every scene is Plate 4 (examples/plate4-fuzzy-sphere-1000.json): the same camera, lights,
sphere, floor and the same 1000 instance transforms; only the primitive changes, so time
differences come from the primitive alone. Every primitive lives in the Plate 4 hair's
lattice box, 7 x 7 x 20 cells of sigma = 1, and fills roughly the same column, so each
covers about as many pixels as the hair and the lattice's cost per visit stays comparable.

  hair19         the Plate 3/4 hair: 10 spheres + 9 cylinders
  tuft200 ...    strands of chained spheres and cylinders (parts = strands x (2n - 1))
  csg1, 4, 12    CSG of tori stretched along the column: one torus, a 4-leaf unit (a torus
                 minus a torus, union the intersection of two tori), three such units

Usage: complexity_scenes.py OUT_DIR [--size N] [--only NAME,...]; prints the written paths.
Python 3 standard library only; the output is deterministic (fixed seeds)."""
import argparse
import json
import math
import os
import random

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PLATE4 = os.path.join(ROOT, "examples", "plate4-fuzzy-sphere-1000.json")
BOX = (7.0, 7.0, 20.0)  # the Plate 4 hair's lattice box, sigma = 1
LATTICE = {"sigma": 1.0, "cells": [7, 7, 20]}

# name -> (strands, spheres per strand, radius). Parts = strands * (2 n - 1). Thinner
# strands as they get more numerous, so the tuft stays a tuft and not a solid block.
TUFTS = {"tuft200": (8, 13, 0.30), "tuft2000": (80, 13, 0.12), "tuft10000": (400, 13, 0.06)}


def hair():
    return json.load(open(PLATE4))["primitives"]["hair"]


def tuft(strands, n, r, seed):
    """Strands rooted in a disc at the bottom of the box, rising with a random lean and
    wiggle to different heights; each is n spheres chained by n - 1 cylinders of radius r."""
    rng = random.Random(seed)
    lo, hi = r + 0.02, BOX[0] - r - 0.02  # keep every part inside the box (x and y)
    spheres, cylinders = [], []
    for _ in range(strands):
        a, d = rng.uniform(0, 2 * math.pi), 2.6 * math.sqrt(rng.random())
        x, y = 3.5 + d * math.cos(a), 3.5 + d * math.sin(a)
        lean = rng.uniform(0, 2 * math.pi)
        top = rng.uniform(14.0, BOX[2] - r - 0.02)
        dz = (top - r) / (n - 1)
        for k in range(n):
            if k:
                x += 0.25 * math.cos(lean) + rng.uniform(-0.3, 0.3)
                y += 0.25 * math.sin(lean) + rng.uniform(-0.3, 0.3)
                x, y = min(max(x, lo), hi), min(max(y, lo), hi)
                cylinders.append([len(spheres) - 1, len(spheres), r])
            spheres.append([round(x, 6), round(y, 6), round(r + k * dz, 6), r])
    return {"spheres": spheres, "cylinders": cylinders, "lattice": LATTICE}


def torus(axis, major, minor, center=(0, 0, 0)):
    return {"type": "torus", "center": list(center), "axis": list(axis),
            "major_radius": major, "minor_radius": minor}


def unit4():
    """Four tori around the origin, within |x|, |y| < 3.45 and |z| < 3.3: a standing ring cut
    in two arcs by a horizontal ring, and a flat ring (two offset tori intersected)."""
    arcs = {"type": "csg", "op": "difference",
            "children": [torus((1, 0, 0), 2.6, 0.6), torus((0, 0, 1), 2.6, 0.8)]}
    flat = {"type": "csg", "op": "intersection",
            "children": [torus((0, 1, 0), 2.4, 0.75), torus((0, 1, 0), 2.4, 0.75, (0, 0.5, 0))]}
    return {"type": "csg", "op": "union", "children": [arcs, flat]}


def placed(obj, zscale, z, rotate_deg=0):
    # Only scales along z, turns by multiples of 90 degrees about z and translates (the
    # renderer bounds a placed torus by its exact extent, so any transform would do).
    ops = [{"scale": [1, 1, zscale]}]
    if rotate_deg:
        ops.append({"rotate": {"axis": [0, 0, 1], "angle_deg": rotate_deg}})
    ops.append({"translate": [BOX[0] / 2, BOX[1] / 2, z]})
    return dict(obj, transform=ops)


def csg(leaves):
    if leaves == 1:  # a standing ring stretched to the column's height
        obj = placed(torus((1, 0, 0), 2.6, 0.6), 2.9, 10.0)
    elif leaves == 4:
        obj = placed(unit4(), 2.9, 10.0)
    else:  # three such units in the same column (one turned by 90 degrees, one narrower):
        # about the silhouette of csg4, so that the leaves, not the size, make the difference
        units = [placed(unit4(), 2.9, 10.0), placed(unit4(), 2.9, 10.0, 90),
                 dict(placed(unit4(), 2.9, 10.0), transform=[
                     {"scale": [0.7, 0.7, 2.9]}, {"translate": [BOX[0] / 2, BOX[1] / 2, 10.0]}])]
        obj = {"type": "csg", "op": "union", "children": units}
    return {"object": obj, "lattice": LATTICE}


PRIMITIVES = {"hair19": (hair, 19)}
PRIMITIVES.update({k: ((lambda s=s, n=n, r=r, k=k: tuft(s, n, r, seed=len(k))), s * (2 * n - 1))
                   for k, (s, n, r) in TUFTS.items()})
PRIMITIVES.update({f"csg{q}": ((lambda q=q: csg(q)), q) for q in (1, 4, 12)})


def scene(name, size):
    s = json.load(open(PLATE4))
    s["camera"]["width"] = s["camera"]["height"] = size
    s["primitives"] = {name: PRIMITIVES[name][0]()}
    for o in s["objects"]:
        if o["type"] == "instance":
            o["primitive"] = name
    s["description"] = (f"complexity benchmark: Plate 4 placement with primitive {name} "
                        f"({PRIMITIVES[name][1]} parts or quartic leaves); bench/complexity_scenes.py")
    return s


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--size", type=int, default=512, help="image width and height")
    ap.add_argument("--only", default="", help="comma-separated primitive names")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    for name in (a.only.split(",") if a.only else PRIMITIVES):
        path = os.path.join(a.out, name + ".json")
        with open(path, "w") as f:
            json.dump(scene(name, a.size), f, separators=(",", ":"))
        print(path)


if __name__ == "__main__":
    main()
