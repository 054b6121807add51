"""The corpus's clean inputs against their outputs by trimesh (a ruler we did not write):
components, Euler characteristic and whether there is a boundary, the input and the output each
loaded by trimesh and welded (`merge_vertices(merge_tex=True, merge_norm=True)`: texture and
normal seams are not cuts), for every clean file of an `eval/corpus --json` file, seeds 1-3.

    eval/corpus --json rows.json
    eval/.venv/bin/python3 eval/corpus_trimesh_topology.py rows.json

Prints each run where trimesh's figures differ, then the count. The binary: $REMESH_BIN or the
release build.
"""

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import trimesh
from trimesh.grouping import group_rows

ROOT = Path(__file__).resolve().parent.parent
REMESH = os.environ.get("REMESH_BIN", str(ROOT / "target" / "release" / "remesh"))
CORPUS = ROOT.parent / "shared" / "corpus"


def topology(path):
    m = trimesh.load(path, force="mesh", process=True)
    m.merge_vertices(merge_tex=True, merge_norm=True)
    boundary = len(group_rows(m.edges_sorted, require_count=1)) > 0
    return len(m.split(only_watertight=False)), m.euler_number, boundary


def main():
    rows = json.load(open(sys.argv[1]))
    runs = differ = 0
    with tempfile.TemporaryDirectory() as work:
        for r in rows:
            if not r.get("clean"):
                continue
            f = CORPUS / r["file"]
            for seed in (1, 2, 3):
                out = Path(work) / f"out-{seed}.obj"
                p = subprocess.run([REMESH, str(f), str(out), "--points", "3000", "--seed",
                                    str(seed), "-q", "--no-distance"], capture_output=True)
                if p.returncode != 0:
                    print("exit", p.returncode, r["file"], seed)
                    continue
                a, b = topology(f), topology(out)
                runs += 1
                if a != b:
                    differ += 1
                    print("differ", r["file"], seed, "input", a, "output", b)
    print(f"runs {runs}, trimesh's topology differs on {differ}")


if __name__ == "__main__":
    main()
