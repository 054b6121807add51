"""Point sets to meshes (issue 19): ours against MeshLab's screened Poisson reconstruction followed
by its isotropic remeshing at the same count, and ball pivoting on a Poisson-disk subset of the
same count, on the same point sets.

Run through eval/points (it sets up the venv and builds remesh):

    eval/points                          # horse, 1M points, -> 10k, with normals / without / noisy
    eval/points --quick                  # spot, 200k points -> 3k, with normals (seconds)

Per model, the point sets are drawn from the shared mesh by `remesh points` (with normals); the
"without normals" variant drops them, the "noisy" one adds Gaussian noise of 0.1% of the diagonal
and 1% outliers uniform in the bounding box (and drops the normals). Every output is measured by
`remesh quality OUT --ref MODEL --json` against the model the points came from: triangle quality
(θmin, Qave), topology, Hausdorff and RMS in bbox-100 units. Times are wall-clock seconds of the
method alone (MeshLab's normal estimation included where the points have none).

Writes eval/results/points/points.md and points.json (the point sets and meshes go to a
temporary folder).
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "data"
REMESH = Path(os.environ.get("REMESH_BIN", ROOT / "target" / "release" / "remesh"))


def read_points(path):
    """Positions and normals of a binary PLY point set written by `remesh points`."""
    raw = path.read_bytes()
    end = raw.index(b"end_header\n") + len(b"end_header\n")
    header = raw[:end].decode()
    n = int(next(l for l in header.split("\n") if l.startswith("element vertex")).split()[2])
    props = [l.split() for l in header.split("\n") if l.startswith("property")]
    dt = np.dtype([(p[2], "<f8" if p[1] == "double" else "<f4") for p in props])
    d = np.frombuffer(raw[end : end + n * dt.itemsize], dtype=dt)
    P = np.stack([d["x"], d["y"], d["z"]], 1).astype(np.float64)
    N = np.stack([d["nx"], d["ny"], d["nz"]], 1).astype(np.float64)
    return P, N


def write_points(path, P, N=None):
    """A binary little-endian PLY of positions (double) and, if given, normals (float)."""
    props = "property double x\nproperty double y\nproperty double z\n"
    if N is not None:
        props += "property float nx\nproperty float ny\nproperty float nz\n"
        dt = np.dtype([("p", "<f8", 3), ("n", "<f4", 3)])
        rec = np.empty(len(P), dtype=dt)
        rec["p"], rec["n"] = P, N
    else:
        dt = np.dtype([("p", "<f8", 3)])
        rec = np.empty(len(P), dtype=dt)
        rec["p"] = P
    head = f"ply\nformat binary_little_endian 1.0\nelement vertex {len(P)}\n{props}end_header\n"
    path.write_bytes(head.encode() + rec.tobytes())


def make_inputs(model, count, work, variants, seed=1):
    """The point sets of `model`: {variant: path}."""
    base = work / f"{model}-{count}.ply"
    subprocess.run(
        [str(REMESH), "points", str(SHARED / f"{model}.obj"), str(base), "--count", str(count), "--seed", str(seed)],
        check=True,
        capture_output=True,
    )
    P, N = read_points(base)
    out = {}
    if "normals" in variants:
        out["normals"] = base
    if "no-normals" in variants:
        path = work / f"{model}-{count}-nn.ply"
        write_points(path, P)
        out["no-normals"] = path
    if "noisy" in variants:
        rng = np.random.default_rng(seed)
        lo, hi = P.min(0), P.max(0)
        diag = float(np.linalg.norm(hi - lo))
        Q = P + rng.normal(0.0, 0.001 * diag, P.shape)
        Q = np.vstack([Q, rng.uniform(lo, hi, (count // 100, 3))])
        Q = Q[rng.permutation(len(Q))]
        path = work / f"{model}-{count}-noisy.ply"
        write_points(path, Q)
        out["noisy"] = path
    return out


def run_ours(points, n, seed, out):
    t = time.perf_counter()
    r = subprocess.run(
        [str(REMESH), str(points), str(out), "--points", str(n), "--seed", str(seed), "--no-distance", "-q"],
        capture_output=True,
        text=True,
    )
    seconds = time.perf_counter() - t
    if r.returncode != 0:
        raise RuntimeError(r.stderr.strip())
    return seconds


def meshlab_set(points, has_normals):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(points))
    if not has_normals:
        ms.compute_normal_for_point_clouds(k=10)
    return ms


def run_poisson_isotropic(points, n, has_normals, out):
    """Screened Poisson (depth 10) then isotropic remeshing at the edge length that gives about n
    vertices (one correction from the first try's count)."""
    import pymeshlab

    t = time.perf_counter()
    ms = meshlab_set(points, has_normals)
    ms.generate_surface_reconstruction_screened_poisson(depth=10, preclean=True)
    poisson = ms.current_mesh_id()
    area = ms.get_geometric_measures()["surface_area"]
    h = math.sqrt(2.0 * area / (math.sqrt(3.0) * n))
    for _ in range(2):
        ms.set_current_mesh(poisson)
        ms.generate_copy_of_current_mesh()
        ms.meshing_isotropic_explicit_remeshing(targetlen=pymeshlab.PureValue(h), iterations=10)
        v = ms.current_mesh().vertex_number()
        if abs(v - n) <= 0.02 * n:
            break
        h *= math.sqrt(v / n)
    seconds = time.perf_counter() - t
    ms.save_current_mesh(str(out), save_vertex_normal=False)
    return seconds


def run_ball_pivoting(points, n, has_normals, out):
    """Ball pivoting on a Poisson-disk subset of n points (MeshLab's point-cloud simplification)."""
    t = time.perf_counter()
    ms = meshlab_set(points, has_normals)
    ms.generate_simplified_point_cloud(samplenum=int(n))
    ms.generate_surface_reconstruction_ball_pivoting()
    seconds = time.perf_counter() - t
    ms.save_current_mesh(str(out), save_vertex_normal=False)
    return seconds


def quality(mesh, model):
    r = subprocess.run(
        [str(REMESH), "quality", str(mesh), "--ref", str(SHARED / f"{model}.obj"), "--json"],
        capture_output=True,
        text=True,
    )
    if r.returncode != 0:
        return {"error": r.stderr.strip()}
    q = json.loads(r.stdout)
    t, d, topo = q["triangles"], q.get("distance") or {}, q["topology"]
    return {
        "vertices": topo["vertices"],
        "components": topo["components"],
        "genus": topo["genus"],
        "boundary_loops": topo["boundary_loops"],
        "manifold": topo["non_manifold_edges"] == 0 and topo["non_manifold_vertices"] == 0,
        "theta_min": t["theta_min"],
        "q_ave": t["q_ave"],
        "hausdorff": d.get("hausdorff"),
        "rms": d.get("rms"),
    }


METHODS = {
    "ours": "remesh (spectral sampling on RIMLS)",
    "poisson_isotropic": "MeshLab screened Poisson (depth 10) + isotropic remeshing (10 it.)",
    "ball_pivoting": "MeshLab Poisson-disk subset + ball pivoting",
}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--models", default="horse")
    ap.add_argument("--count", type=int, default=1_000_000, help="input points")
    ap.add_argument("--points", type=int, default=10_000, help="output vertices")
    ap.add_argument("--variants", default="normals,no-normals,noisy")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--quick", action="store_true", help="spot, 200k -> 3k, with normals")
    ap.add_argument("--out", default=str(ROOT / "eval" / "results" / "points"))
    a = ap.parse_args()
    if a.quick:
        a.models, a.count, a.points, a.variants = "spot", 200_000, 3000, "normals"
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory(prefix="eval-points-") as tmp:
        work = Path(tmp)
        for model in a.models.split(","):
            inputs = make_inputs(model, a.count, work, a.variants.split(","), a.seed)
            for variant, path in inputs.items():
                has_normals = variant == "normals"
                for key in METHODS:
                    mesh = work / f"{model}-{variant}-{key}.ply"
                    try:
                        if key == "ours":
                            seconds = run_ours(path, a.points, a.seed, mesh)
                        elif key == "poisson_isotropic":
                            seconds = run_poisson_isotropic(path, a.points, has_normals, mesh)
                        else:
                            seconds = run_ball_pivoting(path, a.points, has_normals, mesh)
                        row = {"model": model, "variant": variant, "method": key, "seconds": seconds}
                        row.update(quality(mesh, model))
                    except Exception as e:  # a method failing is a row, not the end of the run
                        row = {"model": model, "variant": variant, "method": key, "error": str(e)}
                    print(json.dumps(row), file=sys.stderr)
                    rows.append(row)
    (out / "points.json").write_text(json.dumps(rows, indent=1))
    lines = [
        "# Point sets to meshes",
        "",
        f"`eval/points {' '.join(sys.argv[1:])}`: {a.count} points drawn from each model (`remesh points`), "
        f"remeshed to {a.points} vertices, measured by `remesh quality OUT --ref MODEL` (bbox-100 units). "
        "Screened Poisson + isotropic: times include both (the remeshing is tried at most twice to land "
        "within 2% of the count). Variants: `normals` (as drawn), `no-normals` (dropped; MeshLab estimates them with k = 10), "
        "`noisy` (Gaussian noise 0.1% of the diagonal, 1% outliers in the bounding box, no normals).",
        "",
        "| model | input | method | V | parts | genus | loops | manifold | θmin | Qave | Hausdorff | RMS | s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['model']} | {r['variant']} | {r['method']} | error: {r['error'][:80]} |||||||||")
            continue
        f = lambda x, p: "–" if x is None else f"{x:.{p}f}"
        lines.append(
            f"| {r['model']} | {r['variant']} | {r['method']} | {r['vertices']} | {r['components']} | "
            f"{r['genus']} | {r['boundary_loops']} | {'yes' if r['manifold'] else 'no'} | "
            f"{f(r['theta_min'], 1)} | {f(r['q_ave'], 3)} | {f(r['hausdorff'], 3)} | {f(r['rms'], 4)} | "
            f"{r['seconds']:.1f} |"
        )
    lines += ["", "Methods:", ""] + [f"- `{k}`: {v}" for k, v in METHODS.items()]
    (out / "points.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
