"""Creases on CAD parts (issue 59): ours beside MeshLab's isotropic remeshing (its default 30° feature
detection) and CGAL's isotropic remeshing with the creases as constraints, at the same vertex count.

    eval/features                                  # the made parts and the shared CAD parts, seeds 1-5
    eval/features --parts gear,hex_nut --seeds 1 --name try
    eval/features --parts ../shared/corpus/trimesh-models/plate_holes.STL --name unseen   # any mesh file
    eval/features --parts hex_nut~1e-4,gear~1e-4 --name noisy   # made parts with noise in their positions

Parts: those eval/cad_parts.py makes by CSG (a hex nut, a chamfered block with holes, a gear, a
part with a 1° and a 179° dihedral), written to the work folder (`NAME~A`: that part as a CAD
export with noise in its positions, Gaussian of A times the bounding box's diagonal, its creases
the clean part's: eval/cad_parts.noisy), and the shared CAD parts
(../shared/data: fandisk, bracket, flange), or any mesh file given by its path. Each at `--count`
vertices (3,000).

Per run: vertices; Hausdorff and RMS (bbox-100, two-sided, `remesh quality --ref`); the creases'
distance to the output's edges: the input's crease edges (faces turning by 20° or more,
eval/cad_parts.crease_edges), each sampled every 1/8 of the output's mean edge h, the largest
distance of a sample to the nearest output edge, in units of h (the issue asks ≤ 0.1); the
corners' distance (input vertices where 3 or more crease edges meet) to the nearest output vertex,
in h; θmin and the input's smallest angle between two crease edges at a vertex (the issue asks θmin
≥ 30 or that); topology (components, Euler characteristic, boundary loops) against the input's;
and for ours the automatic decision's note (what decided to keep the creases or not).

The creases are the input's edges, one by one: where a part's rounded edge is a band of narrow
facets each turning by 20° or more (fandisk), every facet edge of the band counts, though the
band is narrower than the output's spacing and no output follows all of them (the p99 column
shows how much of the length is off).

MeshLab and CGAL run once per part (they have no seed); their edge length is searched for the count
as eval/run does (eval/compare.search). Writes eval/results/features/NAME.md and NAME.json (NAME:
`creases` by default).
"""

import argparse
import json
import math
import os
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

here = Path(__file__).resolve().parent
sys.path.insert(0, str(here))
import cad_parts  # noqa: E402
import compare  # noqa: E402
import points_real  # noqa: E402

SHARED = here.parent.parent / "shared" / "data"
SHARED_PARTS = ["fandisk", "bracket", "flange"]
REFERENCES = {
    "meshlab_isotropic": "MeshLab isotropic (30° features)",
    "cgal_features": "CGAL isotropic, creases constrained",
}


def segment_distance(P, A, B):
    """Distance from each point P[i] to the segment A[i]-B[i] (arrays n × 3)."""
    d = B - A
    t = np.clip(((P - A) * d).sum(1) / np.maximum((d * d).sum(1), 1e-300), 0.0, 1.0)
    return np.linalg.norm(P - (A + t[:, None] * d), axis=1)


def crease_samples(V, creases, step):
    """Points along each crease edge, `step` apart at most (ends included)."""
    out = []
    for a, b in creases:
        n = max(1, int(math.ceil(np.linalg.norm(V[b] - V[a]) / step)))
        t = np.linspace(0.0, 1.0, n + 1)[:, None]
        out.append(V[a] + t * (V[b] - V[a]))
    return np.vstack(out) if out else np.zeros((0, 3))


def distance_to_edges(P, V2, F2, k=24):
    """Distance from each point of P to the nearest edge of the mesh (V2, F2): exact against the k
    edges with the nearest midpoints (edges are about as long as each other)."""
    from scipy.spatial import cKDTree

    E = np.unique(np.sort(np.concatenate([F2[:, [0, 1]], F2[:, [1, 2]], F2[:, [2, 0]]]), axis=1), axis=0)
    mid = 0.5 * (V2[E[:, 0]] + V2[E[:, 1]])
    _, idx = cKDTree(mid).query(P, k=min(k, len(E)))
    best = np.full(len(P), np.inf)
    for j in range(idx.shape[1]):
        e = E[idx[:, j]]
        best = np.minimum(best, segment_distance(P, V2[e[:, 0]], V2[e[:, 1]]))
    return best


