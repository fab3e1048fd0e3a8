#!/usr/bin/env bash
# make bench: runs every bench/*_bench program, writes bench/results/<name>.json (Google
# Benchmark's JSON) and bench/results/summary.md (a readable table of all of them), then the
# encodings, complexity, independent-tracer, modes, sampler, scatter and scale benchmarks through the
# lattice command (and docs/images/complexity.png, docs/images/scale.png).
set -euo pipefail
build=${1:-build}
here=$(cd "$(dirname "$0")" && pwd)
out=$here/results
mkdir -p "$out"
for exe in "$build"/bin/*_bench; do
  name=$(basename "$exe")
  echo "== $name"
  "$exe" --benchmark_out="$out/$name.json" --benchmark_out_format=json \
         --benchmark_counters_tabular=true
done
echo "== rasterize (pairs/s of the whole lattice rasterize command; its table joins the summary)"
python3 "$here/rasterize.py" "$build/bin/lattice" "$out" > "$out/rasterize.md"
echo "== encodings (through the lattice command)"
python3 "$here/encodings.py" "$build/bin/lattice" "$out" > "$out/encodings.md"
echo "== complexity (exact against lattice mode as the primitive grows; docs/complexity.md)"
python3 "$here/complexity.py" "$build/bin/lattice" "$out" --work "$build/complexity" > "$out/complexity.md"
echo "== exact mode against an independent Embree tracer (docs/complexity.md)"
python3 "$here/embree_tracer.py" "$build/bin/lattice" "$build/bin/embree_tracer" "$out" --work "$build/embree_tracer" > "$out/embree_tracer.md"
echo "== modes (where lattices pay: every mode against exact mode at its best, at equal time and fidelity)"
python3 "$here/modes.py" "$build/bin/lattice" "$out" --work "$build/modes" > "$out/modes.md"
echo "== samplers (where a pixel's samples fall, at 2 to 16 spp; the truths are modes')"
python3 "$here/samplers.py" "$build/bin/lattice" "$out" --work "$build/modes" > "$out/samplers.md"
echo "== scatter (fur on a mesh, 100,000 instances)"
python3 "$here/scatter.py" "$build/bin/lattice" "$out" > "$out/scatter.md"
echo "== scale (hairs on the bunny, 20,000 to 10 million, exact, lattice and auto mode; about 15 minutes with its truths cached)"
python3 "$here/scale.py" "$build/bin/lattice" "$out" --work "$build/scale" > "$out/scale.md"
echo "== MPI (2 ranks x 1 thread against 1 rank x 2 threads; docs/distributed.md)"
if command -v mpirun > /dev/null && "$build/bin/lattice" --version | grep -q "with MPI"; then
  python3 "$here/distributed.py" "$build/bin/lattice" "$out" > "$out/distributed.md"
else
  echo "(skipped: the build did not find MPI)" > "$out/distributed.md"
fi
echo "== Python module: table lookups over arrays against a loop of single lookups (docs/python.md)"
if [ -d "$build/python" ]; then
  /usr/bin/python3 "$here/python_lookup.py" "$build" "$out" > "$out/python_lookup.md"
else
  echo "(skipped: the build has no Python module)" > "$out/python_lookup.md"
fi
# matplotlib is Debian's python3-matplotlib: plot with Debian's python3 even when another one
# (pyenv, a virtualenv) comes first in PATH.
py=/usr/bin/python3; [ -x "$py" ] || py=python3
"$py" "$here/plot_complexity.py" "$out/complexity.json" "$here/../docs/images/complexity.png"
"$py" "$here/plot_scale.py" "$out/scale.json" "$here/../docs/images/scale.png" "$out/scale-before.json"
{ python3 "$here/summarize.py" "$out"; cat "$out/encodings.md" "$out/complexity.md" "$out/embree_tracer.md" "$out/modes.md" "$out/samplers.md" "$out/scatter.md" "$out/scale.md" "$out/distributed.md" "$out/python_lookup.md"; } > "$out/summary.md"
echo
cat "$out/rasterize.md" >> "$out/summary.md"
cat "$out/summary.md"
echo "results: $out"
