#!/usr/bin/env python3
"""Regenerates the figures README.md quotes, so that they are never a copy that drifts:

- the report block under "## The report": the lines of what
  `remesh data/spot.obj spot-3k.obj --points 3000` prints today (the labels the README keeps);
- the "What to expect" table's θmin, θmax, Qave, Hausdorff and RMS columns: the range over the
  seeds of eval/results/bounds/bounds.md (made by eval/bounds.py); the last column (the other
  remeshers, from eval/run) is left as it is.

tests/readme.rs fails when the README and these sources disagree; this script makes them agree:

    REMESH_BIN=target/release/remesh python3 eval/readme_figures.py          # rewrite README.md
    REMESH_BIN=target/release/remesh python3 eval/readme_figures.py --check  # exit 1 on drift

Formats (the test uses the same): θ one decimal, Qave three, Hausdorff two, RMS two significant
digits; a range "lo–hi", one value when both ends print the same.
"""

import argparse
import math
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
BOUNDS = ROOT / "eval/results/bounds/bounds.md"
# README's name for each model of bounds.md.
NAMES = {"stanford-bunny": "bunny"}


def report_lines(binary):
    with tempfile.TemporaryDirectory() as tmp:
        out = subprocess.run(
            [binary, "data/spot.obj", os.path.join(tmp, "spot-3k.obj"), "--points", "3000"],
            cwd=ROOT, check=True, capture_output=True, text=True,
        ).stdout
    return out.splitlines()


def label(line):
    """The label of a report line ("  Qave      0.9411" -> "Qave"), or None."""
    m = re.match(r"^  (\S.*?)\s{2,}\S", line)
    return m.group(1) if m else None


def rewrite_block(readme, printed):
    start = readme.index("```text\ndata/spot.obj -> ")
    end = readme.index("```", start + 3)
    block = readme[start:end].split("\n")
    by_label = {}
    for line in printed:
        by_label.setdefault(label(line), line)
    for i, line in enumerate(block):
        name = label(line)
        if name is not None and name in by_label:
            block[i] = by_label[name]
    return readme[:start] + "\n".join(block) + readme[end:]


def significant(x, digits):
    if x == 0:
        return "0"
    decimals = max(0, digits - 1 - math.floor(math.log10(abs(x))))
    return f"{x:.{decimals}f}"


def span(values, fmt):
    lo, hi = fmt(min(values)), fmt(max(values))
    return lo if lo == hi else f"{lo}–{hi}"


def bounds_rows():
    """{(README model name, count): [θmin, θmax, Qave, Hausdorff, RMS] cells}."""
    text = BOUNDS.read_text()
    rows = {}
    for m in re.finditer(r"^## (\S+) at (\d+) .*?\n\n(.*?)(?:\n\n|\Z)", text, re.S | re.M):
        seeds = [
            [float(c) for c in line.strip("|").split("|")[1:6]]
            for line in m.group(3).splitlines()
            if re.match(r"^\| \d+ \|", line)
        ]
        cols = list(zip(*seeds))
        rows[(NAMES.get(m.group(1), m.group(1)), int(m.group(2)))] = [
            span(cols[0], lambda v: f"{v:.1f}"),
            span(cols[1], lambda v: f"{v:.1f}"),
            span(cols[2], lambda v: f"{v:.3f}"),
            span(cols[3], lambda v: f"{v:.2f}"),
            span(cols[4], lambda v: significant(v, 2)),
        ]
    return rows


def rewrite_table(readme):
    rows = bounds_rows()
    out = []
    for line in readme.split("\n"):
        m = re.match(r"^\|(\w+) ([\d,]+)\|", line)
        if m and (m.group(1), int(m.group(2).replace(",", ""))) in rows:
            cells = line.strip("|").split("|")
            cells[1:6] = rows[(m.group(1), int(m.group(2).replace(",", "")))]
            line = "|" + "|".join(cells) + "|"
        out.append(line)
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="exit 1 when README.md would change")
    args = ap.parse_args()
    binary = os.environ.get("REMESH_BIN", str(ROOT / "target/release/remesh"))
    old = README.read_text()
    new = rewrite_table(rewrite_block(old, report_lines(binary)))
    if args.check:
        sys.exit(0 if new == old else 1)
    README.write_text(new)
    print("README.md " + ("unchanged" if new == old else "rewritten"))


if __name__ == "__main__":
    main()
