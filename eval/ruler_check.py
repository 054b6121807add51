"""Checks the ruler: `remesh quality --json` against an independent NumPy computation of the
same quantities (θmin, θmin,ave, Qmin, Qave, %θ<30, P30, boundary edges, non-manifold edges and
vertices) on several meshes. Agreement to 1e-6 or the script exits non-zero.

The meshes: the shared OBJ models (read here by a small parser of its own: `v` and `f` lines,
polygons fanned, indices by position as the OBJ gives them) and, when REMESH_BIN is set, one
remesh output. Run by eval/run before the comparison; alone: `python eval/ruler_check.py`.
"""

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SHARED = HERE.parent.parent / "shared" / "data"
REMESH = os.environ.get("REMESH_BIN", str(HERE.parent / "target" / "release" / "remesh"))
TOL = 1e-6


def read_obj(path):
    """Positions (V×3) and triangles (F×3) of an OBJ, polygons fanned from their first corner."""
    v, f = [], []
    for line in Path(path).read_text().splitlines():
        p = line.split()
        if not p:
            continue
        if p[0] == "v":
            v.append([float(x) for x in p[1:4]])
        elif p[0] == "f":
            idx = []
            for c in p[1:]:
                i = int(c.split("/")[0])
                idx.append(i - 1 if i > 0 else len(v) + i)
            for k in range(1, len(idx) - 1):
                f.append([idx[0], idx[k], idx[k + 1]])
    return np.array(v, dtype=np.float64), np.array(f, dtype=np.int64)


WELD_RELATIVE = 1e-10  # remesh's geometry::tolerance::WELD_RELATIVE
WELD_EDGE_RELATIVE = 1e-7  # and WELD_EDGE_RELATIVE


def weld(V, F):
    """Merges positions that are bit-identical or within WELD_RELATIVE of the bounding box's
    diagonal and WELD_EDGE_RELATIVE of the shortest edge at either (each into the first vertex
    kept before it within that distance, as the readers of remesh do; CAD exports repeat a
    seam's corners a rounding apart) and drops faces that then repeat a vertex, then drops
    unreferenced vertices."""
    _, first, inverse = np.unique(V, axis=0, return_index=True, return_inverse=True)
    F = first[inverse.ravel()[F]]
    used = np.unique(F)
    if len(used):
        from scipy.spatial import cKDTree

        P = V[used]
        tol = WELD_RELATIVE * np.linalg.norm(P.max(axis=0) - P.min(axis=0))
        pairs = cKDTree(P).query_pairs(tol, output_type="ndarray") if tol > 0 else np.zeros((0, 2), int)
        if len(pairs):
            E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
            L = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
            shortest = np.full(len(V), np.inf)
            np.minimum.at(shortest, E[:, 0], L)
            np.minimum.at(shortest, E[:, 1], L)
            into = np.arange(len(V))
            near = {}
            for a, b in pairs.tolist():
                a, b = sorted((int(used[a]), int(used[b])))
                if np.linalg.norm(V[a] - V[b]) <= WELD_EDGE_RELATIVE * min(shortest[a], shortest[b]):
                    near.setdefault(b, []).append(a)
            for b in sorted(near):
                kept = [a for a in near[b] if into[a] == a]
                if kept:
                    into[b] = min(kept)
            F = into[F]
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])]
    used, F = np.unique(F, return_inverse=True)
    return V[used], F.reshape(-1, 3)


def triangle_angles(V, F):
    """The three interior angles of every triangle, degrees (F×3), by atan2(|e1×e2|, e1·e2)."""
    T = V[F]
    angles = np.empty((len(F), 3))
    for k in range(3):
        e1 = T[:, (k + 1) % 3] - T[:, k]
        e2 = T[:, (k + 2) % 3] - T[:, k]
        angles[:, k] = np.degrees(
            np.arctan2(np.linalg.norm(np.cross(e1, e2), axis=1), np.einsum("ij,ij->i", e1, e2))
        )
    return angles


def triangle_qualities(V, F):
    """Every triangle's quality Q = 6 A / (sqrt(3) p h), A its area, p its half-perimeter and h its
    longest edge: 1 for an equilateral triangle, 0 for a degenerate one."""
    T = V[F]
    lengths = np.linalg.norm(T[:, [1, 2, 0]] - T, axis=2)
    area = 0.5 * np.linalg.norm(np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]), axis=1)
    return 6 * area / (np.sqrt(3) * 0.5 * lengths.sum(1) * lengths.max(1))


def measures(V, F):
    angles = triangle_angles(V, F)
    q = triangle_qualities(V, F)
    amin = angles.min(1)
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    uniq, counts = np.unique(edges, axis=0, return_counts=True)
    # Non-manifold vertices: the faces around v split into several fans (faces sharing an
    # edge {v, w} are in one fan).
    around = {}
    for fi, t in enumerate(F):
        for v in t:
            around.setdefault(int(v), []).append(fi)
    nm_vertices = 0
    for v, faces in around.items():
        parent = {f: f for f in faces}

        def find(x):
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x

        by_w = {}
        for f in faces:
            for w in F[f]:
                if w != v:
                    by_w.setdefault(int(w), []).append(f)
        for fs in by_w.values():
            for g in fs[1:]:
                parent[find(g)] = find(fs[0])
        if len({find(f) for f in faces}) > 1:
            nm_vertices += 1
    return {
        "theta_min": amin.min(),
        "theta_min_ave": amin.mean(),
        "q_min": q.min(),
        "q_ave": q.mean(),
        "pct_theta_below_30": 100.0 * (amin < 30).mean(),
        "p30": 100.0 * (angles < 30).mean(),
        "boundary_edges": int((counts == 1).sum()),
        "non_manifold_edges": int((counts >= 3).sum()),
        "non_manifold_vertices": nm_vertices,
    }


def ruler(path):
    out = subprocess.run([REMESH, "quality", str(path), "--json"], check=True, capture_output=True, text=True)
    r = json.loads(out.stdout)
    m = dict(r["triangles"])
    m.update({k: r["topology"][k] for k in ("boundary_edges", "non_manifold_edges", "non_manifold_vertices")})
    return m


def main():
    meshes = [SHARED / n for n in ("horse.obj", "fandisk.obj", "spot.obj", "stanford-bunny.obj", "cow.obj")]
    meshes = [m for m in meshes if m.exists()]
    with tempfile.TemporaryDirectory() as tmp:
        if Path(REMESH).exists() and (SHARED / "spot.obj").exists():
            out = Path(tmp) / "spot-remeshed.obj"
            subprocess.run([REMESH, str(SHARED / "spot.obj"), str(out), "--points", "1500", "-q", "--no-distance"], check=True)
            meshes.append(out)
        worst = 0.0
        failures = []
        for path in meshes:
            ours = ruler(path)
            ref = measures(*weld(*read_obj(path)))
            for k, v in ref.items():
                d = abs(float(ours[k]) - float(v))
                worst = max(worst, d)
                if d > TOL:
                    failures.append(f"{path.name}: {k} ruler {ours[k]} vs independent {v}")
        print(f"ruler check: {len(meshes)} meshes, 9 measures each, largest difference {worst:.2e} (tolerance {TOL:g})")
        if failures:
            print("\n".join(failures), file=sys.stderr)
            sys.exit(1)


if __name__ == "__main__":
    main()
