"""Per case median frame time (ms) of each build of one A/B run, from frames.csv files, and the
fps ratios over `one`'s (the README's tables).

    python3 medians.py RUN_DIR one,main,fp,fpc,ub > ab-1/medians.csv   # RUN_DIR/NAME-1/frames.csv
    python3 medians.py --ratios ab-1/medians.csv
"""
import collections
import csv
import statistics
import sys

if sys.argv[1] == "--ratios":
    rows = list(csv.DictReader(open(sys.argv[2])))
    builds = [k for k in rows[0] if k not in ("case", "one")]
    print("| case | one ms | " + " | ".join(builds) + " |")
    print("|---|---:|" + "---:|" * len(builds))
    ratios = collections.defaultdict(list)
    for r in rows:
        one = float(r["one"])
        cells = []
        for b in builds:
            x = one / float(r[b])
            ratios[b].append(x)
            cells.append(f"{x:.2f}")
        print(f"| {r['case']} | {one:.3f} | " + " | ".join(cells) + " |")
    print("| **median** | | " + " | ".join(f"**{statistics.median(ratios[b]):.2f}**" for b in builds) + " |")
    print("| lowest | | " + " | ".join(f"{min(ratios[b]):.2f}" for b in builds) + " |")
    sys.exit()
root, builds = sys.argv[1], sys.argv[2].split(",")
med = {}
for b in builds:
    t = collections.defaultdict(list)
    for r in csv.DictReader(open(f"{root}/{b}-1/frames.csv")):
        t[" ".join((r["dataset"], r["mode"], r["strategy"], r["path"], r["width"]))].append(float(r["ms"]))
    med[b] = {k: statistics.median(v) for k, v in t.items()}
print("case," + ",".join(builds))
for k in sorted(med[builds[0]]):
    print(k + "," + ",".join(f"{med[b][k]:.4f}" for b in builds))
