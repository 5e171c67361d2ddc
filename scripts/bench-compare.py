#!/usr/bin/env python3
"""Compares `leapview bench` runs frame by frame: median ms per (dataset, mode, size, strategy),
each leaping strategy against RC-t of the same run, and the last run against the first.

    scripts/bench-compare.py RUN_DIR_A RUN_DIR_B [...] [--modes mip,minip] [--markdown]

Each RUN_DIR holds a frames.csv written by `leapview bench` (several binaries run one after the
other on one machine in one call, as docs/benchmarks/nvidia-h200-leap-walk/README.md describes).
"""
import csv
import statistics
import sys
from collections import defaultdict


def load(run):
    ms, samples = defaultdict(list), defaultdict(list)
    with open(f"{run}/frames.csv") as f:
        for r in csv.DictReader(f):
            if r["sweep"] == "true":
                continue
            # The path beside the size: runs of both paths are compared path by path.
            size = f"{r['width']}x{r['height']}" + (f" {r['path']}" if r.get("path") else "")
            key = (r["dataset"], r["mode"], size, r["strategy"])
            ms[key].append(float(r["ms"]))
            samples[key].append(int(r["samples"]))
    return {k: (statistics.median(v), statistics.median(samples[k])) for k, v in ms.items()}


def main(argv):
    modes = None
    markdown = "--markdown" in argv
    args = [a for a in argv if a != "--markdown"]
    if "--modes" in args:
        i = args.index("--modes")
        modes = set(args[i + 1].split(","))
        del args[i : i + 2]
    if len(args) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    runs = [load(a) for a in args]
    first, last = runs[0], runs[-1]
    head = ["dataset", "mode", "size", "strategy"]
    for name in args:
        head += [f"{name} ms", f"{name} × RC-t fps", f"{name} rate / RC-t"]
    head.append("last / first ms")
    if markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
    else:
        print("\t".join(head))
    for key in sorted(first):
        dataset, mode, size, strategy = key
        if strategy == "RC-t" or (modes and mode not in modes) or key not in last:
            continue
        cells = [dataset, mode, size, strategy]
        for run in runs:
            ms, samples = run[key]
            t_ms, t_samples = run[(dataset, mode, size, "RC-t")]
            rate = (samples / ms) / (t_samples / t_ms) if t_samples else float("nan")
            cells += [f"{ms:.3f}", f"{t_ms / ms:.2f}", f"{rate:.2f}"]
        cells.append(f"{last[key][0] / first[key][0]:.2f}")
        print(("| " + " | ".join(cells) + " |") if markdown else "\t".join(cells))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
