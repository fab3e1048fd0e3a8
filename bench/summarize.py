#!/usr/bin/env python3
"""Turns bench/results/*.json (Google Benchmark output) into one Markdown table per file."""
import json
import pathlib
import sys


def fmt(v):
    if isinstance(v, float):
        if abs(v) >= 1e6:
            return f"{v / 1e6:.2f} M"
        if abs(v) >= 1e3:
            return f"{v / 1e3:.2f} k"
        return f"{v:.3g}"
    return str(v)


def main(results):
    print("# Benchmark results\n")
    for path in sorted(pathlib.Path(results).glob("*.json")):
        data = json.loads(path.read_text())
        if "benchmarks" not in data:
            continue  # not Google Benchmark output: encodings.json, samplers.json ... have their own
        ctx = data.get("context", {})
        print(f"## {path.stem}\n")
        print(f"{ctx.get('date', '')}, {ctx.get('num_cpus', '?')} CPUs at "
              f"{ctx.get('mhz_per_cpu', '?')} MHz\n")
        rows = [b for b in data.get("benchmarks", []) if b.get("run_type") != "aggregate"
                or b.get("aggregate_name") == "median"]
        counters = []
        skip = {"name", "run_name", "run_type", "repetitions", "repetition_index", "threads",
                "iterations", "real_time", "cpu_time", "time_unit", "family_index",
                "per_family_instance_index", "aggregate_name", "aggregate_unit", "label",
                "error_occurred", "error_message"}
        for b in rows:
            for k in b:
                if k not in skip and k not in counters:
                    counters.append(k)
        print("| benchmark | time | " + " | ".join(counters) + " |")
        print("| --- | ---: | " + " | ".join("---:" for _ in counters) + " |")
        for b in rows:
            t = f"{b['real_time']:.3g} {b.get('time_unit', 'ns')}"
            print(f"| {b['name']} | {t} | " + " | ".join(fmt(b.get(k, "")) for k in counters) + " |")
        print()


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "bench/results")
