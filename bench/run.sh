#!/usr/bin/env bash
# make bench: runs every bench/*_bench program, writes bench/results/<name>.json (Google
# Benchmark's JSON) and bench/results/summary.md (a readable table of all of them).
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
echo "== encodings (through the lattice command)"
python3 "$here/encodings.py" "$build/bin/lattice" "$out" > "$out/encodings.md"
{ python3 "$here/summarize.py" "$out"; cat "$out/encodings.md"; } > "$out/summary.md"
echo
cat "$out/summary.md"
echo "results: $out"
