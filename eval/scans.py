"""Real scans to meshes (issue 39): open, sparse and noisy point sets, measured against the issue's
acceptance at seeds 1-5.

    eval/.venv/bin/python3 eval/scans.py                  # every case, seeds 1-5
    eval/.venv/bin/python3 eval/scans.py --cases square,band --seeds 1-2

Cases (the point sets are made here, in a temporary folder, from a fixed seed):
- `face000`: pymeshlab's test range map (85,849 points, its own mesh in 17 pieces), read as
  points (`--as-points`) -> 20k. Hausdorff is to the range map's own mesh.
- `square`: 5,000 uniform points of a flat unit square -> 500.
- `hemisphere`: 20,000 uniform points of a unit hemisphere (no cap) -> 1,000.
- `band`: 20,000 uniform points of an open cylinder band (radius 1, height 1) -> 1,000.
- `spot-2000`, `spot-4000`: 5,000 area-uniform points of spot (`remesh points`, with normals)
  -> 2,000 and 4,000.
- `horse-nn`, `horse-noisy` (only when asked for: --cases): 1M horse points without normals, and
  with Gaussian noise of 0.1% of the diagonal and 1% outliers -> 10k, Hausdorff to horse.obj.

Per run: vertices (and the count's error), parts, loops, genus, manifold, crossing pairs (our
report's, and CGAL's `self_intersections` as an independent ruler: eval/cgal_ruler.py), θmin,
θmin of the faces with no boundary vertex ("inner"), the widest gap a face spans (the farthest
point of a face - centroid or edge midpoint - from every input point, in output spacings:
a face across a hole 3 spacings wide reaches 1.5), Hausdorff (bbox-100), seconds. For face000 also
the data regions (pieces of the range map's mesh of at least 10 output spacings² of area) and how
many output parts cover each (the largest share of its vertices' nearest output vertices).

Writes eval/results/scans/scans.md and scans.json.
"""

import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
import trimesh
from scipy.spatial import cKDTree

import cgal_ruler

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "data"
REMESH = Path(os.environ.get("REMESH_BIN", ROOT / "target" / "release" / "remesh"))
FACE000 = Path(trimesh.__file__).parent.parent / "pymeshlab/tests/sample_meshes/rangemaps/face000.ply"

CASES = {
    # name: (points maker, output count, extra arguments, reference mesh or None)
    "face000": ("face000", 20_000, ["--as-points"], "face000"),
    "square": ("square", 500, [], None),
    "hemisphere": ("hemisphere", 1_000, [], None),
    "band": ("band", 1_000, [], None),
    "spot-2000": ("spot5k", 2_000, [], None),
    "spot-4000": ("spot5k", 4_000, [], None),
    "horse-nn": ("horse-nn", 10_000, [], SHARED / "horse.obj"),
    "horse-noisy": ("horse-noisy", 10_000, [], SHARED / "horse.obj"),
}
DEFAULT_CASES = "face000,square,hemisphere,band,spot-2000,spot-4000"


def write_xyz(path, P, N=None):
    data = P if N is None else np.hstack([P, N])
    np.savetxt(path, data, fmt="%.9g")


