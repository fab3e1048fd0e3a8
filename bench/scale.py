#!/usr/bin/env python3
"""Lattices at scale: hairs scattered on a mesh, from 20,000 to millions, in exact and lattice mode.

The scene is examples/furry-bunny.json (the Stanford bunny, 14,696 triangles) with its scatter's
count raised, rendered at 1280 x 720 on 2 threads with a warm table cache (the hair's table is
built once before anything is timed). Counts above MAX_PER_SCATTER are split into several
scatters (seeds 1, 2, ...), so that every binary reads the same scene. For each count:

- exact mode at 1 spp with `--instancing` auto, always and never (never only up to
  NEVER_UP_TO hairs: flattening multiplies the hierarchy by the hair's 19 parts), its best
  setting being the smallest total time; and exact mode at 4 spp at that setting, with its
  default point samples and with its footprint filter (`--footprint on`: each sample's
  footprint spanned by 2 x 2 sub-rays, exact mode's most faithful setting per sample);
- lattice mode at 1 spp, with its default filter (shadow rays through the tables), with the
  instances' shadows from deep shadow maps (`--instance-shadows deep-map`), and point-sampled
  (`--filter none`);
- auto mode at 1 spp (a hair, cheap to intersect, answered by its own crossings of 2 x 2
  sub-rays across each footprint: no table);

each once (at these sizes a run takes seconds: one run, interleaved with nothing; the load
average is recorded beside). Load, build, render and total times and peak memory come from
`render --stats` (peak_memory_bytes: the process's peak resident set, getrusage's ru_maxrss,
read as the stats are written, after the image). PSNR is against exact mode at TRUTH_SPP spp
(stratified jitter) where that truth can be rendered in reasonable time (up to TRUTH_UP_TO
hairs), cached in the work directory under the scene's bytes.

Time: the full run (20 k to 10 M) takes about 15 minutes on 2 idle cores with its truths cached
(two to three times that under a load average of 10), and the first time some 15 more for the
truths (the 1 M one the most); --quick (20 k and 200 k) a few minutes. The 10 M renders are
the bulk of it. 10 M hairs peak at about 5 GB in lattice mode and 7 in exact mode.
Writes RESULTS/scale.json (or --name) and prints a Markdown table.

usage: scale.py LATTICE RESULTS [--work DIR] [--quick] [--sizes 20000,...] [--name scale]"""
import argparse
import json
import os
import pathlib
import subprocess

from modes import ground_truth, psnr

ROOT = pathlib.Path(__file__).resolve().parent.parent
SIZES = [20_000, 200_000, 1_000_000, 4_000_000, 10_000_000]
QUICK_SIZES = [20_000, 200_000]
MAX_PER_SCATTER = 2_000_000  # the scatter count limit of older binaries
NEVER_UP_TO = 1_000_000
TRUTH_UP_TO = 1_000_000
TRUTH_SPP = 64
WIDTH, HEIGHT = 1280, 720


def scene_for(hairs, work):
    """The bunny with `hairs` hairs at 1280 x 720, written into work (the mesh by absolute path)."""
    scene = json.loads((ROOT / "examples" / "furry-bunny.json").read_text())
    scene["camera"]["width"], scene["camera"]["height"] = WIDTH, HEIGHT
    objects = scene["objects"]
    objects[0]["file"] = str(ROOT / "examples" / "meshes" / "bunny.ply")
    scatter = objects.pop()
    left, seed = hairs, 1
    while left > 0:
        part = dict(scatter, count=min(left, MAX_PER_SCATTER), seed=seed, name=f"fur{seed}")
        objects.append(part)
        left -= part["count"]
        seed += 1
    path = work / f"bunny-{hairs}.json"
    path.write_text(json.dumps(scene))
    return path


def render(lattice, scene, image, work, args):
    stats = work / "stats.json"
    if stats.exists():
        stats.unlink()
    run = subprocess.run([lattice, "render", "-q", str(scene), "-o", str(image), "--threads", "2",
                          "--stats", str(stats), "--lattice-dir", str(work / "cache"), *args],
                         capture_output=True, text=True)
    if run.returncode != 0:
        return {"failed": (run.stderr.strip().splitlines() or ["exit %d" % run.returncode])[-1]}
    s = json.loads(stats.read_text())
    keep = ("load_ms", "build_ms", "render_ms", "render_cpu_ms", "total_ms", "peak_memory_bytes",
            "table_visits", "primary_rays", "shadow_rays")
    out = {k: s[k] for k in keep if k in s}
    if "primitives" in s:
        out["answers"] = "; ".join(f"{p['primitive']}: {p['how']}" for p in s["primitives"])
    out["loadavg"] = os.getloadavg()[0]
    return out


def truth_for(lattice, scene, work):
    """The exact render at TRUTH_SPP, cached by the scene's bytes as the modes benchmark keeps
    its truths (modes.ground_truth); None when it cannot be rendered."""
    try:
        return ground_truth(lattice, scene, work, TRUTH_SPP)
    except subprocess.CalledProcessError:
        return None


