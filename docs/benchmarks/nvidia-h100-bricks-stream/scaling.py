#!/usr/bin/env python3
"""Plots how load, first picture, frame time and completion grow with the volume: reads the
summaries (`leapview bench --stream`'s stream.md, as RUN.md) of four runs, 256³, 512³, 1024³ and
2048 × 2048 × 1024, in one folder, and writes scaling.svg, log-log.

    python3 scaling.py                       # §15: stream-13, built at 5d4db34
    python3 scaling.py stream-5 v256-1g v512-1g v1024-1g big-cur ca37d6f   # §8
"""
import math
import re
import sys
from pathlib import Path

here = Path(__file__).parent
folder, *runs, build = sys.argv[1:] or ["stream-13", "v256-1g-m6", "v512-1g-m6", "v1024-1g-m6", "big-m6", "5d4db34"]
series = {"load": [], "first picture": [], "frame median": [], "frame 95th pct": [], "complete": []}
voxels = []
for run in runs:
    text = (here / folder / f"{run}.md").read_text()
    dims = [int(d) for d in re.search(r"volume: (\d+)×(\d+)×(\d+)", text).groups()]
    voxels.append(dims[0] * dims[1] * dims[2])
    series["load"].append(float(re.search(r"loaded in ([\d.]+) s", text).group(1)) * 1e3)
    series["first picture"].append(float(re.search(r"first picture: ([\d.]+) ms", text).group(1)))
    m = re.search(r"median ([\d.]+) ms, 95th percentile ([\d.]+) ms", text)
    series["frame median"].append(float(m.group(1)))
    series["frame 95th pct"].append(float(m.group(2)))
    series["complete"].append(float(re.search(r"complete at ([\d.]+) ms", text).group(1)))

W, H, L, B, T, R = 740, 440, 90, 50, 20, 150
xs = [math.log10(v) for v in voxels]
ys = [math.log10(y) for s in series.values() for y in s]
x0, x1 = min(xs) - 0.1, max(xs) + 0.1
y0, y1 = math.floor(min(ys)), math.ceil(max(ys))
px = lambda x: L + (x - x0) / (x1 - x0) * (W - L - R)
py = lambda y: H - B - (y - y0) / (y1 - y0) * (H - B - T)
out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
       f'<rect width="{W}" height="{H}" fill="white"/>']
for e in range(y0, y1 + 1):
    y = py(e)
    out.append(f'<line x1="{L}" y1="{y:.1f}" x2="{W - R}" y2="{y:.1f}" stroke="#ddd"/>')
    out.append(f'<text x="{L - 6}" y="{y + 4:.1f}" text-anchor="end">{10 ** e:g} ms</text>')
labels = ["256³", "512³", "1024³", "2048²×1024"]
for x, label in zip(xs, labels):
    out.append(f'<line x1="{px(x):.1f}" y1="{T}" x2="{px(x):.1f}" y2="{H - B}" stroke="#eee"/>')
    out.append(f'<text x="{px(x):.1f}" y="{H - B + 16}" text-anchor="middle">{label}</text>')
out.append(f'<text x="{W / 2}" y="{H - 8}" text-anchor="middle">vessel trees, 1 GB budget, 1920×1080, H100, {build}; 256³, 512³ one texture, larger ones streamed bricks</text>')
colours = ["#444", "#1f77b4", "#2ca02c", "#98df8a", "#d62728"]
for (name, values), colour, k in zip(series.items(), colours, range(5)):
    points = " ".join(f"{px(x):.1f},{py(math.log10(v)):.1f}" for x, v in zip(xs, values))
    out.append(f'<polyline points="{points}" fill="none" stroke="{colour}" stroke-width="2"/>')
    for x, v in zip(xs, values):
        out.append(f'<circle cx="{px(x):.1f}" cy="{py(math.log10(v)):.1f}" r="3" fill="{colour}"/>')
    out.append(f'<text x="{W - R + 10}" y="{T + 16 + 18 * k}" fill="{colour}">{name}</text>')
out.append("</svg>")
(here / "scaling.svg").write_text("\n".join(out) + "\n")
print("wrote", here / "scaling.svg")
