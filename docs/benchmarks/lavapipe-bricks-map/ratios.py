"""fps of each bricked build over one texture's, per case and median (the README's table).

    python3 docs/benchmarks/lavapipe-bricks-map/ratios.py docs/benchmarks/lavapipe-bricks-map
"""
import collections
import csv
import statistics
import sys
from pathlib import Path

root = Path(sys.argv[1])
builds = [p.name for p in sorted(root.iterdir()) if (p / "frames.csv").exists() and p.name != "one"]


def medians(build):
    times = collections.defaultdict(list)
    for r in csv.DictReader(open(root / build / "frames.csv")):
        times[(r["dataset"], r["mode"], r["strategy"], r["width"])].append(float(r["ms"]))
    return {k: statistics.median(v) for k, v in times.items()}


one = medians("one")
ms = {b: medians(b) for b in builds}
print("| case | " + " | ".join(builds) + " |")
print("|---|" + "---:|" * len(builds))
for k in sorted(one):
    print(f"| {' '.join(k)} | " + " | ".join(f"{one[k] / ms[b][k]:.2f}" for b in builds) + " |")
print("| **median** | " + " | ".join(
    f"**{statistics.median(one[k] / ms[b][k] for k in one):.2f}**" for b in builds) + " |")