def corners(V, creases):
    count = np.bincount(creases.ravel(), minlength=len(V)) if len(creases) else np.zeros(len(V), int)
    return np.where(count >= 3)[0]


def input_corner_angle(V, creases):
    """The smallest angle between two crease edges at a vertex where three or more meet (or two
    meet turning by 20° or more), degrees (180 with none): the corner the creases make, which
    no output's faces there can beat. Measured between the edges' directions in space."""
    best = 180.0
    at = {}
    for a, b in creases.tolist():
        at.setdefault(a, []).append(b)
        at.setdefault(b, []).append(a)
    for v, ns in at.items():
        if len(ns) < 2:
            continue
        d = V[ns] - V[v]
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        c = np.clip(d @ d.T, -1.0, 1.0)
        np.fill_diagonal(c, -1.0)
        ang = math.degrees(math.acos(c.max()))
        if len(ns) >= 3 or ang <= 180.0 - cad_parts.CREASE_TURN_DEG:
            best = min(best, ang)
    return best


def measure(out_path, in_path, V, creases, corner_ids):
    q = compare.ruler(out_path, in_path)
    V2, F2 = compare.read_mesh(out_path)
    h = points_real.mean_edge(V2, F2)
    P = crease_samples(V, creases, h / 8)
    d = distance_to_edges(P, V2, F2) if len(P) else np.zeros(0)
    from scipy.spatial import cKDTree

    dc = cKDTree(V2).query(V[corner_ids])[0] if len(corner_ids) else np.zeros(0)
    topo, itopo = q["topology"], q.get("input_topology") or {}
    same = all(topo.get(k) == itopo.get(k) for k in ("components", "euler_characteristic", "boundary_loops"))
    return {
        "vertices": int(topo["vertices"]),
        "hausdorff": q["distance"]["hausdorff"],
        "rms": q["distance"]["rms"],
        "theta_min": q["triangles"]["theta_min"],
        "q_ave": q["triangles"]["q_ave"],
        "h": h,
        "crease_max_h": float(d.max() / h) if len(d) else 0.0,
        "crease_p99_h": float(np.percentile(d, 99) / h) if len(d) else 0.0,
        "corner_max_h": float(dc.max() / h) if len(dc) else 0.0,
        "topology": f"{topo['components']} / {topo['euler_characteristic']} / {topo['boundary_loops']}",
        "topology_as_input": same,
    }


def run_ours(in_path, n, seed, work, extra=()):
    out = Path(work) / f"ours-{seed}.obj"
    rep = Path(work) / f"ours-{seed}.json"
    compare.subprocess.run(
        [compare.REMESH, str(in_path), str(out), "--points", str(n), "--seed", str(seed), "-q",
         "--no-distance", "--report", str(rep), *extra],
        check=True,
    )
    notes = json.loads(rep.read_text()).get("notes", [])
    decision = next((x for x in notes if x.startswith("sharp features")), "")
    return out, decision


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--parts", default=",".join(list(cad_parts.PARTS) + SHARED_PARTS))
    ap.add_argument("--seeds", default="1-5")
    ap.add_argument("--count", type=int, default=3000)
    ap.add_argument("--no-references", action="store_true")
    ap.add_argument("--ours-args", default="", help="more arguments for ours, e.g. '--chord-error 0.003'")
    ap.add_argument("--name", default="creases")
    ap.add_argument("--out", default=str(here / "results" / "features"))
    args = ap.parse_args()
    lo, _, hi = args.seeds.partition("-")
    seeds = list(range(int(lo), int(hi or lo) + 1))
    names = [p for p in args.parts.split(",") if p]
    work = Path(tempfile.mkdtemp(prefix="features-"))
    made = cad_parts.write_parts(work / "parts")
    results = []
    for name in names:
        spec = cad_parts.parse_noisy(name)
        if spec:
            # A made part with noise in its positions: its creases are the clean part's.
            V, F, V_clean = cad_parts.noisy(*spec)
            in_path = work / "parts" / f"{name}.obj"
            compare.write_obj(in_path, V, F)
            creases = cad_parts.crease_edges(V_clean, F)
        else:
            in_path = made.get(name) or (Path(name) if Path(name).is_file() else SHARED / f"{name}.obj")
            name = name if name in made else Path(in_path).stem
            V, F = compare.read_mesh(in_path)
            creases = cad_parts.crease_edges(V, F)
        corner_ids = corners(V, creases)
        row = {"part": name, "input_vertices": len(V), "crease_edges": len(creases), "corners": len(corner_ids),
               "input_corner_angle": input_corner_angle(V, creases), "runs": []}
        print(f"{name}: {len(V)} vertices, {len(creases)} crease edges, {len(corner_ids)} corners", flush=True)
        pw = work / name
        pw.mkdir()
        for s in seeds:
            out, decision = run_ours(in_path, args.count, s, pw, args.ours_args.split())
            r = {"method": "ours", "seed": s, "decision": decision, **measure(out, in_path, V, creases, corner_ids)}
            row["runs"].append(r)
            print("  ", json.dumps(r), flush=True)
        if not args.no_references:
            for method in REFERENCES:
                mw = pw / method
                mw.mkdir()
                V2, F2, secs, p, tries = compare.search(method, V, F, args.count, mw, in_path, lambda m: None)
                out = mw / "out.obj"
                compare.write_obj(out, V2, F2)
                r = {"method": method, "seed": None, **measure(out, in_path, V, creases, corner_ids)}
                row["runs"].append(r)
                print("  ", json.dumps(r), flush=True)
        results.append(row)
    write(results, args, seeds)


