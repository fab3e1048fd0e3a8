#!/usr/bin/env python3
"""Lattice table encodings, measured through the `lattice` command itself: for the Plate 3 hair
at sigma^-1 = 1, 2, 4 and every encoding, build time and bytes (rasterize --stats) and the
certified error (inspect --json); then Plates 4 and 5 rendered in lattice mode with each
encoding, point-sampled (sigma^-1 = 1, --filter none, 2 threads), and with the coverage encoding
also smoothed (the default filter, levels of detail on): render time, peak memory and PSNR against
exact mode.
Writes bench/results/encodings.json and prints a Markdown summary."""
import json
import os
import subprocess
import sys
import tempfile

LATTICE = sys.argv[1] if len(sys.argv) > 1 else "build/bin/lattice"
OUT = sys.argv[2] if len(sys.argv) > 2 else "bench/results"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HAIR = os.path.join(ROOT, "examples", "plate3-hair-closeup.json")
PLATES = ["plate4-fuzzy-sphere-1000", "plate5-fuzzy-sphere-5000"]


def run(*args):
    return subprocess.run([LATTICE, *args], check=True, capture_output=True, text=True).stdout


def encodings():
    text = run("rasterize", "--help")
    line = next(l for l in text.splitlines() if "Lattice table encoding:" in l)
    return [e.strip() for e in line.split("encoding:")[1].split(",")]


def main():
    os.makedirs(OUT, exist_ok=True)
    work = tempfile.mkdtemp(prefix="lattice-bench-")
    results = {"tables": [], "renders": []}
    for enc in encodings():
        for k in (1, 2, 4):
            table = os.path.join(work, f"hair-{enc}-{k}.lht")
            stats = os.path.join(work, "stats.json")
            run("rasterize", "-q", HAIR, "--primitive", "hair", "--sigma-inv", str(k),
                "--encoding", enc, "-o", table, "--stats", stats, "--threads", "2")
            s = json.load(open(stats))
            cert = json.loads(run("inspect", table, "--json", "--threads", "2"))["certified"]
            results["tables"].append({
                "encoding": enc, "sigma_inv": k, "stored_hits": s["stored_hits"],
                "table_bytes": s["table_bytes"], "bytes_per_hit": s["bytes_per_hit"],
                "build_seconds": s["rasterize_seconds"] + s["encode_seconds"],
                "encode_seconds": s["encode_seconds"], "peak_memory_bytes": s["peak_memory_bytes"],
                "certified": cert})
            os.remove(table)
    for plate in PLATES:
        scene = os.path.join(ROOT, "examples", plate + ".json")
        exact = os.path.join(work, plate + "-exact.png")
        stats = os.path.join(work, "stats.json")
        run("render", "-q", scene, "-o", exact, "--threads", "2", "--stats", stats)
        e = json.load(open(stats))
        results["renders"].append({"plate": plate, "mode": "exact", "render_ms": e["render_ms"],
                                   "peak_memory_bytes": e["peak_memory_bytes"], "psnr_db": None})
        # Every encoding point-sampled (--filter none: with the coverage encoding the default
        # filter would be smooth, with its levels of detail), then coverage with the default
        # filter (smooth: this hair, 19 parts, is answered from sub-rays, with one table) as
        # its own row.
        for enc, filt, label in [(e, "none", e) for e in encodings()] + [
                ("coverage", "smooth", "coverage smooth")]:
            img = os.path.join(work, f"{plate}-{enc}-{filt}.png")
            args = ["render", "-q", scene, "-o", img, "--threads", "2", "--mode", "lattice",
                    "--encoding", enc, "--filter", filt, "--lattice-dir", work, "--stats", stats]
            run(*args)  # builds the table
            run(*args)  # timed: cached
            l = json.load(open(stats))
            cmp = json.loads(run("compare", exact, img, "--json"))
            results["renders"].append({
                "plate": plate, "mode": "lattice", "encoding": label, "render_ms": l["render_ms"],
                "peak_memory_bytes": l["peak_memory_bytes"], "table_bytes": l["table_bytes"],
                "psnr_db": cmp["psnr_db"], "share_over_8": cmp["share_over_threshold"]})
    json.dump(results, open(os.path.join(OUT, "encodings.json"), "w"), indent=2)

    print("## Lattice table encodings (Plate 3 hair)\n")
    print("| encoding | sigma^-1 | stored hits | bytes | bytes/hit | build s | max point err (sigma) "
          "| max normal err (deg) | false hits | false misses |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for t in results["tables"]:
        c = t["certified"]
        print(f"| {t['encoding']} | {t['sigma_inv']} | {t['stored_hits']} | {t['table_bytes']} "
              f"| {t['bytes_per_hit']:.2f} | {t['build_seconds']:.2f} | {c['max_point_error_sigma']:.4f} "
              f"| {c['max_normal_error_deg']:.3f} | {c['false_hits']} | {c['false_misses']} |")
    print("\n## Plates 4 and 5 by encoding (sigma^-1 = 1, 2 threads)\n")
    print("| plate | mode | render ms | peak memory MB | PSNR vs exact (dB) |")
    print("| --- | --- | ---: | ---: | ---: |")
    for r in results["renders"]:
        mode = r["mode"] + (f" {r['encoding']}" if r["mode"] == "lattice" else "")
        p = r["psnr_db"]
        psnr = "-" if p is None else (p if isinstance(p, str) else f"{p:.2f}")
        print(f"| {r['plate']} | {mode} | {r['render_ms']:.1f} | "
              f"{r['peak_memory_bytes'] / 2**20:.1f} | {psnr} |")
    print()


if __name__ == "__main__":
    main()
