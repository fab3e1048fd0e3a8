#!/usr/bin/env python3
"""MPI benchmark, through the lattice command on this machine's 2 cores:

1. overhead: 2 ranks x 1 thread (mpirun) against 1 rank x 2 threads (a plain run), interleaved
   A B A B ..., best of RUNS, for Plate 5 at 4 spp (exact and lattice mode, the table cached
   beforehand) and for rasterizing the hair at sigma^-1 = 4 (hash14);
2. the figures the cluster model of docs/distributed.md is fitted to: the cost of a tile per
   thread, the dealer's chunks and the bytes gathered per pixel, from the 2-rank runs' --stats;
   loading and building the acceleration structure for 100,000 scattered hairs, and the cost of
   a sample among them (the furry bunny with its count raised, lattice mode);
3. the model's prediction for a 4K (3840 x 2160), 16-spp, 100,000-hair frame on 4 to 64 nodes.

Prints Markdown; writes distributed-runs.txt (the raw stats) beside it.
Usage: distributed.py path/to/lattice OUT_DIR [--mpirun mpirun]"""
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
RUNS = 5
PLATE5 = ROOT / "examples" / "plate5-fuzzy-sphere-5000.json"
BUNNY = ROOT / "examples" / "furry-bunny.json"
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def run(cmd, stats):
    """Runs a command; returns its --stats and its wall time (mpirun's start-up included)."""
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env=ENV, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    s = json.loads(stats.read_text())
    s["wall_s"] = wall
    return s


def pair(lattice, mpirun, args, stats):
    """(1 rank x 2 threads, 2 ranks x 1 thread) command lines for the same job."""
    one = [lattice, *args, "--threads", "2", "--stats", str(stats)]
    two = [mpirun, "-q", "-n", "2", "--bind-to", "none", lattice, *args, "--threads", "1", "--stats", str(stats)]
    return one, two


def interleaved(lattice, mpirun, args, stats, key, cpu):
    """Run A B A B ..., RUNS of each: the best run of each by key(stats) (wall time), and the
    least CPU time of each, cpu(stats) (all threads of all ranks: steadier on a busy machine)."""
    one, two = pair(lattice, mpirun, args, stats)
    a, b = [], []
    for _ in range(RUNS):
        a.append(run(one, stats))
        b.append(run(two, stats))
    return min(a, key=key), min(b, key=key), min(map(cpu, a)), min(map(cpu, b)), a + b


STEPS = ("joined", "loaded", "checked", "tables", "accel", "dealt", "gathered", "encoded")


def print_phases(phases):
    """Where the time of the best runs went: the plain run's own figures, and each rank's
    timeline (--stats timeline_ms: when each step ended, from the process's start)."""
    print("\n## Where the time goes (the best runs above)\n")
    print("Milliseconds per step. 1 x 2: the plain run's `load_ms`, `prepare_ms` (tables), `build_ms` "
          "(acceleration structure), `render_ms`, or rasterize and encode. 2 x 1: each rank's step "
          "durations from its timeline (MPI_Init from the process's start, then from one step to the next); "
          "`dealt` is the dealt loop (tiles or blocks, waiting for the other rank at its start included), "
          "`gathered` the gather to rank 0.\n")
    print("| job | run | " + " | ".join(STEPS) + " | wall (s) |")
    print("| --- | --- | " + " | ".join("---:" for _ in STEPS) + " | ---: |")
    for job, a, b in phases:
        one = {"loaded": a.get("load_ms"), "tables": a.get("prepare_ms"), "accel": a.get("build_ms"),
               "dealt": a.get("render_ms")}
        if "rasterize_seconds" in a:
            one = {"dealt": a["rasterize_seconds"] * 1e3, "encoded": a["encode_seconds"] * 1e3}
        cells = [f"{one[k]:.0f}" if one.get(k) is not None else "" for k in STEPS]
        print(f"| {job} | 1 x 2 | " + " | ".join(cells) + f" | {a['wall_s']:.2f} |")
        for r in b.get("ranks", []):
            t = r.get("timeline_ms", {})
            cells, last = [], 0.0
            for k in STEPS:
                if k in t:
                    cells.append(f"{t[k] - last:.0f}")
                    last = t[k]
                else:
                    cells.append("")
            print(f"| {job} | 2 x 1, rank {r['rank']} | " + " | ".join(cells) + f" | {b['wall_s']:.2f} |")


