"""Whose are an output's crossing pairs: an independent ruler beside our report (issue 76).

    eval/.venv/bin/python3 eval/crossing_ruler.py INPUT OUTPUT     # one JSON line

Issue 76's rule: a crossing pair of the output counts as the input's when both faces lie within
one output spacing of the input's own crossing curve, whatever vertex they share; every other
pair is the output's own (a violation). Written apart from the Rust code, on other libraries:

- the pairs of both meshes are CGAL's (`Polygon_mesh_processing.self_intersections`, exact
  predicates, the standard definition), the input read welded as remesh reads it
  (`ruler_check.weld`), without faces that repeat an index or another face's three vertices
  (as remesh's input cleanup), and taken apart into single faces (CGAL builds no polyhedral surface of
  an input whose parts meet at non-manifold edges) for the pairs that share no vertex, and the
  standard definition's two other cases in floating point for those that share one or two;
- the input's crossing curve: for each of its pairs the segment where the two triangles meet (the
  points where an edge of one passes through the other's plane inside the other, the two
  farthest apart; a coplanar pair: the smaller triangle), and where closed parts meet, the
  vertices and edges used by more than two faces;
- the output spacing is the output's mean edge length (model units), not our sigma_p;
- a face's distance to the curve: the curve sampled every spacing / 16 (the smaller triangles
  of coplanar pairs on a grid of that step) and the samples' exact distances to the face
  (trimesh's closest point), so a face within the spacing may be read up to spacing / 32 farther.

Output: `{"pairs", "at_input", "own", "spacing", "own_kinds"}`, `own_kinds` counting the output's
own pairs by how many vertices their faces share.
"""

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cgal_ruler  # noqa: E402
import ruler_check  # noqa: E402

STEP = 1.0 / 16.0


def cgal_pairs(v, f):
    """CGAL's intersecting pairs of the faces `f` over `v`, as index pairs."""
    import tempfile
    from CGAL import CGAL_Polygon_mesh_processing as PMP
    from CGAL.CGAL_Polyhedron_3 import Polyhedron_3
    with tempfile.TemporaryDirectory() as tmp:
        off = Path(tmp) / "m.off"
        with open(off, "w") as fh:
            fh.write(f"OFF\n{len(v)} {len(f)} 0\n")
            fh.writelines(f"{p[0]!r} {p[1]!r} {p[2]!r}\n" for p in v.tolist())
            fh.writelines(f"3 {t[0]} {t[1]} {t[2]}\n" for t in f.tolist())
        P = Polyhedron_3(str(off))
    if P.size_of_facets() != len(f):
        raise ValueError(f"CGAL built {P.size_of_facets()} of {len(f)} faces")
    it, i = P.facets(), 0
    while it.hasNext():
        it.next().set_id(i)
        i += 1
    pairs = []
    PMP.self_intersections(P, pairs)
    return np.array([[p[0].id(), p[1].id()] for p in pairs], dtype=np.int64).reshape(-1, 2)


def meeting(a, b):
    """Points sampling where triangles `a` and `b` (3x3) meet, every `step` apart is applied by
    the caller: returns ("segment", p, q) or ("area", triangle)."""
    area = lambda t: np.linalg.norm(np.cross(t[1] - t[0], t[2] - t[0]))
    smaller = a if area(a) <= area(b) else b
    tol = 1e-9 * max(np.abs(a).max(), np.abs(b).max(), 1e-300)
    pts = []
    for s, t in ((a, b), (b, a)):
        n = np.cross(t[1] - t[0], t[2] - t[0])
        ln = np.linalg.norm(n)
        if ln == 0:
            return ("area", smaller)
        n = n / ln
        d = (s - t[0]) @ n
        if np.all(np.abs(d) <= tol):
            return ("area", smaller)
        for k in range(3):
            p, q, dp, dq = s[k], s[(k + 1) % 3], d[k], d[(k + 1) % 3]
            if abs(dp) <= tol:
                x = p
            elif dp * dq < 0:
                x = p + (q - p) * (dp / (dp - dq))
            else:
                continue
            if point_triangle_distance(x, t) <= tol:
                pts.append(x)
    if not pts:
        return ("area", smaller)
    best = max(((np.sum((p - q) ** 2), i, j) for i, p in enumerate(pts) for j, q in enumerate(pts)))
    return ("segment", pts[best[1]], pts[best[2]])


def point_triangle_distance(x, t):
    import trimesh
    c = trimesh.triangles.closest_point(t[None, :, :], x[None, :])
    return float(np.linalg.norm(c[0] - x))


def curve_samples(v, f, pairs, step):
    """Points on the input's crossing curve and junction, `step` apart at most."""
    out = []

    def along(p, q):
        n = max(1, int(np.ceil(np.linalg.norm(q - p) / step)))
        s = np.linspace(0.0, 1.0, n + 1)[:, None]
        out.append(p + s * (q - p))

    for i, j in pairs:
        m = meeting(v[f[i]], v[f[j]])
        if m[0] == "segment":
            along(m[1], m[2])
        else:
            t = m[1]
            n = max(1, int(np.ceil(max(np.linalg.norm(t[1] - t[0]), np.linalg.norm(t[2] - t[0])) / step)))
            u, w = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
            keep = (u + w) <= 1.0
            out.append(t[0] + u[keep][:, None] * (t[1] - t[0]) + w[keep][:, None] * (t[2] - t[0]))
    # Where parts meet: edges used by more than two faces.
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    uniq, counts = np.unique(e, axis=0, return_counts=True)
    for a, b in uniq[counts > 2]:
        along(v[a], v[b])
    return np.concatenate(out) if out else np.zeros((0, 3))


