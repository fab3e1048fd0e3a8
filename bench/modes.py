#!/usr/bin/env python3
"""Where lattices pay: every way `lattice render` can answer fur, against exact mode at its best.

For each scene (at its own size, 2 threads): PSNR (8-bit) against exact mode at 256 samples per
pixel with stratified jitter (the truth, cached in the work directory by the scene's bytes) and
render time of exact mode at 1 and 4 spp (its default sampler, the best at low counts:
bench/results/samplers.md), exact mode with footprint filtering at 1, 2 and 4 spp,
  lattice mode (tables: the default filter with levels of detail, and point-sampled), and auto
  mode (each primitive's cheaper answer).
Renders are interleaved round by round so that load from other processes falls on all alike;
the median render_ms is reported. Tables come from the cache (built before timing; their build
time is reported apart). Then exact mode is swept over sample counts (EXACT_SPP), with point
samples and with its footprint filter, to compare the filtered modes with each sweep at equal
fidelity (the fewest samples as faithful) and at equal time (the most faithful exact render that
takes no longer).
Writes RESULTS/modes.json and prints a Markdown summary.

usage: modes.py LATTICE RESULTS [--work DIR] [--runs N] [--only a,b] [--gt-spp N]"""
import argparse
import hashlib
import json
import os
import statistics
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ["plate2-thistle", "plate3-hair-closeup", "plate4-fuzzy-sphere-1000",
          "plate5-fuzzy-sphere-5000", "furry-bunny", "grass"]
# Costly primitives: 400 instances on a ball of a CSG of quartics, and of a tuft of 216
# segments; written by complexity_scenes.py.
GENERATED = ["ball-csg7", "ball-tuft216"]
# Mode label -> render arguments after the scene.
MODES = {
    "exact 1 spp": ["--mode", "exact"],
    "exact 4 spp": ["--mode", "exact", "--spp", "4"],
    "exact footprint": ["--mode", "exact", "--footprint", "on"],
    "exact footprint 2 spp": ["--mode", "exact", "--footprint", "on", "--spp", "2"],
    "exact footprint 4 spp": ["--mode", "exact", "--footprint", "on", "--spp", "4"],
    "lattice": ["--mode", "lattice"],
    "lattice none": ["--mode", "lattice", "--filter", "none"],
    "auto": ["--mode", "auto"],
}
# The modes compared with exact mode's sweeps (SWEEPS) at equal fidelity and equal time;
# footprint filtering at 2 and 4 spp is in the modes table only.
FILTERED = ["exact footprint", "lattice", "auto"]
# The sample counts of exact mode's sweep: near-square grids (stratify in renderer.cpp).
EXACT_SPP = [1, 2, 4, 6, 9, 12, 16, 25, 36, 64]
# Exact mode's two sweeps: point samples, and its footprint filter (each sample's footprint
# spanned by sub-rays), the more faithful for its time on every scene here.
SWEEPS = {"exact_sweep": [], "footprint_sweep": ["--footprint", "on"]}


def render(lattice, scene, image, stats, args):
    subprocess.run([lattice, "render", "-q", scene, "-o", image, "--threads", "2",
                    "--stats", stats, *args], check=True)
    return json.load(open(stats))


def psnr(lattice, image, truth):
    out = subprocess.run([lattice, "compare", image, truth, "--json"], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)["psnr_db"]


def ground_truth(lattice, scene, work, spp):
    """The exact render at spp samples, kept under a name that depends on the scene's bytes.
    Stratified jitter: the truth shares no samples with a sequence's renders it is set against."""
    digest = hashlib.sha256(open(scene, "rb").read()).hexdigest()[:16]
    path = os.path.join(work, f"truth-{os.path.basename(scene)[:-5]}-{spp}spp-{digest}.png")
    if not os.path.exists(path):
        render(lattice, scene, path + ".tmp.png", os.path.join(work, "stats.json"),
               ["--mode", "exact", "--spp", str(spp), "--sampler", "jitter"])
        os.replace(path + ".tmp.png", path)
    return path


def scene_path(name, work):
    if name not in GENERATED:
        return os.path.join(ROOT, "examples", name + ".json")
    subprocess.run(["python3", os.path.join(ROOT, "bench", "complexity_scenes.py"),
                    os.path.join(work, "scenes"), "--only", name], check=True,
                   capture_output=True)
    return os.path.join(work, "scenes", name + ".json")


def answers(stats):
    """What answered each primitive, in the words of render --stats."""
    return "; ".join(f"{p['primitive']}: {p['how']}" for p in stats.get("primitives", []))


def measure(lattice, name, work, runs, gt_spp):
    scene = scene_path(name, work)
    truth = ground_truth(lattice, scene, work, gt_spp)
    cache = ["--lattice-dir", os.path.join(work, "cache")]
    stats = os.path.join(work, "stats.json")
    images = {m: os.path.join(work, f"{name}-{m.replace(' ', '-')}.png") for m in MODES}
    first = {}
    for m in MODES:  # builds the tables into the cache; not timed
        s = render(lattice, scene, images[m], stats, MODES[m] + cache)
        first[m] = {"tables_ms": s.get("tables_ms", 0), "tables_built": s.get("tables_built", 0),
                    "table_bytes": s.get("table_bytes", 0), "answers": answers(s),
                    "table_visits": s.get("table_visits", 0)}
    times = {m: [] for m in MODES}
    for _ in range(runs):
        for m in MODES:
            times[m].append(render(lattice, scene, images[m], stats, MODES[m] + cache)["render_ms"])
    modes = {m: {"runs_ms": times[m], "ms": statistics.median(times[m]),
                 "psnr_db": psnr(lattice, images[m], truth), **first[m]} for m in MODES}
    sweeps = {k: exact_sweep(lattice, scene, work, name, stats, truth,
                             max(modes[m]["psnr_db"] for m in FILTERED),
                             max(modes[m]["ms"] for m in FILTERED), args)
              for k, args in SWEEPS.items()}
    return {"scene": name, "loadavg": os.getloadavg()[0], "modes": modes, **sweeps}


