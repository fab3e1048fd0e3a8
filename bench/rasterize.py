#!/usr/bin/env python3
"""Rasterization throughput of the whole `lattice rasterize` command: the Plate 3 hair at
sigma^-1 = 1, 2 and 4 (hash14, 2 threads), several runs each. Reports the pairs per second the
command prints (N_lp over rasterize plus encode, wall clock) as the median of the runs, the split
between tracing and encoding, and the pairs per CPU second (N_lp over the build's CPU time, which
a loaded machine disturbs far less than the wall clock), with the load average at the start.
Writes bench/results/rasterize.json and prints a Markdown summary."""
import json
import os
import statistics
import subprocess
import sys
import tempfile

LATTICE = sys.argv[1] if len(sys.argv) > 1 else "build/bin/lattice"
OUT = sys.argv[2] if len(sys.argv) > 2 else "bench/results"
RUNS = int(sys.argv[3]) if len(sys.argv) > 3 else 5
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HAIR = os.path.join(ROOT, "examples", "plate3-hair-closeup.json")


def one(k, work):
    table = os.path.join(work, f"hair-{k}.lht")
    stats = os.path.join(work, "stats.json")
    subprocess.run([LATTICE, "rasterize", "-q", HAIR, "--primitive", "hair", "--sigma-inv", str(k),
                    "-o", table, "--stats", stats, "--threads", "2"], check=True)
    os.remove(table)
    return json.load(open(stats))


def main():
    os.makedirs(OUT, exist_ok=True)
    work = tempfile.mkdtemp(prefix="lattice-bench-")
    rows = []
    for k in (1, 2, 4):
        load = os.getloadavg()[0]
        runs = [one(k, work) for _ in range(RUNS)]
        med = lambda key: statistics.median(r[key] for r in runs)
        pairs = runs[0]["N_lp"]
        rows.append({
            "sigma_inv": k, "pairs": pairs, "runs": RUNS, "load_average": load,
            "pairs_per_second": med("pairs_per_second"),
            "rasterize_seconds": med("rasterize_seconds"), "encode_seconds": med("encode_seconds"),
            "build_cpu_seconds": med("build_cpu_seconds"),
            "pairs_per_cpu_second": pairs / med("build_cpu_seconds"),
            "segment_tests": runs[0]["segment_tests"], "stored_hits": runs[0]["stored_hits"]})
    json.dump(rows, open(os.path.join(OUT, "rasterize.json"), "w"), indent=2)
    print("## Rasterize throughput (Plate 3 hair, hash14, 2 threads, medians)\n")
    print("| sigma^-1 | N_lp | M pairs/s (command) | rasterize s | encode s | build CPU s "
          "| M pairs per CPU s | exact tests | load avg |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for r in rows:
        print(f"| {r['sigma_inv']} | {r['pairs']} | {r['pairs_per_second'] / 1e6:.1f} "
              f"| {r['rasterize_seconds']:.3f} | {r['encode_seconds']:.3f} "
              f"| {r['build_cpu_seconds']:.3f} | {r['pairs_per_cpu_second'] / 1e6:.1f} "
              f"| {r['segment_tests']} | {r['load_average']:.1f} |")
    print()


if __name__ == "__main__":
    main()