def segment_meets_triangle(p, q, t, eps=1e-12):
    """Whether the closed segment p q meets the closed triangle t (floating point, Möller and
    Trumbore's test with a relative tolerance; a segment in the triangle's plane: no)."""
    e1, e2, d = t[1] - t[0], t[2] - t[0], q - p
    h = np.cross(d, e2)
    det = e1 @ h
    scale = max(np.linalg.norm(e1) * np.linalg.norm(e2) * np.linalg.norm(d), 1e-300)
    if abs(det) <= eps * scale:
        return False
    s = p - t[0]
    u = (s @ h) / det
    w = np.cross(s, e1)
    vv = (d @ w) / det
    r = (e2 @ w) / det
    return -eps <= u <= 1 + eps and -eps <= vv and u + vv <= 1 + eps and -eps <= r <= 1 + eps


def input_pairs(v, f):
    """The pairs of the input's faces that intersect by the standard definition. Those that
    share no vertex: CGAL's pairs of the faces taken apart (each its own three vertices), as CGAL
    cannot build a polyhedral surface of an input whose parts meet at non-manifold edges (pairs
    that then share a vertex are left to the next step). Those that share one vertex: the edge
    of one opposite the shared vertex meets the other triangle (floating point). Those that share
    an edge: coplanar, the third corners on the same side of it."""
    soup_v = v[f].reshape(-1, 3)
    soup_f = np.arange(3 * len(f), dtype=np.int64).reshape(-1, 3)
    pairs = cgal_pairs(soup_v, soup_f)
    keep = [k for k, (a, b) in enumerate(pairs.tolist()) if not set(f[a].tolist()) & set(f[b].tolist())]
    out = [tuple(p) for p in pairs[keep].tolist()]
    around = {}
    for i, t in enumerate(f.tolist()):
        for x in t:
            around.setdefault(x, []).append(i)
    seen = set()
    for faces in around.values():
        for i in faces:
            for j in faces:
                if j <= i or (i, j) in seen:
                    continue
                seen.add((i, j))
                a, b = f[i].tolist(), f[j].tolist()
                shared = set(a) & set(b)
                ta, tb = v[f[i]], v[f[j]]
                if len(shared) == 1:
                    s = shared.pop()
                    ea = [v[x] for x in a if x != s]
                    eb = [v[x] for x in b if x != s]
                    if segment_meets_triangle(ea[0], ea[1], tb) or segment_meets_triangle(eb[0], eb[1], ta):
                        out.append((i, j))
                elif len(shared) == 2:
                    n = np.cross(ta[1] - ta[0], ta[2] - ta[0])
                    ca = [v[x] for x in a if x not in shared][0]
                    cb = [v[x] for x in b if x not in shared][0]
                    if abs(n @ (cb - ta[0])) <= 1e-12 * np.linalg.norm(n) * max(np.linalg.norm(cb - ta[0]), 1e-300):
                        e0, e1 = [v[x] for x in shared]
                        m = np.cross(n, e1 - e0)
                        if (m @ (ca - e0)) * (m @ (cb - e0)) > 0:
                            out.append((i, j))
    return np.array(sorted(set(out)), dtype=np.int64).reshape(-1, 2)


def classify(input_path, output_path):
    vi, fi = cgal_ruler.read_mesh(input_path)
    vi, fi = ruler_check.weld(np.array(vi, dtype=np.float64).reshape(-1, 3),
                              np.array(fi, dtype=np.int64).reshape(-1, 3))
    # As remesh cleans its input: a face repeating an index, and the second of two faces on the
    # same three vertices (either orientation), go.
    fi = fi[(fi[:, 0] != fi[:, 1]) & (fi[:, 1] != fi[:, 2]) & (fi[:, 0] != fi[:, 2])]
    _, first = np.unique(np.sort(fi, axis=1), axis=0, return_index=True)
    fi = fi[np.sort(first)]
    vo, fo = cgal_ruler.read_mesh(output_path)
    vo = np.array(vo, dtype=np.float64).reshape(-1, 3)
    fo = np.array(fo, dtype=np.int64).reshape(-1, 3)
    out_pairs = cgal_pairs(vo, fo)
    e = np.concatenate([fo[:, [0, 1]], fo[:, [1, 2]], fo[:, [2, 0]]])
    spacing = float(np.linalg.norm(vo[e[:, 0]] - vo[e[:, 1]], axis=1).mean())
    result = {"pairs": int(len(out_pairs)), "at_input": 0, "own": 0, "spacing": spacing,
              "own_kinds": {}}
    if len(out_pairs) == 0:
        return result
    in_pairs = input_pairs(vi, fi)
    samples = curve_samples(vi, fi, in_pairs, STEP * spacing)
    import trimesh
    from scipy.spatial import cKDTree
    tree = cKDTree(samples) if len(samples) else None
    near = {}

    def is_near(face):
        if face in near:
            return near[face]
        t = vo[fo[face]]
        c = t.mean(axis=0)
        r = np.linalg.norm(t - c, axis=1).max()
        ok = False
        if tree is not None:
            idx = tree.query_ball_point(c, r + spacing)
            if idx:
                pts = samples[idx]
                cp = trimesh.triangles.closest_point(np.repeat(t[None], len(pts), axis=0), pts)
                ok = bool(np.linalg.norm(cp - pts, axis=1).min() <= spacing)
        near[face] = ok
        return ok

    for a, b in out_pairs.tolist():
        if is_near(a) and is_near(b):
            result["at_input"] += 1
        else:
            result["own"] += 1
            k = str(len(set(fo[a].tolist()) & set(fo[b].tolist())))
            result["own_kinds"][k] = result["own_kinds"].get(k, 0) + 1
    return result


if __name__ == "__main__":
    print(json.dumps(classify(sys.argv[1], sys.argv[2])))
