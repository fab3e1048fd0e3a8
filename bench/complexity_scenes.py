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

Besides, the class of scene the costly-primitive comparison is made on:
several hundred instances on a ball, here 400 placed evenly (a Fibonacci spiral), each turned
at random about the ball's normal, filling most of the frame, so that the instances, not the
ball and floor, take most of the time. Two primitives:

  ball-csg7      six tilted tori (major radius 3, minor 0.35) centred in an 8^3 box, minus a
                 sphere: 7 quartic leaves
  ball-tuft216   a tuft of 24 strands of 5 spheres and 4 cylinders (radius 0.15): 216 parts

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


def ball_csg():
    rng = random.Random(3)
    tori = []
    for _ in range(6):
        a = [rng.gauss(0, 1) for _ in range(3)]
        norm = math.sqrt(sum(x * x for x in a))
        tori.append(torus([x / norm for x in a], 3.0, 0.35, (4, 4, 4)))
    bite = {"type": "sphere", "center": [4, 4, 6.5], "radius": 1.8}
    obj = {"type": "csg", "op": "difference",
           "children": [{"type": "csg", "op": "union", "children": tori}, bite]}
    return {"object": obj, "lattice": {"sigma": 1.0, "cells": [8, 8, 8]}}


PRIMITIVES = {"hair19": (hair, 19)}
PRIMITIVES.update({k: ((lambda s=s, n=n, r=r, k=k: tuft(s, n, r, seed=len(k))), s * (2 * n - 1))
                   for k, (s, n, r) in TUFTS.items()})
PRIMITIVES.update({f"csg{q}": ((lambda q=q: csg(q)), q) for q in (1, 4, 12)})


# name -> (primitive, parts or leaves, the target: exact / lattice at least this).
CHECKS = {"ball-csg7": (ball_csg, 7, 5.0),
          "ball-tuft216": ((lambda: tuft(24, 5, 0.15, seed=7)), 216, 2.0)}
BALL_RADIUS, BALL_INSTANCES = 40.0, 400


def ball_transforms(n, seed=5):
    """n lattice boxes standing on a ball: local (4, 4, 0) at the surface (a little below it,
    so that no gap shows), local z along the normal, turned at random about it."""
    rng = random.Random(seed)
    out = []
    golden = math.pi * (3 - math.sqrt(5))
    for i in range(n):
        z = 1 - 2 * (i + 0.5) / n
        r = math.sqrt(1 - z * z)
        nrm = (r * math.cos(golden * i), r * math.sin(golden * i), z)
        a = (1, 0, 0) if abs(nrm[0]) < 0.9 else (0, 1, 0)
        e1 = cross(a, nrm)
        e1 = [x / math.sqrt(sum(y * y for y in e1)) for x in e1]
        e2 = cross(nrm, e1)
        phi = rng.uniform(0, 2 * math.pi)
        u = [math.cos(phi) * p + math.sin(phi) * q for p, q in zip(e1, e2)]
        v = [-math.sin(phi) * p + math.cos(phi) * q for p, q in zip(e1, e2)]
        t = [BALL_RADIUS * nrm[k] - 4 * u[k] - 4 * v[k] - 0.5 * nrm[k] for k in range(3)]
        out.append([[round(u[k], 6), round(v[k], 6), round(nrm[k], 6), round(t[k], 6)]
                    for k in range(3)])
    return out


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def ball_scene(name, size):
    s = json.load(open(PLATE4))
    s["camera"] = {"eye": [0, -250, 70], "look_at": [0, 0, 0], "up": [0, 0, 1],
                   "fov_y_deg": 28, "width": size, "height": size}
    s["primitives"] = {name: CHECKS[name][0]()}
    ball, floor = [o for o in s["objects"] if o["type"] != "instance"]
    ball.update(center=[0, 0, 0], radius=BALL_RADIUS)
    s["objects"] = [ball, floor] + [
        {"type": "instance", "primitive": name, "transform": m, "material": "fur"}
        for m in ball_transforms(BALL_INSTANCES)]
    s["description"] = (f"the costly-primitive check class: {BALL_INSTANCES} instances of {name} "
                        f"({CHECKS[name][1]} parts or quartic leaves) on a ball; "
                        "bench/complexity_scenes.py")
    return s


def scene(name, size):
    if name in CHECKS:
        return ball_scene(name, size)
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
    for name in (a.only.split(",") if a.only else list(PRIMITIVES) + list(CHECKS)):
        path = os.path.join(a.out, name + ".json")
        with open(path, "w") as f:
            json.dump(scene(name, a.size), f, separators=(",", ":"))
        print(path)


if __name__ == "__main__":
    main()