def main(lattice, out, mpirun):
    out = pathlib.Path(out)
    raw = []
    rows = []
    phases = []  # (job, best 1 x 2 stats, best 2 x 1 stats)
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        stats = work / "stats.json"
        img = str(work / "out.png")
        render_ms = lambda s: s["render_ms"]
        # Plate 5, exact and lattice (its table built first, so both columns are rendering only).
        subprocess.run([lattice, "render", "-q", str(PLATE5), "--mode", "lattice", "--lattice-dir", str(work),
                        "-o", img], check=True)
        p5 = {}
        for mode in ("exact", "lattice"):
            args = ["render", "-q", str(PLATE5), "--spp", "4", "--mode", mode, "--lattice-dir", str(work), "-o", img]
            a, b, ca, cb, r = interleaved(lattice, mpirun, args, stats, render_ms, lambda s: s["render_cpu_ms"] / 1e3)
            raw += r
            p5[mode] = b
            rows.append((f"Plate 5, 4 spp, {mode}: render", a["render_ms"] / 1e3, b["render_ms"] / 1e3, ca, cb,
                         a["wall_s"], b["wall_s"]))
            phases.append((f"Plate 5, {mode}", a, b))
        # The hair at sigma^-1 = 4, written outside the cache.
        args = ["rasterize", "-q", str(PLATE5), "--primitive", "hair", "--sigma-inv", "4", "-o", str(work / "h.lht")]
        build_s = lambda s: s["rasterize_seconds"] + s["encode_seconds"]
        a, b, ca, cb, r = interleaved(lattice, mpirun, args, stats, build_s, lambda s: s["build_cpu_seconds"])
        raw += r
        rows.append(("hair, sigma^-1 = 4: rasterize + encode", build_s(a), build_s(b), ca, cb,
                     a["wall_s"], b["wall_s"]))
        phases.append(("hair, rasterize", a, b))
        # The fixed cost of a job: mpirun, MPI_Init and MPI_Finalize, with nothing to do.
        startup = {}
        for name, cmd in (("plain", [lattice, "--version"]),
                          ("mpirun", [mpirun, "-q", "-n", "2", "--bind-to", "none", lattice, "--version"])):
            times = []
            for _ in range(RUNS):
                t0 = time.perf_counter()
                subprocess.run(cmd, check=True, env=ENV, stdout=subprocess.DEVNULL)
                times.append(time.perf_counter() - t0)
            startup[name] = min(times)
        raster = b

        # 100,000 hairs on the bunny (the scatter benchmark's scene), lattice mode: load and
        # build at 16 x 16, then the cost of a sample at 256 x 256, 4 spp, on 2 threads.
        scene = json.loads(BUNNY.read_text())
        scene["objects"][2]["count"] = 100000
        big = ROOT / "examples" / "_bench-mpi-100k.json"  # beside the mesh it names
        try:
            scene["camera"]["width"] = scene["camera"]["height"] = 16
            big.write_text(json.dumps(scene))
            one = [lattice, "render", "-q", str(big), "--mode", "lattice", "--lattice-dir", str(work), "-o", img,
                   "--threads", "2", "--stats", str(stats)]
            run(one, stats)  # builds the table
            small = min((run(one, stats) for _ in range(RUNS)), key=lambda s: s["load_ms"] + s["build_ms"])
            scene["camera"]["width"] = scene["camera"]["height"] = 256
            big.write_text(json.dumps(scene))
            frame = min((run(one + ["--spp", "4"], stats) for _ in range(RUNS)), key=lambda s: s["render_cpu_ms"])
            raw += [small, frame]
        finally:
            big.unlink(missing_ok=True)

    (out / "distributed-runs.txt").write_text("\n".join(json.dumps(r, sort_keys=True) for r in raw) + "\n")
    print("## MPI: 2 ranks x 1 thread against 1 rank x 2 threads\n")
    print(f"Best of {RUNS}, interleaved; `mpirun -q -n 2 --bind-to none ... --threads 1` against a plain run "
          "with `--threads 2`. Time is `render_ms` (tiles dealt, rendered and gathered) or rasterize + "
          "encode seconds; CPU is the CPU time of every thread of every rank over the render (or the table's "
          "build: check, rasterize, gather, encode, write), least of the runs; wall time includes "
          "start-up (mpirun and MPI_Init: about a second). On a busy machine time swings with the "
          "load; CPU time is the steadier measure of overhead.\n")
    print("| job | time 1 x 2 (s) | time 2 x 1 (s) | ratio | CPU 1 x 2 (s) | CPU 2 x 1 (s) | CPU overhead | wall 1 x 2 (s) | wall 2 x 1 (s) |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name, a, b, ca, cb, wa, wb in rows:
        print(f"| {name} | {a:.3f} | {b:.3f} | {b / a:.2f} | {ca:.3f} | {cb:.3f} | {100 * (cb / ca - 1):+.1f} % | "
              f"{wa:.2f} | {wb:.2f} |")

    print(f"\nStart-up alone (`lattice --version`, best of {RUNS}): {startup['plain']:.2f} s plain, "
          f"{startup['mpirun']:.2f} s under `mpirun -n 2` (mpirun, MPI_Init, MPI_Finalize): a floor under every "
          "2-rank wall time above.")
    print_phases(phases)

    # Figures for the model.
    ex = p5["exact"]
    w, h = ex["width"], ex["height"]
    tiles = sum(r["tiles"] for r in ex["ranks"])
    tile_ms = {m: p5[m]["render_cpu_ms"] / tiles for m in p5}
    chunks = sum(r["chunks"] for r in ex["ranks"])
    waits = {m: sum(r["wait_ms"] for r in p5[m]["ranks"]) for m in p5}
    samples_100k = frame["width"] * frame["height"] * frame["spp"]
    us_per_sample = frame["render_cpu_ms"] * 1e3 / samples_100k
    setup_s = (small["load_ms"] + small["build_ms"]) / 1e3
    print("\n## Figures the model is fitted to\n")
    print(f"- Plate 5 ({w} x {h}, 4 spp, {tiles} tiles of 16 x 16): a tile costs {tile_ms['exact']:.2f} ms "
          f"(exact) and {tile_ms['lattice']:.2f} ms (lattice) of CPU, 2 ranks; the dealer sent {chunks} chunks "
          f"in all (8-byte requests and replies); threads waited {waits['exact']:.1f} ms (exact) and "
          f"{waits['lattice']:.1f} ms (lattice) for tiles, summed over both ranks.")
    print(f"- Gathered on rank 0: 15 bytes a pixel (RGB float radiance + RGB 8-bit display) plus 8 bytes a "
          f"chunk: {15 * w * h / 2**20:.1f} MB for Plate 5, of which rank 1 sent its share.")
    print(f"- Hair at sigma^-1 = 4, 2 ranks: {raster['stored_hits']} hits (20 bytes each while building); "
          "per rank: " + ", ".join(f"rank {r['rank']} {r['stored_hits']} hits, peak {r['peak_memory_bytes'] / 2**20:.0f} MB"
                                   for r in raster["ranks"]) + ".")
    print(f"- 100,000 hairs on the bunny (lattice mode): load + acceleration build {setup_s:.2f} s "
          f"(every rank does it), {us_per_sample:.2f} us of one thread per sample "
          f"(256 x 256, 4 spp: {frame['render_cpu_ms']:.0f} ms of CPU on {frame['threads']} threads).")

    # The model (docs/distributed.md): T(N) = start(N) + setup + table / (N c) + samples * t_s / (N c)
    # + tail + gather, on N nodes of c cores each like these, 10 Gb/s between them.
    c, bandwidth, latency = 32, 10e9 / 8, 50e-6
    W, H, spp = 3840, 2160, 16
    samples = W * H * spp
    # The hair's table at sigma^-1 = 4: rasterized across every core, encoded by rank 0 alone.
    encode_s = raster["encode_seconds"]
    raster_core_s = raster["build_cpu_seconds"] - encode_s
    tile_s = 256 * spp * us_per_sample / 1e6
    ntiles = (W // 16) * ((H + 15) // 16)
    print(f"\n## Model: a {W} x {H}, {spp}-spp frame of 100,000 hairs, nodes of {c} cores\n")
    print("| nodes | start-up | setup | table | render | tail | gather | total (s) | efficiency vs 4 nodes |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    base = None
    for n in (4, 8, 16, 32, 64):
        start = 1.0 + 0.02 * n
        render = samples * us_per_sample / 1e6 / (n * c)
        table = raster_core_s / (n * c) + encode_s
        tail = tile_s + 2 * latency
        chunks_n = 4 * n * 16  # guided chunks: about kGuide x ln(tiles per thread) per rank
        gather = 15 * W * H / bandwidth + chunks_n * latency / n
        total = start + setup_s + table + render + tail + gather
        base = base or total * 4
        print(f"| {n} | {start:.2f} | {setup_s:.2f} | {table:.2f} | {render:.2f} | {tail:.3f} | {gather:.3f} | "
              f"{total:.2f} | {100 * base / (total * n):.0f} % |")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    mpirun = sys.argv[sys.argv.index("--mpirun") + 1] if "--mpirun" in sys.argv else "mpirun"
    if not shutil.which(mpirun):
        sys.exit(f"distributed.py: {mpirun} not found (Debian's openmpi-bin)")
    main(sys.argv[1], sys.argv[2], mpirun)
