#!/usr/bin/env python3
"""Scatter benchmarks, through the lattice command on 2 threads:

1. fur on a mesh: examples/furry-bunny.json (14,696 triangles, 20,000 hairs) at 512 x 512, in
   exact and lattice mode (the table built beforehand, so the lattice figure is rendering only);
2. loading and building the acceleration structure for 100,000 scattered instances (the same
   scene with the count raised, rendered at 16 x 16 so that load + build is what is measured).

Each figure is the median of 3 runs, from `render --stats`. Prints Markdown; writes
scatter-runs.txt (the raw stats) beside it."""
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
RUNS = 3


def render(lattice, scene, work, *extra):
    stats = work / "stats.json"
    subprocess.run([lattice, "render", "-q", str(scene), "-o", str(work / "out.png"), "--threads", "2",
                    "--stats", str(stats), "--lattice-dir", str(work), *extra], check=True)
    return json.loads(stats.read_text())


def median_of(lattice, scene, work, *extra):
    runs = [render(lattice, scene, work, *extra) for _ in range(RUNS)]
    return {k: statistics.median(r[k] for r in runs) for k in ("load_ms", "build_ms", "render_ms", "total_ms")}, runs


def main(lattice, out):
    out = pathlib.Path(out)
    bunny = ROOT / "examples" / "furry-bunny.json"
    raw = []
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        render(lattice, bunny, work, "--mode", "lattice")  # builds the hair's table once
        rows = []
        for mode in ("exact", "lattice"):
            m, runs = median_of(lattice, bunny, work, "--mode", mode)
            raw += runs
            rows.append((f"furry bunny, {mode}", "512 x 512", m))
        scene = json.loads(bunny.read_text())
        scene["objects"][2]["count"] = 100000
        scene["camera"]["width"] = scene["camera"]["height"] = 16
        big = ROOT / "examples" / "_bench-100k.json"  # beside the mesh it names
        big.write_text(json.dumps(scene))
        try:
            for mode in ("exact", "lattice"):
                m, runs = median_of(lattice, big, work, "--mode", mode)
                raw += runs
                rows.append((f"100,000 hairs on the bunny, {mode}", "16 x 16", m))
        finally:
            big.unlink()
    (out / "scatter-runs.txt").write_text("\n".join(json.dumps(r, sort_keys=True) for r in raw) + "\n")
    print("## Scatter: fur on a mesh\n")
    print("The Stanford bunny (14,696 triangles) under a scatter, 2 threads, median of 3 runs, "
          "times from `render --stats` in ms. `load` reads the scene and mesh and places the "
          "instances; `build` makes the Embree hierarchy (and, in lattice mode, opens the table).\n")
    print("| scene | image | load | build | render | total |")
    print("| --- | --- | ---: | ---: | ---: | ---: |")
    for name, size, m in rows:
        print(f"| {name} | {size} | {m['load_ms']:.0f} | {m['build_ms']:.0f} | {m['render_ms']:.0f} | {m['total_ms']:.0f} |")
    print()


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
