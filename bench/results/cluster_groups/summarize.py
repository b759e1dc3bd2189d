#!/usr/bin/env python3
"""Summarizes before_after.sh's runs: for each mesh, ray kind and query, the
layout's ratio to Embree's default build in every run of each binary (the
ratio comes from one run, the peer measured beside it), as a Markdown table.
    summarize.py OUT [LAYOUT]"""
import csv
import glob
import os
import statistics
import sys

out = sys.argv[1]
layout = sys.argv[2] if len(sys.argv) > 2 else "OctTreeCompressed/ClusterBitPackSOA8"
ratios = {}  # (mesh, rays, query) -> side -> [ratio]
ns = {}
order = []
for path in sorted(glob.glob(os.path.join(out, "run*_*/peers.csv"))):
    side = os.path.basename(os.path.dirname(path)).split("_")[1]
    with open(path) as f:
        for row in csv.DictReader(f):
            if row["contender"] != layout:
                continue
            key = (row["mesh"], row["rays"], row["query"])
            if key not in ratios:
                order.append(key)
            ratios.setdefault(key, {}).setdefault(side, []).append(float(row["ratio_to_embree_default"]))
            ns.setdefault(key, {}).setdefault(side, []).append(float(row["ns_per_ray"]))
print("| mesh | rays | query | before: x Embree (runs) | after: x Embree (runs) | after ns/ray | after/before |")
print("|---|---|---|---|---|---:|---:|")
news = []
for key in order:
    r = ratios[key]
    old, new = r.get("old", []), r.get("new", [])
    if not old or not new:
        continue
    mo, mn = statistics.median(old), statistics.median(new)
    news.append(mn)
    fmt = lambda v: ", ".join(f"{x:.2f}" for x in v)
    print(f"| {key[0]} | {key[1]} | {key[2]} | {mo:.2f} ({fmt(old)}) | {mn:.2f} ({fmt(new)}) | "
          f"{statistics.median(ns[key]['new']):.0f} | {mn / mo:.2f} |")
if news:
    print(f"\nafter: rows {len(news)}, median {statistics.median(news):.2f}, worst {max(news):.2f}, "
          f"rows at most 1.15: {sum(x <= 1.15 for x in news)}")
