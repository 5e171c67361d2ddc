"""Frame figures of `leapview bench --stream` runs: the first frame, median, 95th percentile
and slowest frame after the first (column wall_ms), and nvidia-smi's peak (MiB) where a
smi-NAME.log lies beside NAME.csv.gz.

    python3 orbit.py DIR NAME...              # the orbit phase; the still phase's slowest
    python3 orbit.py --until-complete DIR NAME...
        # every frame up to the one that completes the stream (the frame after the last with
        # a brick missing; an orbit longer than the stream, `--stream-frames 2000`), with its
        # time after the upload started and the count of frames above 16 ms
"""
import csv, gzip, os, statistics, sys

args = sys.argv[1:]
until = args[0] == "--until-complete"
if until:
    args = args[1:]
root, names = args[0], args[1:]


def smi_peak(name):
    path = os.path.join(root, f"smi-{name}.log")
    if not os.path.exists(path):
        return "–"
    used = [int(l.split(",")[1].split()[0]) for l in open(path) if "MiB" in l]
    return str(max(used)) if used else "–"


def p95(ms):
    ranked = sorted(ms)
    return ranked[int(0.95 * (len(ranked) - 1))]


rows_of = lambda name: list(csv.DictReader(gzip.open(os.path.join(root, f"{name}.csv.gz"), "rt")))
if until:
    print("| run | frames | complete ms | first frame ms | median ms | 95th pct ms | slowest after the first ms | above 16 ms | nvidia-smi peak MiB |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name in names:
        rows = rows_of(name)
        done = max(i for i, r in enumerate(rows) if int(r["missing"]) > 0) + 1
        ms = [float(r["wall_ms"]) for r in rows[: done + 1]]
        after = ms[1:]
        print(f"| {name} | {len(ms)} | {float(rows[done]['since_upload_ms']):.0f} | {ms[0]:.1f} | {statistics.median(after):.2f} | {p95(after):.2f} | {max(after):.2f} | {sum(m > 16 for m in after)} | {smi_peak(name)} |")
else:
    print("| run | first frame ms | median ms | 95th pct ms | slowest after the first ms | slowest still ms | nvidia-smi peak MiB |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name in names:
        rows = rows_of(name)
        orbit = [float(r["wall_ms"]) for r in rows if r["phase"] == "orbit"]
        still = [float(r["wall_ms"]) for r in rows if r["phase"] != "orbit"]
        print(f"| {name} | {orbit[0]:.1f} | {statistics.median(orbit):.2f} | {p95(orbit):.2f} | {max(orbit[1:]):.2f} | {max(still) if still else float('nan'):.2f} | {smi_peak(name)} |")
