"""Table lookups from Python: one call over 10^6 pairs as arrays against a Python loop of single
lookups, per pair (docs/python.md). Usage: python_lookup.py BUILD_DIR RESULTS_DIR > python_lookup.md"""
import json
import os
import sys
import tempfile
import time

build, out = sys.argv[1], sys.argv[2]
sys.path.insert(0, os.path.join(build, "python"))
import numpy as np  # noqa: E402

import lattice  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
with open(os.path.join(here, "..", "examples", "plate4-fuzzy-sphere-1000.json")) as f:
    scene = lattice.Scene(json.load(f))
rows = []
with tempfile.TemporaryDirectory() as tmp:
    for encoding in ("hash14", "dense"):
        table = lattice.rasterize(scene, "hair", output=os.path.join(tmp, encoding + ".lht"), encoding=encoding)
        entry, exit_ = table.pairs()
        idx = np.resize(np.arange(len(entry)), 1_000_000)
        ea, eb = entry[idx], exit_[idx]
        start = time.perf_counter()
        table.lookup(ea, eb)
        array_ns = (time.perf_counter() - start) / len(ea) * 1e9
        loop = 20_000
        start = time.perf_counter()
        for i in range(loop):
            table.lookup(ea[i:i + 1], eb[i:i + 1])
        loop_ns = (time.perf_counter() - start) / loop * 1e9
        rows.append({"encoding": encoding, "array_ns_per_pair": array_ns, "loop_ns_per_pair": loop_ns,
                     "ratio": loop_ns / array_ns})
with open(os.path.join(out, "python_lookup.json"), "w") as f:
    json.dump(rows, f, indent=2)
print("| encoding | one call, 10^6 pairs (ns/pair) | Python loop of single lookups (ns/pair) | ratio |")
print("| --- | ---: | ---: | ---: |")
for r in rows:
    print(f"| {r['encoding']} | {r['array_ns_per_pair']:.1f} | {r['loop_ns_per_pair']:.0f} | {r['ratio']:.0f}x |")
