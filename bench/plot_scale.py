#!/usr/bin/env python3
"""Plots bench/results/scale.json (bench/scale.py): total time and peak memory against the number
of hairs, log-log, exact mode at its best setting (and at 4 spp, point-sampled and
footprint-filtered, the time alone: their memory is the same), lattice mode (default filter, deep
shadow maps, and point-sampled tables) and auto mode; with a second file (an earlier binary's run), its lines dashed.
Usage: plot_scale.py scale.json out.png [earlier.json]   (python3-matplotlib, from Debian)"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display on a build machine
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

SERIES = [("exact (best --instancing)", None, "black"),
          ("exact, 4 spp", "exact 4 spp", "tab:gray"),
          ("exact --footprint on, 4 spp", "exact footprint 4 spp", "tab:brown"),
          ("lattice", "lattice", "tab:orange"),
          ("lattice, deep shadow maps", "lattice deep-map", "tab:green"),
          ("lattice --filter none", "lattice none", "tab:blue"),
          ("auto (sub-rays, no table)", "auto", "tab:purple")]


def points(res, label, key):
    out = []
    for s in res["sizes"]:
        r = s["runs"].get(label or s["best_exact"], {})
        if key in r:
            out.append((s["hairs"], r[key] / (1000 if key == "total_ms" else 2**20)))
    return out


def main():
    res = json.load(open(sys.argv[1]))
    earlier = json.load(open(sys.argv[3])) if len(sys.argv) > 3 and os.path.exists(sys.argv[3]) else None
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, key, ylabel in zip(axes, ("total_ms", "peak_memory_bytes"),
                               ("total time (s): load + build + render", "peak memory (MB)")):
        for name, label, colour in SERIES:
            if label and label.startswith("exact") and key != "total_ms":
                continue
            if pts := points(res, label, key):
                ax.plot(*zip(*pts), "o-", color=colour, label=name)
            if earlier and (pts := points(earlier, label, key)):
                ax.plot(*zip(*pts), "x--", color=colour, alpha=0.6, label=name + ", before")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:,.0f}"))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.set_xlabel("hairs on the bunny")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"Hairs scattered on the bunny, {res['width']} x {res['height']}, "
                 f"{res['threads']} threads, warm table cache", fontsize=10)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=110)
    print(sys.argv[2])


if __name__ == "__main__":
    main()
