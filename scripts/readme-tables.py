#!/usr/bin/env python3
"""The README's result tables, copied from the committed benchmark reports.

Each table in README.md sits between two markers:

    <!-- report docs/benchmarks/detect.md table 3 [columns 1,2,4] [rows TEXT] -->
    ...
    <!-- end report -->

`table N` is the N-th table of the report (1-based; a table is a run of
lines that start with '|'), `columns` keeps those columns (1-based), `rows`
keeps the header and the rows that contain TEXT (alternatives separated by
`;;`: the rows that contain any of them, in the report's order). A source file is copied
the same way, as a fenced block:

    <!-- file examples/quickstart.cpp -->
    <!-- end file -->

Without arguments the script rewrites README.md; with --check it exits 1
and prints the difference when README.md does not match the reports (the
test suite runs it so).
"""
import difflib
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
MARKER = re.compile(
    r"^<!-- report (\S+) table (\d+)(?: columns ([\d,]+))?(?: rows (.+?))? -->$")
END = "<!-- end report -->"
FILE = re.compile(r"^<!-- file (\S+) -->$")
END_FILE = "<!-- end file -->"


def tables(path):
    out, cur = [], []
    for line in path.read_text().splitlines():
        if line.startswith("|"):
            cur.append(line)
        elif cur:
            out.append(cur)
            cur = []
    if cur:
        out.append(cur)
    return out


def cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def extract(report, index, columns, rows, where):
    path = ROOT / report
    if not path.is_file():
        sys.exit(f"{where}: {report}: no such report")
    found = tables(path)
    if not 1 <= index <= len(found):
        sys.exit(f"{where}: {report} has {len(found)} tables, not {index}")
    t = found[index - 1]
    if rows:
        wanted = [r.strip() for r in rows.split(";;")]
        t = t[:2] + [line for line in t[2:] if any(w in line for w in wanted)]
    if columns:
        keep = [int(c) - 1 for c in columns.split(",")]
        t = ["| " + " | ".join(cells(line)[k] for k in keep if k < len(cells(line))) + " |"
             for line in t]
    return t


def render(readme):
    lines = readme.read_text().splitlines()
    out, i = [], 0
    while i < len(lines):
        m = MARKER.match(lines[i])
        f = FILE.match(lines[i])
        out.append(lines[i])
        i += 1
        if f:
            end = i
            while end < len(lines) and lines[end] != END_FILE:
                end += 1
            if end == len(lines):
                sys.exit(f"README.md:{i}: no '{END_FILE}' after the marker")
            lang = "cpp" if f.group(1).endswith((".cpp", ".h")) else ""
            out += ["```" + lang] + (ROOT / f.group(1)).read_text().rstrip("\n").split("\n")
            out += ["```", END_FILE]
            i = end + 1
            continue
        if not m:
            continue
        where = f"README.md:{i}"
        end = i
        while end < len(lines) and lines[end] != END:
            end += 1
        if end == len(lines):
            sys.exit(f"{where}: no '{END}' after the marker")
        out += extract(m.group(1), int(m.group(2)), m.group(3), m.group(4), where)
        out.append(END)
        i = end + 1
    return "\n".join(out) + "\n"


def main():
    readme = ROOT / "README.md"
    new = render(readme)
    old = readme.read_text()
    if "--check" in sys.argv[1:]:
        if new != old:
            sys.stdout.writelines(difflib.unified_diff(
                old.splitlines(True), new.splitlines(True), "README.md", "from the reports"))
            print("README.md's tables differ from the reports: run scripts/readme-tables.py")
            return 1
        return 0
    readme.write_text(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
