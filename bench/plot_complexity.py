#!/usr/bin/env python3
"""Plots bench/results/complexity.json: render time against primitive cost, exact mode and
lattice mode per encoding, log-log; one panel per family (sphere/cylinder parts, quartic
leaves), since a part and a quartic leaf do not cost the same.
Usage: plot_complexity.py [complexity.json] [out.png]   (python3-matplotlib, from Debian)"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display on a build machine
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter, NullFormatter  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "bench/results/complexity.json")
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "docs/images/complexity.png")
    res = json.load(open(src))
    c = res["config"]
    families = [("spheres+cylinders", "parts (spheres + cylinders)"), ("csg", "quartic leaves (tori)")]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, (family, xlabel) in zip(axes, families):
        rows = sorted((r for r in res["primitives"] if r["family"] == family), key=lambda r: r["cost"])
        if not rows:
            ax.set_visible(False)
            continue
        x = [r["cost"] for r in rows]
        ax.plot(x, [r["exact_ms"] for r in rows], "o-", color="black", lw=2, label="exact")
        for enc, style in zip(c["encodings"], ["s--", "^--", "d--", "v--"]):
            pts = [(r["cost"], r["lattice"][enc]["ms"]) for r in rows if "ms" in r["lattice"].get(enc, {})]
            if pts:
                ax.plot(*zip(*pts), style, label=f"lattice {enc}")
        for r in rows:
            ax.annotate(r["primitive"], (r["cost"], r["exact_ms"]), textcoords="offset points",
                        xytext=(4, 6), fontsize=7)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xticks(x)  # the measured costs, as plain numbers
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.tick_params(axis="y", which="minor", labelsize=7)
        ax.set_xlabel(xlabel)
        ax.set_ylabel("render time (ms)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"Plate 4 placement, 1000 instances, {c['size']}x{c['size']}, {c['threads']} threads, "
                 f"sigma^-1 = {c['sigma_inv']} (median of {c['runs']}; load average {c['loadavg_start']:.1f} "
                 f"on {c['cpus']} CPUs)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
