#!/usr/bin/env python3
"""The table of docs/benchmarks/pipeline-stages.md from the per-detection CSVs
of codemark-bench-pose-calib (scripts/bench-pipeline-stages.sh runs it).

Usage: pipeline-stages-table.py WORK NAME LABEL [NAME LABEL ...]
reads WORK/NAME.csv and WORK/NAME.log per row; the first row is the peer of
the ratios.
"""
import csv
import math
import re
import sys

BINS = [(0, 25), (25, 35), (35, 50), (50, 80), (80, math.inf)]
PEER_BIN = (25, 80)
# The prints codemark-bench-pose-calib --vary-scene cycles, in its order.
PRINTS = ["fluorescent", "inkjet", "laser"]


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else math.nan


def load(work, name):
    with open(f"{work}/{name}.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    with open(f"{work}/{name}.log") as f:
        m = re.search(r"^(\d+) detections, (\d+) missed", f.read(), re.M)
    if not m:
        sys.exit(f"pipeline-stages-table.py: {work}/{name}.log: no 'N detections, M missed' line")
    return rows, int(m.group(1)), int(m.group(2))


def errors(rows, lo, hi):
    """P's x and y errors of the detections whose apparent width is in [lo, hi)."""
    sel = [r for r in rows if lo <= float(r["width_px"]) < hi]
    ex = [float(r[k]) for r in sel for k in ("e_x1", "e_x2")]
    ey = [float(r[k]) for r in sel for k in ("e_y1", "e_y2")]
    return ex, ey


def fmt(v):
    return "-" if math.isnan(v) else f"{v:.3f}"


def main():
    if len(sys.argv) < 4 or len(sys.argv) % 2:
        sys.exit(__doc__)
    work = sys.argv[1]
    pairs = list(zip(sys.argv[2::2], sys.argv[3::2]))
    head = ["stages", "detected"]
    head += [f"x / y {lo}-{hi} px" if hi != math.inf else f"x / y >= {lo} px" for lo, hi in BINS]
    head += [f"{axis} {PEER_BIN[0]}-{PEER_BIN[1]} px" for axis in ("x", "y")]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    runs = [(label, *load(work, name)) for name, label in pairs]
    peer = None
    for label, rows, found, missed in runs:
        cells = [label, f"{100 * found / max(1, found + missed):.1f}%"]
        for lo, hi in BINS:
            ex, ey = errors(rows, lo, hi)
            cells.append(f"{fmt(rms(ex))} / {fmt(rms(ey))} ({len(ex) // 2})")
        ex, ey = errors(rows, *PEER_BIN)
        mid = (rms(ex), rms(ey))
        if peer is None:
            peer = mid
        cells += [f"{mid[0] / peer[0]:.2f}x", f"{mid[1] / peer[1]:.2f}x"]
        print("| " + " | ".join(cells) + " |")
    print()
    print("Cells: RMS error of x / of y [px] (detections in the bin). Detected: of the")
    print("renders where the landmark is fully visible.")
    print()
    print("## Per print")
    print()
    print(f"RMS error of x [px] over the widths {PEER_BIN[0]}-{PEER_BIN[1]} px per print (the CSV's group")
    print("modulo 3, as codemark-bench-pose-calib --vary-scene cycles them; every")
    print("light in each), as a ratio to the sensor row's for the same print:")
    print()
    print("| stages | " + " | ".join(PRINTS) + " |")
    print("|" + "---|" * (len(PRINTS) + 1))
    peer = None
    for label, rows, _, _ in runs:
        cells = []
        for k in range(len(PRINTS)):
            sel = [r for r in rows if int(r["group"]) % len(PRINTS) == k]
            ex, _ = errors(sel, *PEER_BIN)
            cells.append(rms(ex))
        if peer is None:
            peer = cells
        print(
            f"| {label} | "
            + " | ".join(f"{fmt(c)} ({c / p:.1f}x)" for c, p in zip(cells, peer))
            + " |"
        )


if __name__ == "__main__":
    main()
