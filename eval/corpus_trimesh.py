"""A second ruler for issue 75's corpus claim: on every clean input of an `eval/corpus --json`
run, does trimesh (a library we did not write) count the same bodies, Euler characteristic and
boundary loops on the output as on the input?

    eval/.venv/bin/python3 eval/corpus_trimesh.py ROWS.json [--seeds 1-3] [--points 3000]
        [--corpus ../shared/corpus] [--remesh target/release/remesh]

ROWS.json is what `eval/corpus --json ROWS.json` wrote (its `clean` flag per file: welded within
1e-10 of the diagonal, no non-manifold edge, no degenerate face, no crossing by CGAL). Each clean
file is welded the same way (eval/corpus.welded_copy) and read by trimesh with its vertices
merged; each seed's output is `remesh FILE OUT.obj --points N --seed S -q --no-distance`.
Bodies are trimesh's connected components, the Euler characteristic is summed over them, and a
boundary loop is a connected set of edges used by one face. Inputs that touch themselves at a
vertex (a pinch) count as one body here; remesh's report compares them split there (see
docs/decisions/topological-ball.md), so such files are listed apart, not as failures.
Prints one line per run that differs and a summary; exits 1 when a run on an input without a
pinch differs.
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import networkx as nx
import trimesh

import corpus

HERE = Path(__file__).resolve().parent


def counts(path):
    """(bodies, Euler characteristic, boundary loops, pinched vertices) of the mesh at `path`,
    its identical vertices merged."""
    m = trimesh.load(str(path), force="mesh", process=False)
    m = trimesh.Trimesh(m.vertices, m.faces, process=True)
    bodies = m.split(only_watertight=False)
    loops = 0
    for b in bodies:
        once = trimesh.grouping.group_rows(b.edges_sorted, require_count=1)
        if len(once):
            g = nx.Graph()
            g.add_edges_from(b.edges_sorted[once].tolist())
            loops += nx.number_connected_components(g)
    # A vertex whose faces form more than one fan (connected through shared edges) is pinched.
    pinched = 0
    faces_of = [[] for _ in range(len(m.vertices))]
    for f, t in enumerate(m.faces):
        for v in t:
            faces_of[v].append(f)
    for v, fs in enumerate(faces_of):
        if len(fs) < 2:
            continue
        g = nx.Graph()
        g.add_nodes_from(fs)
        by_edge = {}
        for f in fs:
            for w in m.faces[f]:
                if w != v:
                    by_edge.setdefault(int(w), []).append(f)
        for shared in by_edge.values():
            for a, b in zip(shared, shared[1:]):
                g.add_edge(a, b)
        pinched += nx.number_connected_components(g) > 1
    return len(bodies), int(sum(b.euler_number for b in bodies)), loops, pinched


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("rows", help="the JSON eval/corpus --json wrote")
    ap.add_argument("--seeds", default="1-3")
    ap.add_argument("--points", type=int, default=3000)
    ap.add_argument("--corpus", default=str(HERE.parent.parent / "shared" / "corpus"))
    ap.add_argument("--remesh", default=str(HERE.parent / "target" / "release" / "remesh"))
    args = ap.parse_args()
    a, _, b = args.seeds.partition("-")
    seeds = list(range(int(a), int(b) + 1)) if b else [int(s) for s in args.seeds.split(",")]
    rows = json.loads(Path(args.rows).read_text())
    clean = [r["file"] for r in rows if r.get("clean")]
    root = Path(args.corpus)
    differ, pinch_differ, runs = [], [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for f in clean:
            path = Path(f) if Path(f).is_absolute() else root / f
            if not path.exists():
                path = next(root.rglob(Path(f).name))
            ci = counts(corpus.welded_copy(path, tmp))
            for s in seeds:
                out = Path(tmp) / "out.obj"
                r = subprocess.run([args.remesh, str(path), str(out), "--points", str(args.points),
                                    "--seed", str(s), "-q", "--no-distance"], capture_output=True)
                if r.returncode != 0:
                    print(f"{f} seed {s}: exit {r.returncode}", flush=True)
                    continue
                runs += 1
                co = counts(out)
                if co[:3] != ci[:3]:
                    (pinch_differ if ci[3] else differ).append((f, s))
                    print(f"{f} seed {s}: input (bodies, chi, loops) {ci[:3]}, output {co[:3]}"
                          + (f" (input pinched at {ci[3]} vertices)" if ci[3] else ""), flush=True)
    print(f"{len(clean)} clean inputs, {runs} runs: trimesh counts differ on {len(differ)} runs, "
          f"and on {len(pinch_differ)} runs of inputs pinched at a vertex")
    sys.exit(1 if differ else 0)


if __name__ == "__main__":
    main()