def write(results, args, seeds):
    outdir = Path(args.out)
    outdir.mkdir(parents=True, exist_ok=True)
    (outdir / f"{args.name}.json").write_text(json.dumps({"count": args.count, "seeds": seeds, "results": results}, indent=1))
    L = [f"# Creases on CAD parts at {args.count} vertices (issue 59)", "",
         "Generated by `eval/features` (eval/features.py; definitions in its docstring). Ours: median / worst of "
         f"seeds {seeds[0]}-{seeds[-1]}; the references run once. Hausdorff in bbox-100 units; creases and corners: "
         "largest distance to the output's edges / vertices in output mean edges h. Topology: components / Euler "
         "characteristic / boundary loops.", ""]
    L.append("| part | method | V | Hausdorff | creases max (h) | creases p99 (h) | corners max (h) | θmin (input corner) | Qave | topology (as input) | creases kept |")
    L.append("|---|---|---|---|---|---|---|---|---|---|---|")
    for row in results:
        ours = [r for r in row["runs"] if r["method"] == "ours"]

        def agg(key, worst):
            v = [r[key] for r in ours]
            return f"{statistics.median(v):.3g} / {worst(v):.3g}"

        kept = sum(1 for r in ours if "sharp features" in r["decision"] and "sampled like the rest" not in r["decision"])
        L.append(
            f"| {row['part']} | ours | {agg('vertices', max)} | {agg('hausdorff', max)} | {agg('crease_max_h', max)} | "
            f"{agg('crease_p99_h', max)} | {agg('corner_max_h', max)} | {agg('theta_min', min)} ({row['input_corner_angle']:.1f}) | "
            f"{agg('q_ave', min)} | {sum(r['topology_as_input'] for r in ours)}/{len(ours)} | {kept}/{len(ours)} |"
        )
        for r in row["runs"]:
            if r["method"] == "ours":
                continue
            L.append(
                f"| {row['part']} | {REFERENCES[r['method']]} | {r['vertices']} | {r['hausdorff']:.3g} | {r['crease_max_h']:.3g} | "
                f"{r['crease_p99_h']:.3g} | {r['corner_max_h']:.3g} | {r['theta_min']:.3g} | {r['q_ave']:.3g} | "
                f"{r['topology']} ({'yes' if r['topology_as_input'] else 'no'}) | |"
            )
    L += ["", "Ours' decision per part (seed 1):", ""]
    for row in results:
        ours = [r for r in row["runs"] if r["method"] == "ours"]
        if ours:
            L.append(f"- {row['part']}: {ours[0]['decision'] or '(no note)'}")
    (outdir / f"{args.name}.md").write_text("\n".join(L) + "\n")
    print(f"wrote {outdir / (args.name + '.md')}")


if __name__ == "__main__":
    main()
