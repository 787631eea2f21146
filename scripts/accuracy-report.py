#!/usr/bin/env python3
"""Writes docs/benchmarks/pose.md from the accuracy map's summary.txt files.

usage: accuracy-report.py COMMAND RESULTS_DIR [COMPARISON_DIR] > pose.md

RESULTS_DIR holds codemark-accuracy-map's summary.txt and heat maps (the
paper's survey grid); COMPARISON_DIR, when given, the same map measured with
another calibration. Each region of the summary becomes a table (closed
form, general 6-DoF path, AprilTag 3, the closed form's predicted sigma),
its notes a list.
"""
import datetime
import os
import re
import platform
import subprocess
import sys

HEADERS = ["metric", "closed form", "general 6-DoF", "AprilTag 3 + 6-DoF", "predicted sigma (cf)"]


def regions(path):
    """[(title, header comment lines, table rows, notes)] of a summary.txt."""
    out, cur = [], None
    preamble = []
    for line in open(path):
        line = line.rstrip("\n")
        if line.startswith("## "):
            cur = [line[3:], [], []]
            out.append(cur)
        elif cur is None:
            if line.startswith("# "):
                preamble.append(line[2:])
        elif line.startswith("metric"):
            cur.append("worse" in line)
            continue
        elif cur is not None and len(cur) == 4 and cur[3] and re.match(
                r"^(\S+)\s+(\d+ \(\d+\))\s+(\d+ \(\d+\))\s+(\d+)$", line):
            cur[1].append(list(re.match(
                r"^(\S+)\s+(\d+ \(\d+\))\s+(\d+ \(\d+\))\s+(\d+)$", line).groups()))
        elif line.strip() and cur is not None and line[:1] != " " and "  " in line and \
                not line.startswith(("pose NEES", "cells", "corner", "95%")):
            # "name [unit]   v1   v2   v3   v4" (trailing columns may be blank)
            name = line[:20].strip()
            vals = line[20:].split()
            cur[1].append([name] + vals + [""] * (4 - len(vals)))
        elif line.strip():
            cur[2].append(line.strip().lstrip("# "))
    return preamble, out


def table(rows, headers):
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def main():
    command, results = sys.argv[1], sys.argv[2]
    comparison = sys.argv[3] if len(sys.argv) > 3 else None
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    commit = subprocess.run(["git", "-C", root, "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip() or "unknown"
    print("# Pose accuracy on the paper's survey grid")
    print()
    print(f"Written by `{command}` on {datetime.date.today()} ({os.cpu_count()} cores, "
          f"{platform.machine()}), commit {commit}.")
    preamble, regs = regions(os.path.join(results, "summary.txt"))
    for p in preamble:
        print(p[0].upper() + p[1:] + ".")
    print()
    for title, rows, notes, *kind in regs:
        if not rows:
            continue
        print(f"## {title[0].upper() + title[1:]}")
        print()
        per_cell = bool(kind and kind[0])
        print(table(rows, ["metric", "cells where cf is worse than AprilTag (> 2 se)",
                           "where gen is worse (> 2 se)", "cells"] if per_cell else HEADERS))
        print()
        for n in notes:
            print(f"- {n}")
        print()
    if comparison:
        pre, regs = regions(os.path.join(comparison, "summary.txt"))
        print("## With another calibration")
        print()
        for p in pre:
            print(p[0].upper() + p[1:] + ".")
        print()
        for title, rows, notes, *kind in regs:
            if not rows or (kind and kind[0]):
                continue
            print(f"### {title[0].upper() + title[1:]}")
            print()
            print(table([r[:3] + [r[4]] for r in rows],
                        ["metric", "closed form", "general 6-DoF", "predicted sigma (cf)"]))
            print()
    print("## Error maps")
    print()
    for f in ["l2", "phi2", "x", "y"]:
        print(f"![{f}](../images/accuracy-heat_{f}.png)")
    print()


if __name__ == "__main__":
    main()
