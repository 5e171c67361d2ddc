"""Orbit-phase figures of `bench --stream` runs: first frame, median, 95th percentile and the
slowest frame after the first (column wall_ms, phase orbit), the still phase's slowest, and
nvidia-smi's peak (MiB) where logged.

    python3 orbit.py big-1-mem2 big-2-mem2 ...   # NAME.csv.gz, smi-NAME.log
"""
import csv, gzip, os, statistics, sys

print("| run | first frame ms | median ms | 95th pct ms | slowest after the first ms | slowest still ms | nvidia-smi peak MiB |")
print("|---|---:|---:|---:|---:|---:|---:|")
for name in sys.argv[1:]:
    rows = list(csv.DictReader(gzip.open(f"{name}.csv.gz", "rt")))
    orbit = [float(r["wall_ms"]) for r in rows if r["phase"] == "orbit"]
    still = [float(r["wall_ms"]) for r in rows if r["phase"] != "orbit"]
    ranked = sorted(orbit)
    p95 = ranked[int(0.95 * (len(ranked) - 1))]
    smi = "–"
    if os.path.exists(f"smi-{name}.log"):
        used = [int(l.split(",")[1].split()[0]) for l in open(f"smi-{name}.log") if "MiB" in l]
        smi = str(max(used)) if used else "–"
    print(f"| {name} | {orbit[0]:.1f} | {statistics.median(orbit):.2f} | {p95:.2f} | {max(orbit[1:]):.2f} | {max(still) if still else float('nan'):.2f} | {smi} |")