def make_points(kind, work):
    """The point set `kind` in `work`: its path (made once)."""
    rng = np.random.default_rng(7)
    if kind == "face000":
        return FACE000
    path = work / f"{kind}.{'ply' if kind.startswith(('spot', 'horse')) else 'xyz'}"
    if path.exists():
        return path
    if kind == "square":
        P = rng.random((5000, 3))
        P[:, 2] = 0.0
        write_xyz(path, P)
    elif kind == "hemisphere":
        u = rng.normal(size=(20_000, 3))
        u /= np.linalg.norm(u, axis=1)[:, None]
        u[:, 2] = np.abs(u[:, 2])
        write_xyz(path, u)
    elif kind == "band":
        t = rng.random(20_000) * 2 * np.pi
        z = rng.random(20_000)
        write_xyz(path, np.stack([np.cos(t), np.sin(t), z], 1))
    elif kind == "spot5k":
        subprocess.run([str(REMESH), "points", str(SHARED / "spot.obj"), str(path), "--count", "5000",
                        "--seed", "7"], check=True, capture_output=True)
    elif kind.startswith("horse"):
        import pointsets as pts  # eval/points.py's variants, from the same points

        base = work / "horse-1M.ply"
        if not base.exists():
            subprocess.run([str(REMESH), "points", str(SHARED / "horse.obj"), str(base), "--count",
                            "1000000", "--seed", "1"], check=True, capture_output=True)
        P, N = pts.read_points(base)
        if kind == "horse-nn":
            pts.write_points(path, P)
        else:
            lo, hi = P.min(0), P.max(0)
            diag = float(np.linalg.norm(hi - lo))
            Q = P + rng.normal(0.0, 0.001 * diag, P.shape)
            Q = np.vstack([Q, rng.uniform(lo, hi, (len(P) // 100, 3))])
            pts.write_points(path, Q[rng.permutation(len(Q))])
    return path


def input_points(path):
    if path.suffix == ".xyz":
        return np.loadtxt(path)[:, :3]
    m = trimesh.load(path, process=False)
    return np.asarray(m.vertices if hasattr(m, "vertices") else m.points, dtype=np.float64)


def boundary_vertices(F):
    e = np.sort(np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    u, c = np.unique(e, axis=0, return_counts=True)
    return np.unique(u[c == 1])


def angles(V, F):
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]

    def ang(p, q, r):
        u, v = q - p, r - p
        cos = np.einsum("ij,ij->i", u, v) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
        return np.degrees(np.arccos(np.clip(cos, -1, 1)))

    return np.stack([ang(a, b, c), ang(b, c, a), ang(c, a, b)], 1).min(1)


def regions_covered(ref_mesh, V, F, spacing):
    """For each piece of the range map's mesh of at least 10 spacings² of area: how many output
    parts hold its vertices' nearest output vertices (counting a part when it holds 10% or more)."""
    comps = trimesh.graph.connected_components(ref_mesh.edges, nodes=np.arange(len(ref_mesh.vertices)))
    out = trimesh.Trimesh(V, F, process=False)
    labels = np.full(len(V), -1)
    for k, c in enumerate(trimesh.graph.connected_components(out.edges, nodes=np.arange(len(V)))):
        labels[c] = k
    tree = cKDTree(V)
    face_comp = {}
    vert_comp = np.full(len(ref_mesh.vertices), -1)
    for k, c in enumerate(comps):
        vert_comp[c] = k
    areas = np.zeros(len(comps))
    np.add.at(areas, vert_comp[ref_mesh.faces[:, 0]], ref_mesh.area_faces)
    counts = []
    for k, c in enumerate(comps):
        if areas[k] < 10 * spacing**2:
            continue
        _, nearest = tree.query(ref_mesh.vertices[c])
        lab = labels[nearest]
        lab = lab[lab >= 0]
        values, n = np.unique(lab, return_counts=True)
        counts.append(int((n >= 0.1 * len(lab)).sum()))
    return counts


def measure(out_path, pts, ref, n, seconds, report):
    cgal = cgal_ruler.check(out_path)
    m = trimesh.load(out_path, process=False)
    V, F = np.asarray(m.vertices), np.asarray(m.faces)
    e = np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    spacing = float(np.linalg.norm(V[e[:, 0]] - V[e[:, 1]], axis=1).mean())
    bv = boundary_vertices(F)
    on_b = np.zeros(len(V), bool)
    on_b[bv] = True
    inner = ~on_b[F].any(1)
    th = angles(V, F)
    probes = np.vstack([V[F].mean(1), 0.5 * (V[F[:, 0]] + V[F[:, 1]]), 0.5 * (V[F[:, 1]] + V[F[:, 2]]),
                        0.5 * (V[F[:, 2]] + V[F[:, 0]])])
    gap = float(cKDTree(pts).query(probes)[0].max() / spacing)
    topo, tri = report["topology"], report["triangles"]
    row = {
        "vertices": topo["vertices"],
        "count_error_pct": 100.0 * (topo["vertices"] - n) / n,
        "parts": topo["components"],
        "loops": topo["boundary_loops"],
        "genus": topo["genus"],
        "manifold": topo["non_manifold_edges"] == 0 and topo["non_manifold_vertices"] == 0,
        "crossings": report["self_intersections"]["pairs"],
        "cgal_pairs": cgal["pairs"],
        "cgal_agrees": cgal_ruler.agrees(report, cgal),
        "theta_min": tri["theta_min"],
        "theta_min_inner": float(th[inner].min()) if inner.any() else None,
        "q_ave": tri["q_ave"],
        "gap_spacings": gap,
        "seconds": seconds,
    }
    if ref is not None:
        q = subprocess.run([str(REMESH), "quality", str(out_path), "--ref", str(ref), "--json"],
                           capture_output=True, text=True, check=True)
        row["hausdorff"] = json.loads(q.stdout)["distance"]["hausdorff"]
    if str(ref).endswith("face000.ply"):
        ref_mesh = trimesh.load(ref, process=False)
        counts = regions_covered(ref_mesh, V, F, spacing)
        row["regions"] = len(counts)
        row["regions_split"] = int(sum(c != 1 for c in counts))
    return row


def parse_seeds(s):
    if "-" in s:
        a, b = s.split("-")
        return list(range(int(a), int(b) + 1))
    return [int(x) for x in s.split(",")]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default=DEFAULT_CASES)
    ap.add_argument("--seeds", default="1-5")
    ap.add_argument("--out", default=str(ROOT / "eval" / "results" / "scans"))
    ap.add_argument("--json", help="write the rows here instead of the results folder (no table)")
    a = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory(prefix="eval-scans-") as tmp:
        work = Path(tmp)
        for case in a.cases.split(","):
            kind, n, extra, ref = CASES[case]
            path = make_points(kind, work)
            pts = input_points(path)
            ref_path = FACE000 if ref == "face000" else ref
            for seed in parse_seeds(a.seeds):
                out = work / f"{case}-{seed}.obj"
                rep = work / f"{case}-{seed}.json"
                t = time.perf_counter()
                r = subprocess.run([str(REMESH), str(path), str(out), "--points", str(n), "--seed", str(seed),
                                    "--no-distance", "--report", str(rep), "-q"] + extra,
                                   capture_output=True, text=True)
                seconds = time.perf_counter() - t
                if r.returncode != 0:
                    row = {"error": r.stderr.strip()}
                else:
                    row = measure(out, pts, ref_path, n, seconds, json.loads(rep.read_text()))
                row.update(case=case, seed=seed)
                rows.append(row)
                print(json.dumps(row), flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))
        return
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "scans.json").write_text(json.dumps(rows, indent=1))
    cols = ["vertices", "count_error_pct", "parts", "loops", "genus", "manifold", "crossings", "cgal_pairs",
            "cgal_agrees", "theta_min",
            "theta_min_inner", "q_ave", "gap_spacings", "hausdorff", "regions", "regions_split", "seconds"]
    lines = ["# Real scans to meshes (issue 39)", "",
             f"`eval/.venv/bin/python3 eval/scans.py --cases {a.cases} --seeds {a.seeds}`. Per case, the "
             "median over the seeds and, after the slash, the worst seed (θmin: lowest; parts, loops, "
             "gap, Hausdorff, count error: largest).", "",
             "| case | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
    worst_low = {"theta_min", "theta_min_inner", "q_ave"}
    for case in dict.fromkeys(r["case"] for r in rows):
        rs = [r for r in rows if r["case"] == case and "error" not in r]
        cells = []
        for c in cols:
            vals = [r.get(c) for r in rs if r.get(c) is not None]
            if not vals:
                cells.append("")
            elif isinstance(vals[0], bool):
                cells.append("yes" if all(vals) else "no")
            else:
                med = statistics.median(vals)
                worst = min(vals) if c in worst_low else max(vals, key=abs)
                fmt = (lambda v: f"{v:.3g}") if isinstance(vals[0], float) else str
                cells.append(f"{fmt(med)} / {fmt(worst)}")
        errors = sum("error" in r for r in rows if r["case"] == case)
        lines.append(f"| {case}{f' ({errors} failed)' if errors else ''} | " + " | ".join(cells) + " |")
    (out / "scans.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
