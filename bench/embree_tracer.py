#!/usr/bin/env python3
"""Exact mode against an independent Embree tracer ("exact mode is at most the time of
an independent Embree tracer on the same machine"; docs/complexity.md).

bench/embree_tracer.cpp reads reference scenes with the reference tracer's parser and renders
them with Embree as a user of Embree would: `user` (balls and flat cylinders as user geometry,
intersected in double, as exact mode does) and `native` (Embree's own float spheres and capped
cones), each one ray at a time or in packets of 8. For each scene, renders are interleaved round
by round (exact mode, then each tracer) at 2 threads; the median render time is reported, with
each tracer's PSNR against exact mode (the same picture: user geometry gives images identical to
exact mode's, native differs by float rounding).

Scenes: Plates 4 and 5; the costly-primitive ball of 400 tufts of 216 parts, and the same ball and floor
without instances (the scene around the instances, b in docs/complexity.md); the complexity
benchmark's tuft2000 on Plate 4's placement. (CSG primitives are not in the reference format.)
Writes RESULTS/embree_tracer.json and prints a Markdown summary.

usage: embree_tracer.py LATTICE TRACER RESULTS [--work DIR] [--runs N]"""
import argparse
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
import complexity_scenes  # noqa: E402

# Tracer configurations: label -> arguments. Packets: a row's 8 pixels through rtcIntersect8,
# their shadow rays through rtcOccluded8 (user geometry's callbacks take the 8 lanes).
TRACERS = {"user": ["--geometry", "user"], "user, packets": ["--geometry", "user", "--packets"],
           "native": ["--geometry", "native"],
           "native, packets": ["--geometry", "native", "--packets"]}


def write_scenes(work):
    """name -> path: the plates as shipped, the ball scenes and tuft2000 as complexity_scenes.py
    writes them, and the ball and floor alone."""
    os.makedirs(work, exist_ok=True)
    paths = {n: os.path.join(ROOT, "examples", n + ".json")
             for n in ["plate4-fuzzy-sphere-1000", "plate5-fuzzy-sphere-5000"]}
    tuft_ball = complexity_scenes.scene("ball-tuft216", 512)
    base = dict(tuft_ball, primitives={}, objects=tuft_ball["objects"][:2],
                description="the costly-primitive ball and floor without instances")
    for name, s in [("ball-base", base), ("ball-tuft216", tuft_ball),
                    ("tuft2000", complexity_scenes.scene("tuft2000", 512))]:
        paths[name] = os.path.join(work, name + ".json")
        with open(paths[name], "w") as f:
            json.dump(s, f, separators=(",", ":"))
    return paths


def exact_ms(lattice, scene, image, stats):
    subprocess.run([lattice, "render", "-q", scene, "-o", image, "--mode", "exact",
                    "--threads", "2", "--stats", stats], check=True)
    return json.load(open(stats))["render_ms"]


def tracer_ms(tracer, scene, image, args):
    out = subprocess.run([tracer, scene, "-o", image, *args, "--threads", "2"],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)["render_ms"]


def psnr(lattice, a, b):
    out = subprocess.run([lattice, "compare", a, b, "--json"], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)["psnr_db"]


def measure(lattice, tracer, name, scene, work, runs):
    times = {"exact": [], **{g: [] for g in TRACERS}}
    img = {k: os.path.join(work, f"{name}-{k.replace(', ', '-')}.png") for k in times}
    for _ in range(runs):
        times["exact"].append(exact_ms(lattice, scene, img["exact"], os.path.join(work, "stats.json")))
        for g, args in TRACERS.items():
            times[g].append(tracer_ms(tracer, scene, img[g], args))
    return {"scene": name, "runs": runs,
            "median_ms": {k: statistics.median(v) for k, v in times.items()},
            "psnr_vs_exact": {g: psnr(lattice, img[g], img["exact"]) for g in TRACERS}}


def fmt_db(v):
    return "identical" if v == "inf" else f"{v:.1f} dB"


def report(results):
    print("## Exact mode against an independent Embree tracer\n")
    print("512 x 512, 1 spp, 2 threads, median render time of interleaved rounds (each tracer's "
          "PSNR against exact mode in brackets); last column: exact mode's time over the fastest "
          "tracer's (at most 1: exact mode is at most the independent tracer's time).\n")
    print("| scene | exact mode | " + " | ".join(f"Embree, {g}" for g in TRACERS) +
          " | exact / fastest |")
    print("| --- | ---: | " + " | ".join("---:" for _ in TRACERS) + " | ---: |")
    for r in results:
        m, p = r["median_ms"], r["psnr_vs_exact"]
        cells = [f"{m[g]:.0f} ms ({fmt_db(p[g])})" for g in TRACERS]
        print(f"| {r['scene']} | {m['exact']:.0f} ms | " + " | ".join(cells) +
              f" | {m['exact'] / min(m[g] for g in TRACERS):.2f} |")
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("lattice")
    ap.add_argument("tracer")
    ap.add_argument("results")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "embree_tracer"))
    ap.add_argument("--runs", type=int, default=7)
    a = ap.parse_args()
    results = [measure(a.lattice, a.tracer, name, path, a.work, a.runs)
               for name, path in write_scenes(a.work).items()]
    with open(os.path.join(a.results, "embree_tracer.json"), "w") as f:
        json.dump(results, f, indent=1)
    report(results)


if __name__ == "__main__":
    main()