def exact_sweep(lattice, scene, work, name, stats, truth, target_db, target_ms, args=()):
    """Exact mode (with args) at EXACT_SPP, until it is both as faithful as target_db and slower
    than target_ms: [{spp, ms, psnr_db}] (ms: the median of 3)."""
    image = os.path.join(work, f"{name}-exact-sweep.png")
    out = []
    for spp in EXACT_SPP:
        ms = statistics.median(
            render(lattice, scene, image, stats,
                   ["--mode", "exact", "--spp", str(spp), *args])["render_ms"]
            for _ in range(3))
        out.append({"spp": spp, "ms": ms, "psnr_db": psnr(lattice, image, truth)})
        if out[-1]["psnr_db"] >= target_db and ms > target_ms:
            break
    return out


def equal_fidelity(sweep, db):
    """The cheapest exact render of the sweep at least db faithful, or None."""
    return next((e for e in sweep if e["psnr_db"] >= db), None)


def equal_time(sweep, ms):
    """The most faithful exact render of the sweep that takes at most ms, or None."""
    within = [e for e in sweep if e["ms"] <= ms]
    return max(within, key=lambda e: e["psnr_db"]) if within else None


def compare_table(results, sweep_key, modes):
    print("| scene | mode | exact spp at equal fidelity | exact time / mode time | "
          "exact spp at equal time | mode - exact (dB) |")
    print("| --- | --- | ---: | ---: | ---: | ---: |")
    for r in results["scenes"]:
        sweep = r[sweep_key]
        for k in modes:
            m = r["modes"][k]
            f = equal_fidelity(sweep, m["psnr_db"])
            t = equal_time(sweep, m["ms"])
            fcells = f"{f['spp']} | {f['ms'] / m['ms']:.2f}" if f else f"over {sweep[-1]['spp']} | "
            tcells = f"{t['spp']} | {m['psnr_db'] - t['psnr_db']:+.2f}" if t else "none as fast | "
            print(f"| {r['scene']} | {k} | {fcells} | {tcells} |")


def report(results, gt_spp):
    print("## Where lattices pay: every mode against exact mode at its best\n")
    print(f"Each scene at its own size, 2 threads, median of {results['runs']} interleaved renders "
          f"(tables cached); PSNR against exact at {gt_spp} spp. Cells: dB / ms.\n")
    print("| scene | load | " + " | ".join(MODES) + " |")
    print("| --- | ---: | " + " | ".join("---:" for _ in MODES) + " |")
    for r in results["scenes"]:
        m = r["modes"]
        cells = " | ".join(f"{m[k]['psnr_db']:.2f} / {m[k]['ms']:.0f}" for k in MODES)
        print(f"| {r['scene']} | {r['loadavg']:.1f} | {cells} |")
    print("\nAgainst exact mode's point samples swept over " + ", ".join(map(str, EXACT_SPP)) +
          " spp: at equal fidelity, the fewest samples as faithful as the mode and their time "
          "over the mode's (above 1: the mode is faster); at equal time, the most faithful exact render that "
          "takes no longer, and the mode's lead over it in dB (above 0: the mode is more "
          "faithful).\n")
    compare_table(results, "exact_sweep", FILTERED)
    print("\nThe same against exact mode's footprint filter (`--footprint on`) swept over the same "
          "counts, exact mode's most faithful setting for its time:\n")
    compare_table(results, "footprint_sweep", [k for k in FILTERED if k != "exact footprint"])
    print("\nWhat answered each primitive, and the tables read (built once, before timing):\n")
    print("| scene | mode | answered by | tables | build ms |")
    print("| --- | --- | --- | ---: | ---: |")
    for r in results["scenes"]:
        for k in ["lattice", "lattice none", "auto"]:
            m = r["modes"][k]
            mb = m["table_bytes"] / 2**20
            print(f"| {r['scene']} | {k} | {m['answers']} | {mb:.1f} MB | {m['tables_ms']:.0f} |")
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("lattice")
    ap.add_argument("results")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "modes"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--only", default="")
    ap.add_argument("--gt-spp", type=int, default=256)
    a = ap.parse_args()
    os.makedirs(os.path.join(a.work, "cache"), exist_ok=True)
    os.makedirs(a.results, exist_ok=True)
    names = [n for n in SCENES + GENERATED
             if not a.only or any(o in n for o in a.only.split(","))]
    results = {"runs": a.runs, "gt_spp": a.gt_spp,
               "scenes": [measure(a.lattice, n, a.work, a.runs, a.gt_spp) for n in names]}
    json.dump(results, open(os.path.join(a.results, "modes.json"), "w"), indent=2)
    report(results, a.gt_spp)


if __name__ == "__main__":
    main()