def measure(lattice, hairs, work, truth_up_to):
    scene = scene_for(hairs, work)
    runs = {}

    def run(label, args):
        image = work / f"{scene.stem}-{label.replace(' ', '-')}.png"
        runs[label] = render(lattice, scene, image, work, args)
        runs[label]["image"] = str(image)

    for inst in ("auto", "always", "never"):
        if inst == "never" and hairs > NEVER_UP_TO:
            continue
        run(f"exact {inst}", ["--mode", "exact", "--instancing", inst])
    ok = {k: v for k, v in runs.items() if "total_ms" in v}
    best = min(ok, key=lambda k: ok[k]["total_ms"]) if ok else "exact auto"
    run("exact 4 spp", ["--mode", "exact", "--instancing", best.split()[1], "--spp", "4"])
    run("exact footprint 4 spp", ["--mode", "exact", "--instancing", best.split()[1], "--footprint",
                                  "on", "--spp", "4"])
    run("lattice", ["--mode", "lattice"])
    run("lattice deep-map", ["--mode", "lattice", "--instance-shadows", "deep-map"])
    run("lattice none", ["--mode", "lattice", "--filter", "none"])
    run("auto", ["--mode", "auto"])
    truth = truth_for(lattice, scene, work) if hairs <= truth_up_to else None
    for r in runs.values():
        if truth and "total_ms" in r:
            r["psnr_db"] = psnr(lattice, r["image"], truth)
        del r["image"]
    return {"hairs": hairs, "best_exact": best, "truth_spp": TRUTH_SPP if truth else None,
            "runs": runs}


def cell(r, key, fmt):
    return fmt.format(r[key]) if key in r else ("failed" if "failed" in r else "-")


def report(res):
    print("## Lattices at scale: hairs on the bunny\n")
    print(f"1280 x 720, 2 threads, warm table cache, one run each; times in seconds from "
          f"`render --stats` (render CPU: all threads', steadier than wall time on a shared "
          f"machine), peak MB the process's peak resident set; PSNR (dB) against exact "
          f"mode at {TRUTH_SPP} spp where one was rendered. Binary: `{res['binary']}`.\n")
    print("| hairs | mode | load | build | render | render CPU | total | peak MB | PSNR | load avg |")
    print("| ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for s in res["sizes"]:
        for label, r in s["runs"].items():
            mark = " (best)" if label == s["best_exact"] else ""
            secs = [cell(r, k, "{:.2f}") if k not in r else f"{r[k] / 1000:.2f}"
                    for k in ("load_ms", "build_ms", "render_ms", "render_cpu_ms", "total_ms")]
            mb = f"{r['peak_memory_bytes'] / 2**20:.0f}" if "peak_memory_bytes" in r else "-"
            print(f"| {s['hairs']:,} | {label}{mark} | " + " | ".join(secs) +
                  f" | {mb} | {cell(r, 'psnr_db', '{:.2f}')} | {cell(r, 'loadavg', '{:.1f}')} |")
    answers = sorted({f"{k}: {r['answers']}" for s in res["sizes"] for k, r in s["runs"].items()
                      if "answers" in r})
    if answers:
        print("\nWhat answered the hairs in lattice mode (`render --stats`), at every size: " +
              "; ".join(answers) + ".")
    failed = [(s["hairs"], k, r["failed"]) for s in res["sizes"] for k, r in s["runs"].items()
              if "failed" in r]
    if failed:
        print("\nFailed runs:\n")
        for h, k, why in failed:
            print(f"- {h:,} hairs, {k}: {why}")
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("lattice")
    ap.add_argument("results")
    ap.add_argument("--work", default=str(ROOT / "build" / "scale"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--sizes", default="")
    ap.add_argument("--name", default="scale")
    a = ap.parse_args()
    work = pathlib.Path(a.work)
    (work / "cache").mkdir(parents=True, exist_ok=True)
    sizes = [int(s) for s in a.sizes.split(",")] if a.sizes else (QUICK_SIZES if a.quick else SIZES)
    # Warms the table cache: the hair's table, built before anything is timed.
    warm = scene_for(20_000, work)
    render(a.lattice, warm, work / "warm.png", work, ["--mode", "lattice"])
    render(a.lattice, warm, work / "warm.png", work, ["--mode", "lattice", "--filter", "none"])
    truth_up_to = 200_000 if a.quick else TRUTH_UP_TO
    res = {"binary": str(a.lattice), "width": WIDTH, "height": HEIGHT, "threads": 2,
           "sizes": [measure(a.lattice, n, work, truth_up_to) for n in sizes]}
    out = pathlib.Path(a.results)
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{a.name}.json").write_text(json.dumps(res, indent=2) + "\n")
    report(res)


if __name__ == "__main__":
    main()
