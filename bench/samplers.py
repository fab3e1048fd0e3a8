#!/usr/bin/env python3
"""The samplers of `render --sampler` at low sample counts: for each bench scene (modes.py's),
exact mode at 1 spp (the pixel centre, whatever the sampler) and at 2, 4, 9 and 16 spp with each
sampler, PSNR (8-bit) against exact at 256 spp (the truth modes.py renders and caches: stratified
jitter, which holds none of a sequence's samples) and render time at 2 threads, the median of
interleaved rounds (sampler by sampler, then again) so that load from other processes falls on all
of them alike. The default sampler should be the best at these counts.
Writes RESULTS/samplers.json and prints a Markdown summary (README, `--sampler`).

usage: samplers.py LATTICE RESULTS [--work DIR] [--runs N] [--only a,b] [--spp 2,4,9,16]"""
import argparse
import json
import os
import statistics

from modes import GENERATED, ROOT, SCENES, ground_truth, psnr, render, scene_path

SAMPLERS = ["grid", "sobol", "jitter"]
SPP = [2, 4, 9, 16]
GT_SPP = 256
# The target: Plate 4, exact mode, 4 spp, the default sampler.
CHECK = ("plate4-fuzzy-sphere-1000", 4, 39.5)


def measure(lattice, name, work, runs, spps):
    scene = scene_path(name, work)
    truth = ground_truth(lattice, scene, work, GT_SPP)
    stats = os.path.join(work, "stats.json")
    # The default is asked for by leaving --sampler out; the stats name it.
    runs_of = {"centre": (1, None), "default 4": (4, None)}
    for spp in spps:
        for s in SAMPLERS:
            runs_of[f"{s} {spp}"] = (spp, s)
    images = {k: os.path.join(work, f"{name}-sampler-{k.replace(' ', '-')}.png") for k in runs_of}
    times = {k: [] for k in runs_of}
    ran = {}
    for _ in range(runs):
        for k, (spp, s) in runs_of.items():
            st = render(lattice, scene, images[k], stats, ["--mode", "exact", "--spp", str(spp)] +
                        (["--sampler", s] if s else []))
            times[k].append(st["render_ms"])
            ran[k] = st["sampler"]
    return {"scene": name, "loadavg": os.getloadavg()[0], "default": ran["default 4"],
            "renders": {k: {"spp": spp, "sampler": ran[k], "runs_ms": times[k],
                            "ms": statistics.median(times[k]),
                            "psnr_db": psnr(lattice, images[k], truth)}
                        for k, (spp, _) in runs_of.items()}}


def best_of(r, spp):
    return max(SAMPLERS, key=lambda s: r["renders"][f"{s} {spp}"]["psnr_db"])


def report(results):
    spps = results["spp"]
    print("## Samplers at low sample counts\n")
    print(f"Exact mode, each scene at its own size, 2 threads; PSNR against exact at {GT_SPP} spp "
          f"(stratified jitter) and the median render time of {results['runs']} interleaved rounds. "
          "At 1 spp every sampler takes the pixel centre. The best at each count is in bold; load is "
          "the machine's load average as the scene began.\n")
    print("| scene | load | centre (1 spp) dB / ms | spp | " +
          " | ".join(f"{s} dB / ms" for s in SAMPLERS) + " |")
    print("| --- | ---: | ---: | ---: | " + " | ".join("---:" for _ in SAMPLERS) + " |")
    for r in results["scenes"]:
        c = r["renders"]["centre"]
        for i, spp in enumerate(spps):
            best = best_of(r, spp)
            cells = []
            for s in SAMPLERS:
                m = r["renders"][f"{s} {spp}"]
                db = f"{m['psnr_db']:.2f}"
                cells.append(f"{'**' + db + '**' if s == best else db} / {m['ms']:.0f}")
            head = (f"| {r['scene']} | {r['loadavg']:.1f} | {c['psnr_db']:.2f} / {c['ms']:.0f}"
                    if i == 0 else "| | | ")
            print(f"{head} | {spp} | " + " | ".join(cells) + " |")
    print()
    print("Mean over the scenes (dB), and the scenes on which each sampler is best:\n")
    print("| spp | " + " | ".join(SAMPLERS) + " |")
    print("| ---: | " + " | ".join("---:" for _ in SAMPLERS) + " |")
    for spp in spps:
        cells = []
        for s in SAMPLERS:
            dbs = [r["renders"][f"{s} {spp}"]["psnr_db"] for r in results["scenes"]]
            wins = sum(best_of(r, spp) == s for r in results["scenes"])
            cells.append(f"{statistics.mean(dbs):.2f} ({wins})")
        print(f"| {spp} | " + " | ".join(cells) + " |")
    print()
    name, spp, target = CHECK
    for r in results["scenes"]:
        if r["scene"] == name:
            default = r["default"]
            db = r["renders"]["default 4"]["psnr_db"]
            print(f"The default sampler is {default}. {name} at {spp} spp with it: {db:.2f} dB "
                  f"(target {target} dB: {'met' if db >= target else 'NOT met'}).\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("lattice")
    ap.add_argument("results")
    # modes.py's work directory by default: the truths are rendered once for both.
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "modes"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--only", default="")
    ap.add_argument("--spp", default=",".join(map(str, SPP)))
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    os.makedirs(a.results, exist_ok=True)
    spps = [int(v) for v in a.spp.split(",")]
    names = [n for n in SCENES + GENERATED
             if not a.only or any(o in n for o in a.only.split(","))]
    results = {"runs": a.runs, "gt_spp": GT_SPP, "spp": spps, "samplers": SAMPLERS,
               "scenes": [measure(a.lattice, n, a.work, a.runs, spps) for n in names]}
    json.dump(results, open(os.path.join(a.results, "samplers.json"), "w"), indent=2)
    report(results)


if __name__ == "__main__":
    main()
