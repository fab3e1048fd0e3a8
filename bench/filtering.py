#!/usr/bin/env python3
"""Issue 10's check, measured through the `lattice` command: for each scene, PSNR (8-bit) against
an exact render at 256 samples per pixel (the ground truth, cached in the work directory) and
render time of exact mode at 1 and 4 spp, point-sampled lattices (--filter none) and the default
filter (smooth, levels of detail on), all at 2 threads: the plates, and issue 9's check class (a
ball of 400 instances of a CSG of tori, or of a tuft). Renders are interleaved round by round
(exact 1, exact 4, none, smooth, then again) so that load from other processes falls on all of
them alike; the median render_ms is reported. The default filter meets the issue where its PSNR
is at least exact 4 spp's in no more time. Also found and timed: the fewest samples at which
exact mode is as faithful as the default filter (MATCH_SPP), for the time each takes at equal
fidelity.
Writes RESULTS/filtering.json and prints a Markdown summary (docs/filtering.md).

usage: filtering.py LATTICE RESULTS [--work DIR] [--runs N] [--only a,b] [--gt-spp N]"""
import argparse
import hashlib
import json
import os
import statistics
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ["plate2-thistle", "plate3-hair-closeup", "plate4-fuzzy-sphere-1000",
          "plate5-fuzzy-sphere-5000", "furry-bunny", "grass"]
# Issue 9's check class, which the issue's "scenes you have not seen" may resemble: 400
# instances on a ball of a CSG of quartics (costlier than kMaxExactCost, its level wanted past
# the build budget) and of a tuft of 216 segments; written by complexity_scenes.py.
CHECK_SCENES = ["ball-csg7", "ball-tuft216"]
# Mode label -> render arguments after the scene.
MODES = {
    "exact 1 spp": ["--mode", "exact"],
    "exact 4 spp": ["--mode", "exact", "--spp", "4"],
    "lattice none": ["--mode", "lattice", "--filter", "none"],
    "lattice smooth": ["--mode", "lattice"],
}


# The sample counts exact mode is tried at to find the fewest that are as faithful as the default
# filter: counts the renderer lays on a near-square grid (sampler.cpp, stratify; 5 spp is a
# 1 x 5 grid, and on grass and the furry bunny gained only 0.1 dB over 4).
MATCH_SPP = [6, 9, 12, 16, 25, 36, 64]
MATCH = "exact at equal fidelity"


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
    if name not in CHECK_SCENES:
        return os.path.join(ROOT, "examples", name + ".json")
    subprocess.run(["python3", os.path.join(ROOT, "bench", "complexity_scenes.py"),
                    os.path.join(work, "scenes"), "--only", name], check=True,
                   capture_output=True)
    return os.path.join(work, "scenes", name + ".json")


def measure(lattice, name, work, runs, gt_spp):
    scene = scene_path(name, work)
    truth = ground_truth(lattice, scene, work, gt_spp)
    cache = ["--lattice-dir", os.path.join(work, "cache")]
    stats = os.path.join(work, "stats.json")
    images = {m: os.path.join(work, f"{name}-{m.replace(' ', '-')}.png") for m in MODES}
    for m in MODES:  # builds the tables into the cache; not timed
        render(lattice, scene, images[m], stats, MODES[m] + cache)
    # The fewest samples at which exact mode is as faithful as the default filter, timed with
    # the rest.
    modes = dict(MODES)
    images[MATCH] = os.path.join(work, f"{name}-exact-match.png")
    spp = matching_spp(lattice, scene, images[MATCH], stats, cache, truth,
                       psnr(lattice, images["lattice smooth"], truth))
    if spp:
        modes[MATCH] = ["--mode", "exact", "--spp", str(spp)]
    times = {m: [] for m in modes}
    for _ in range(runs):
        for m in modes:
            times[m].append(render(lattice, scene, images[m], stats, modes[m] + cache)["render_ms"])
    return {"scene": name, "loadavg": os.getloadavg()[0], "match_spp": spp,
            "modes": {m: {"runs_ms": times[m], "ms": statistics.median(times[m]),
                          "psnr_db": psnr(lattice, images[m], truth)} for m in modes}}


def matching_spp(lattice, scene, image, stats, cache, truth, target_db):
    """The fewest samples of MATCH_SPP at which exact mode reaches target_db (None: none does)."""
    for spp in MATCH_SPP:
        render(lattice, scene, image, stats, ["--mode", "exact", "--spp", str(spp)] + cache)
        if psnr(lattice, image, truth) >= target_db:
            return spp
    return None


def fmt_db(v):
    return v if isinstance(v, str) else f"{v:.2f}"


def report(results, gt_spp):
    print("## Filtered lattices against exact mode (issue 10)\n")
    print(f"Each scene at its own size, 2 threads, median of {results['runs']} interleaved renders "
          f"(tables cached); PSNR against exact at {gt_spp} spp. The default filter meets the "
          "issue where it is at least as faithful as exact at 4 spp in no more time.\n")
    print("| scene | load | " + " | ".join(f"{m} dB / ms" for m in MODES) +
          " | smooth - exact 4 spp (dB) | smooth / exact 4 spp (time) | met |")
    print("| --- | ---: | " + " | ".join("---:" for _ in MODES) + " | ---: | ---: | --- |")
    for r in results["scenes"]:
        m = r["modes"]
        s, e4 = m["lattice smooth"], m["exact 4 spp"]
        gain = s["psnr_db"] - e4["psnr_db"]
        ratio = s["ms"] / e4["ms"]
        met = "yes" if gain >= 0 and ratio <= 1 else (
            "fidelity only" if gain >= 0 else ("time only" if ratio <= 1 else "no"))
        cells = " | ".join(f"{fmt_db(m[k]['psnr_db'])} / {m[k]['ms']:.0f}" for k in MODES)
        print(f"| {r['scene']} | {r['loadavg']:.1f} | {cells} | {gain:+.2f} | {ratio:.2f} | {met} |")
    print()
    report_equal_fidelity(results)


def report_equal_fidelity(results):
    print("At equal fidelity: the fewest samples (of " + ", ".join(map(str, MATCH_SPP)) +
          ") at which exact mode is at least as faithful as the default filter, timed in the "
          "same rounds.\n")
    print("| scene | lattice smooth dB / ms | exact spp | exact dB / ms | exact time / smooth time |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for r in results["scenes"]:
        m = r["modes"]
        s = m["lattice smooth"]
        e = m.get(MATCH)
        tail = (f"{r['match_spp']} | {fmt_db(e['psnr_db'])} / {e['ms']:.0f} | {e['ms'] / s['ms']:.2f}"
                if e else f"over {MATCH_SPP[-1]} | | ")
        print(f"| {r['scene']} | {fmt_db(s['psnr_db'])} / {s['ms']:.0f} | {tail} |")
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("lattice")
    ap.add_argument("results")
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "filtering"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--only", default="")
    ap.add_argument("--gt-spp", type=int, default=256)
    a = ap.parse_args()
    os.makedirs(os.path.join(a.work, "cache"), exist_ok=True)
    os.makedirs(a.results, exist_ok=True)
    names = [n for n in SCENES + CHECK_SCENES
             if not a.only or any(o in n for o in a.only.split(","))]
    results = {"runs": a.runs, "gt_spp": a.gt_spp,
               "scenes": [measure(a.lattice, n, a.work, a.runs, a.gt_spp) for n in names]}
    json.dump(results, open(os.path.join(a.results, "filtering.json"), "w"), indent=2)
    report(results, a.gt_spp)


if __name__ == "__main__":
    main()
