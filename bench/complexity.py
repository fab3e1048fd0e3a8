#!/usr/bin/env python3
"""Complexity benchmark: exact mode against lattice mode as the primitive grows.

For every scene of bench/complexity_scenes.py (Plate 4's placement and camera, primitives
from the 19-part hair to a 10,000-part tuft and CSG of 1 to 12 tori), through the `lattice`
command itself:
  1. builds each encoding's table into WORK/cache with `lattice rasterize` (build time, bytes;
     an encoding that refuses the primitive is skipped and its message recorded);
  2. renders the scene without its instances, exact mode and lattice mode per encoding, RUNS
     times each, interleaved so that load from other processes hits all alike; the median
     render_ms is kept (and the minimum, in the JSON);
  3. compares each lattice image with the exact one (`lattice compare --json`: PSNR);
  4. takes lattice visits from render --stats (lattice_visits; bench/lattice_visits splits
     them by kind) and estimates the CPU time per visit as (lattice ms - ms of the scene without its
     instances) x threads / visits: everything the instances add, Embree traversal included.
Then the same for the costly-primitive check class (complexity_scenes.CHECKS: 400 instances on a ball),
with the target ratio for each; and, for the burr (ball-csg7), every way of answering it (exact at
1 and 4 spp, lattice mode with and without levels of detail): render time, cold build time,
PSNR against exact at 256 spp, table bytes and visits (`--only burr` runs that alone).
Writes OUT/complexity.json and prints a Markdown summary.

Usage: complexity.py LATTICE_BIN OUT_DIR [--work DIR] [--size N] [--runs N] [--threads N]
                     [--encodings a,b] [--only name,...,burr] [--burr-cold]"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.dont_write_bytecode = True  # no bench/__pycache__ in the source tree
import complexity_scenes  # noqa: E402


def run(cmd):
    """Runs a command; returns (exit code, stdout, stderr) without raising."""
    p = subprocess.run(cmd, capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def check(cmd):
    code, out, err = run(cmd)
    if code:
        sys.exit(f"complexity.py: {' '.join(cmd)} failed ({code}): {err.strip()}")
    return out


def render(a, scene, image, *extra):
    stats = os.path.join(a.work, "stats.json")
    check([a.lattice, "render", "-q", scene, "-o", image, "--threads", str(a.threads),
           "--stats", stats, *extra])
    return json.load(open(stats))


def lattice_args(a, enc):
    return ["--mode", "lattice", "--encoding", enc, "--sigma-inv", str(a.sigma_inv),
            "--lattice-dir", a.cache]


def fmt_db(v):
    return f"{v:.2f}" if isinstance(v, (int, float)) else str(v)  # identical images: "inf"


def without_instances(a, name):
    """The scene without its instances: what the sphere, floor and shading cost alone."""
    s = json.load(open(os.path.join(a.work, "scenes", name + ".json")))
    s["objects"] = [o for o in s["objects"] if o["type"] != "instance"]
    path = os.path.join(a.work, "scenes", "base.json")
    json.dump(s, open(path, "w"))
    return path


def family(name):
    if name in complexity_scenes.CHECKS:
        return "check"
    return "csg" if name.startswith("csg") else "spheres+cylinders"


def bench_primitive(a, name, cost):
    scene = os.path.join(a.work, "scenes", name + ".json")
    r = {"primitive": name, "cost": cost, "loadavg": os.getloadavg()[0],
         "family": family(name), "lattice": {}}
    encs = []
    for enc in a.encodings:  # build tables first, timed apart from rendering
        stats = os.path.join(a.work, "rasterize.json")
        t0 = time.time()
        code, _, err = run([a.lattice, "rasterize", "-q", scene, "--primitive", name,
                            "--encoding", enc, "--sigma-inv", str(a.sigma_inv), "--lattice-dir",
                            a.cache, "--threads", str(a.threads), "--stats", stats])
        if code:  # how long the refusal took matters too: it may come after the rasterization
            r["lattice"][enc] = {"refused": err.strip().removeprefix("lattice: "),
                                 "exit_code": code, "refused_after_s": time.time() - t0}
            continue
        s = json.load(open(stats))
        r["lattice"][enc] = {"build_s": s["rasterize_seconds"] + s["encode_seconds"],
                             "table_bytes": s["table_bytes"], "stored_hits": s["stored_hits"],
                             "N_lp": s["N_lp"], "runs_ms": []}
        encs.append(enc)
    exact_png = os.path.join(a.work, name + "-exact.png")
    base, base_png = without_instances(a, name), os.path.join(a.work, "base.png")
    r["exact_runs_ms"], r["base_runs_ms"] = [], []
    for _ in range(a.runs):  # interleaved: base, exact, then every encoding, RUNS times
        r["base_runs_ms"].append(render(a, base, base_png)["render_ms"])
        e = render(a, scene, exact_png)
        r["exact_runs_ms"].append(e["render_ms"])
        r["rays"] = e["primary_rays"] + e["shadow_rays"]
        for enc in encs:
            png = os.path.join(a.work, f"{name}-{enc}.png")
            s = render(a, scene, png, *lattice_args(a, enc))
            assert s["tables_built"] == 0, "the table should have come from the cache"
            r["lattice"][enc]["runs_ms"].append(s["render_ms"])
            r["lattice"][enc]["rays"] = s["primary_rays"] + s["shadow_rays"]
            r["lattice"][enc]["lattice_visits"] = s.get("table_visits")
    r["exact_ms"] = statistics.median(r["exact_runs_ms"])
    r["exact_min_ms"] = min(r["exact_runs_ms"])
    r["base_ms"] = base_ms = statistics.median(r["base_runs_ms"])
    for enc in encs:
        L = r["lattice"][enc]
        L["ms"] = statistics.median(L["runs_ms"])
        L["min_ms"] = min(L["runs_ms"])
        cmp = json.loads(check([a.lattice, "compare", exact_png,
                                os.path.join(a.work, f"{name}-{enc}.png"), "--json"]))
        L["psnr_db"] = cmp["psnr_db"]
        visits = L.get("lattice_visits")  # measured by the renderer (render --stats)
        if os.path.exists(a.visits):  # the split by kind, from the counting wrapper
            v = json.loads(check([a.visits, scene, "--threads", str(a.threads),
                                  "--lattice-dir", a.cache, "--encoding", enc,
                                  "--sigma-inv", str(a.sigma_inv)]))
            L["visits"] = {k: v[k] for k in ("intersect", "occluded", "spans", "shading_calls")}
            if visits is None:  # a renderer from before render --stats reported them
                visits = v["intersect"] + v["occluded"] + v["spans"]
        if visits is not None:
            L["visits_per_ray"] = visits / L["rays"]
            L["ns_per_visit_est"] = ((L["ms"] - base_ms) * 1e6 * a.threads / visits
                                     if visits else None)
    return r


def fmt_ms(v):
    return f"{v:.1f}" if v < 100 else f"{v:.0f}"


def best_lattice(r):
    """(encoding, ms) of the fastest lattice encoding that built, or None."""
    done = [(e, L["ms"]) for e, L in r["lattice"].items() if "ms" in L]
    return min(done, key=lambda x: x[1]) if done else None


def markdown_checks(res):
    rows = res.get("checks", [])
    if not rows:
        return
    c = res["config"]
    print(f"## The costly-primitive check class: {complexity_scenes.BALL_INSTANCES} instances on a ball\n")
    print("The check class is several hundred instances on a sphere; "
          "these are its stand-ins (bench/complexity_scenes.py), same settings as above: "
          f"{c['size']} x {c['size']}, {c['threads']} threads, median of {c['runs']}, "
          "tables cached. The ratio depends on how much of the image the instances cover: "
          "the ball and floor alone cost the same in both modes.\n")
    print("| scene | parts / leaves | no instances ms | exact ms | best lattice ms | "
          "exact / best lattice | target | met |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    for r in rows:
        best = best_lattice(r)
        target = complexity_scenes.CHECKS[r["primitive"]][2]
        if best is None:
            print(f"| {r['primitive']} | {r['cost']} | {fmt_ms(r['base_ms'])} | "
                  f"{fmt_ms(r['exact_ms'])} | none built | - | {target:g} | no |")
            continue
        ratio = r["exact_ms"] / best[1]
        print(f"| {r['primitive']} | {r['cost']} | {fmt_ms(r['base_ms'])} | "
              f"{fmt_ms(r['exact_ms'])} | {fmt_ms(best[1])} ({best[0]}) | {ratio:.2f} | "
              f"{target:g} | {'yes' if ratio >= target else 'no'} |")
    print()


def markdown(res):
    c = res["config"]
    encs = c["encodings"]
    print("## Complexity: exact against lattice mode as the primitive grows\n")
    print(f"Plate 4 placement (1000 instances), {c['size']} x {c['size']}, {c['threads']} threads, "
          f"sigma^-1 = {c['sigma_inv']}, median of {c['runs']} renders (render_ms); "
          f"load average {c['loadavg_start']:.1f} at start (timings are noisy when it exceeds "
          f"{c['cpus']}: compare within a row). Runs {c['seconds']:.0f} s.\n")
    print("| primitive | parts / leaves | load | no instances ms | exact ms | " + " | ".join(f"{e} ms" for e in encs)
          + " | exact / best lattice |")
    print("| --- | ---: | ---: | ---: | ---: | " + " | ".join("---:" for _ in encs) + " | ---: |")
    for r in res["primitives"]:
        cells, best = [], None
        for e in encs:
            L = r["lattice"][e]
            if "refused" in L:
                cells.append("refused")
            else:
                cells.append(fmt_ms(L["ms"]))
                best = L["ms"] if best is None else min(best, L["ms"])
        ratio = f"{r['exact_ms'] / best:.2f}" if best else "-"
        print(f"| {r['primitive']} | {r['cost']} | {r['loadavg']:.1f} | {fmt_ms(r['base_ms'])} | "
              f"{fmt_ms(r['exact_ms'])} | "
              + " | ".join(cells) + f" | {ratio} |")
    print("\n| primitive | encoding | ms | visits/ray | ns/visit (est.) | table bytes | build s "
          "| PSNR vs exact (dB) |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for r in res["primitives"] + res.get("checks", []):  # the ball scenes too
        for e in encs:
            L = r["lattice"][e]
            if "refused" in L:
                print(f"| {r['primitive']} | {e} | refused after {L['refused_after_s']:.1f} s "
                      f"(exit {L['exit_code']}): {L['refused']} | | | | | |")
                continue
            vpr = f"{L['visits_per_ray']:.2f}" if "visits_per_ray" in L else "n/a"
            nsv = L.get("ns_per_visit_est")
            nsv = f"{nsv:.0f}" if nsv is not None else "n/a"
            print(f"| {r['primitive']} | {e} | {fmt_ms(L['ms'])} | {vpr} | {nsv} | "
                  f"{L['table_bytes']} | {L['build_s']:.2f} | {fmt_db(L['psnr_db'])} |")
    print("\nvisits: calls of a lattice's intersect/occluded/spans (render --stats table_visits); "
          "ns/visit: (lattice ms - ms without instances) x threads / visits.\n")


# The burr check: how each mode answers the costly-primitive class (ball-csg7, 400 burrs: six
# tori minus a sphere), against a many-sample exact truth. Mode label -> render arguments.
BURR = "ball-csg7"
BURR_MODES = {
    "exact 1 spp": ["--mode", "exact"],
    "exact 4 spp": ["--mode", "exact", "--spp", "4"],
    "lattice": ["--mode", "lattice"],
    "lattice --filter box": ["--mode", "lattice", "--filter", "box"],
    "lattice --lod off": ["--mode", "lattice", "--lod", "off"],
    "auto": ["--mode", "auto"],
}
BURR_TRUTH_SPP = 256


def burr_builds(a, cache, label, stats):
    """The cold build time of the tables a lattice mode reads: measured when its first render built
    them, and kept beside the cache (build-times.json) for later runs that find them cached."""
    path = os.path.join(cache, "build-times.json")
    times = json.load(open(path)) if os.path.exists(path) else {}
    key = label + " " + ",".join(os.path.basename(f) for f in stats.get("table_files", []))
    if stats.get("tables_built"):
        times[key] = stats["tables_ms"] / 1000
        json.dump(times, open(path, "w"), indent=1)
    return times.get(key)


def bench_burr(a):
    """Render time, cold build time, PSNR against exact at BURR_TRUTH_SPP (stratified jitter,
    cached by the scene's bytes) and table bytes of each BURR_MODES mode; lattice modes also their
    table visits and notes (a fallback to sub-rays shows as a note and as what answered)."""
    import modes  # noqa: E402 (the truth is made as the modes benchmark makes it)
    scene = os.path.join(a.work, "scenes", BURR + ".json")
    cache = os.path.join(a.work, "burr-cache")
    if a.burr_cold and os.path.isdir(cache):
        for f in os.listdir(cache):
            os.remove(os.path.join(cache, f))
    os.makedirs(cache, exist_ok=True)
    truth = modes.ground_truth(a.lattice, scene, a.work, BURR_TRUTH_SPP)
    r = {"scene": BURR, "loadavg": os.getloadavg()[0], "modes": {}}
    images = {m: os.path.join(a.work, f"burr-{i}.png") for i, m in enumerate(BURR_MODES)}
    args = {m: v + (["--lattice-dir", cache] if v[1] != "exact" else [])
            for m, v in BURR_MODES.items()}
    for m in BURR_MODES:  # a first render builds what is not cached, timed apart
        s = render(a, scene, images[m], *args[m])
        r["modes"][m] = {"runs_ms": [], "build_s": burr_builds(a, cache, m, s)}
    base, base_png = without_instances(a, BURR), os.path.join(a.work, "base.png")
    r["base_runs_ms"] = []
    for _ in range(a.runs):  # interleaved, so that load from other processes hits all alike
        r["base_runs_ms"].append(render(a, base, base_png)["render_ms"])
        for m in BURR_MODES:
            s = render(a, scene, images[m], *args[m])
            assert s.get("tables_built", 0) == 0, "tables should have come from the cache"
            M = r["modes"][m]
            M["runs_ms"].append(s["render_ms"])
            M["table_bytes"] = s.get("table_bytes", 0)
            M["table_visits"] = s.get("table_visits", 0)
            M["notes"] = s.get("lattice_notes", [])
            M["how"] = "; ".join(p["how"] for p in s.get("primitives", []))
    r["base_ms"] = statistics.median(r["base_runs_ms"])
    for m, M in r["modes"].items():
        M["ms"] = statistics.median(M["runs_ms"])
        M["psnr_db"] = modes.psnr(a.lattice, images[m], truth)
        if M["table_visits"]:  # everything the instances add, per visit (as above)
            M["ns_per_visit_est"] = (M["ms"] - r["base_ms"]) * 1e6 * a.threads / M["table_visits"]
    return r


def markdown_burr(r):
    if not r:
        return
    print(f"## The burr: {complexity_scenes.BALL_INSTANCES} CSG of six tori minus a sphere\n")
    print(f"{BURR}, 512 x 512 unless --size says otherwise, 2 threads, median of the runs, "
          f"load average {r['loadavg']:.1f}; PSNR against exact mode at {BURR_TRUTH_SPP} spp "
          "(stratified jitter). Build s: the tables' cold build, when the first render built "
          "them (kept beside the cache for later runs). Tables answer in lattice mode when "
          "visits > 0 and no note says a level fell back.\n")
    print("| mode | render ms | build s (cold) | PSNR dB | table bytes | table visits | "
          "ns/visit (est.) | answered by | notes |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- | --- |")
    for m, M in r["modes"].items():
        build = f"{M['build_s']:.1f}" if M.get("build_s") is not None else "-"
        nsv = f"{M['ns_per_visit_est']:.0f}" if "ns_per_visit_est" in M else "-"
        print(f"| {m} | {fmt_ms(M['ms'])} | {build} | {fmt_db(M['psnr_db'])} | "
              f"{M['table_bytes']} | {M['table_visits']} | {nsv} | {M['how'] or 'exact'} | "
              f"{' '.join(M['notes']) or '-'} |")
    print(f"\nWithout its instances the scene renders in {fmt_ms(r['base_ms'])} ms; ns/visit: "
          "(render ms - that) x threads / table visits, everything the instances add.\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("lattice")
    ap.add_argument("out")
    ap.add_argument("--work", help="scenes, table cache and images (default: BUILD/complexity)")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--sigma-inv", type=int, default=1)
    ap.add_argument("--encodings", default="hash14,dense,candidates")
    ap.add_argument("--only", default="")
    ap.add_argument("--burr-cold", action="store_true",
                    help="empty the burr's table cache first, to time its cold build")
    a = ap.parse_args()
    a.lattice = os.path.abspath(a.lattice)
    a.visits = os.path.join(os.path.dirname(a.lattice), "lattice_visits")
    a.work = os.path.abspath(a.work or os.path.join(os.path.dirname(os.path.dirname(a.lattice)),
                                                     "complexity"))
    a.cache = os.path.join(a.work, "cache")
    a.encodings = a.encodings.split(",")
    os.makedirs(a.cache, exist_ok=True)
    names = (a.only.split(",") if a.only
             else list(complexity_scenes.PRIMITIVES) + list(complexity_scenes.CHECKS) + ["burr"])
    burr = "burr" in names
    names = [n for n in names if n != "burr"]
    check([sys.executable, os.path.join(HERE, "complexity_scenes.py"),
           os.path.join(a.work, "scenes"), "--size", str(a.size),
           "--only", ",".join(names + [BURR] if burr else names)])

    res = {"config": {"size": a.size, "runs": a.runs, "threads": a.threads,
                      "sigma_inv": a.sigma_inv, "encodings": a.encodings,
                      "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                      "cpus": os.cpu_count(), "loadavg_start": os.getloadavg()[0]},
           "primitives": [], "checks": []}
    t0 = time.time()
    for name in names:
        print(f"complexity: {name}", file=sys.stderr)
        check_class = name in complexity_scenes.CHECKS
        cost = (complexity_scenes.CHECKS if check_class else complexity_scenes.PRIMITIVES)[name][1]
        res["checks" if check_class else "primitives"].append(bench_primitive(a, name, cost))
    if burr:
        print("complexity: burr", file=sys.stderr)
        res["burr"] = bench_burr(a)
    res["config"]["seconds"] = time.time() - t0
    os.makedirs(a.out, exist_ok=True)
    json.dump(res, open(os.path.join(a.out, "complexity.json"), "w"), indent=2)
    if res["primitives"]:
        markdown(res)
    markdown_checks(res)
    markdown_burr(res.get("burr"))


if __name__ == "__main__":
    main()
