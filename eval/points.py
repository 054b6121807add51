"""Point sets to meshes (issue 19): ours against MeshLab's screened Poisson reconstruction followed
by its isotropic remeshing at the same count, and ball pivoting on a Poisson-disk subset of the
same count, on the same point sets.

Run through eval/points (it sets up the venv and builds remesh):

    eval/points                          # horse, 1M points, -> 10k, with normals / without / noisy
    eval/points --quick                  # spot, 200k points -> 3k, with normals (seconds)
    eval/points --scans default          # issue 39's scan inputs (eval/scans.py's cases), all three methods
    eval/points --real                   # issue 58's real scans beside MeshLab and Open3D, seeds 1-5
                                         # (eval/points_real.py; writes eval/results/scans/real.md)

With --scans CASES (comma-separated names of eval/scans.py's CASES, or `default` for its default
list: face000, square, hemisphere, band, spot-2000, spot-4000), the point sets are made by
eval/scans.py's `make_points` (the same files its own runs use) and remeshed to the case's count by
all three methods; ours gets the case's extra arguments (face000: `--as-points`), MeshLab loads
the points only (face000's faces dropped). References for the distance: face000's own range-map
mesh, spot.obj for the spot cases, horse.obj for the horse cases, and for the square, hemisphere
and band a fine analytic mesh of the surface the points were drawn from (built here with numpy).
Writes scans.md and scans.json beside points.md.

Per model, the point sets are drawn from the shared mesh by `remesh points` (with normals); the
"without normals" variant drops them, the "noisy" one adds Gaussian noise of 0.1% of the diagonal
and 1% outliers uniform in the bounding box (and drops the normals). Every output is measured by
`remesh quality OUT --ref MODEL --json` against the model the points came from: triangle quality
(θmin, Qave), topology, Hausdorff and RMS in bbox-100 units. Times are wall-clock seconds of the
method alone (MeshLab's normal estimation included where the points have none). MeshLab runs in a
child process (a crash or a --timeout is a row saying so, not the end of the run).

Writes eval/results/points/points.md and points.json (the point sets and meshes go to a
temporary folder).
"""

import argparse
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from pointsets import child_last_line, read_points, write_points

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "data"
REMESH = Path(os.environ.get("REMESH_BIN", ROOT / "target" / "release" / "remesh"))


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


def run_ours(points, n, seed, out, extra=()):
    t = time.perf_counter()
    r = subprocess.run(
        [str(REMESH), str(points), str(out), "--points", str(n), "--seed", str(seed), "--no-distance", "-q"]
        + list(extra),
        capture_output=True,
        text=True,
    )
    seconds = time.perf_counter() - t
    if r.returncode != 0:
        raise RuntimeError(r.stderr.strip())
    return seconds


def quality(mesh, ref):
    """`remesh quality MESH --ref REF --json`, the row's measures."""
    r = subprocess.run(
        [str(REMESH), "quality", str(mesh), "--ref", str(ref), "--json"],
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
        "crossings": (q.get("self_intersections") or {}).get("pairs"),
        "theta_min": t["theta_min"],
        "q_ave": t["q_ave"],
        "hausdorff": d.get("hausdorff"),
        "rms": d.get("rms"),
        "forward_hausdorff": d.get("forward_hausdorff"),  # output -> reference
        "backward_hausdorff": d.get("backward_hausdorff"),  # reference -> output
    }


METHODS = {
    "ours": "remesh (spectral sampling on RIMLS)",
    "poisson_isotropic": "MeshLab screened Poisson (depth 10) + isotropic remeshing (10 it.)",
    "ball_pivoting": "MeshLab Poisson-disk subset + ball pivoting",
}

# Runs one MeshLab method in a child process: argv = eval dir, method, points, n, has_normals, out.
CHILD = (
    "import sys; from pathlib import Path; sys.path.insert(0, sys.argv[1]); import pointsets as p; "
    "f = getattr(p, 'run_' + sys.argv[2]); "
    "print(f(Path(sys.argv[3]), int(sys.argv[4]), sys.argv[5] == '1', Path(sys.argv[6])))"
)


def run_meshlab(key, points, n, has_normals, out, timeout=None):
    """run_poisson_isotropic or run_ball_pivoting in a child process (its own seconds): a crash or a
    timeout raises, so it becomes an error row."""
    args = [sys.executable, "-c", CHILD, str(Path(__file__).resolve().parent), key, str(points), str(n),
            "1" if has_normals else "0", str(out)]
    return float(child_last_line(args, timeout, "MeshLab child"))


def run_method(key, points, n, seed, has_normals, out, extra=(), timeout=None):
    if key == "ours":
        return run_ours(points, n, seed, out, extra)
    return run_meshlab(key, points, n, has_normals, out, timeout)


def ply_has_normals(path):
    path = Path(path)
    if path.suffix.lower() != ".ply":
        return False
    raw = path.read_bytes()[:65536]
    header = raw[: raw.find(b"end_header")].decode(errors="replace")
    return any(l.split()[-1:] == ["nx"] for l in header.split("\n") if l.startswith("property"))


def grid_faces(rows, cols, wrap=False):
    """Two triangles per cell of a rows x cols vertex grid (index r * cols + c); columns wrap around
    when `wrap`."""
    idx = np.arange(rows * cols).reshape(rows, cols)
    nxt = np.roll(idx, -1, axis=1) if wrap else idx[:, 1:]
    cur = idx if wrap else idx[:, :-1]
    a, b, c, d = cur[:-1], cur[1:], nxt[1:], nxt[:-1]
    return np.vstack([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])


def analytic_reference(kind, work):
    """A fine mesh of the surface eval/scans.py draws `kind`'s points from: the unit square (201 x
    201 grid), the unit hemisphere z >= 0 without cap (180 rings x 720 around, a fan at the pole), the
    open band of radius 1 and height 1 (101 rows x 720 around). Chord error below 1e-5 of the radius."""
    import trimesh

    path = work / f"{kind}-reference.ply"
    if path.exists():
        return path
    m = 720
    phi = np.arange(m) * 2 * np.pi / m
    if kind == "square":
        u = np.linspace(0.0, 1.0, 201)
        X, Y = np.meshgrid(u, u, indexing="ij")
        V = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)
        F = grid_faces(201, 201)
    elif kind == "hemisphere":
        theta = np.linspace(0.0, np.pi / 2, 181)[1:]
        rings = np.stack([np.sin(theta)[:, None] * np.cos(phi), np.sin(theta)[:, None] * np.sin(phi),
                          np.cos(theta)[:, None] * np.ones(m)], -1).reshape(-1, 3)
        V = np.vstack([[0.0, 0.0, 1.0], rings])
        fan = np.stack([np.zeros(m, int), 1 + np.arange(m), 1 + (np.arange(m) + 1) % m], 1)
        F = np.vstack([fan, 1 + grid_faces(180, m, wrap=True)])
    elif kind == "band":
        z = np.linspace(0.0, 1.0, 101)
        V = np.stack([np.cos(phi)[None, :] * np.ones((101, 1)), np.sin(phi)[None, :] * np.ones((101, 1)),
                      z[:, None] * np.ones(m)], -1).reshape(-1, 3)
        F = grid_faces(101, m, wrap=True)
    else:
        raise ValueError(f"no analytic reference for {kind}")
    trimesh.Trimesh(V, F, process=False).export(path)
    return path


def built_from(given):
    """The commit the remesh binary was built from: --built-from, else the binary's name
    (remesh-<hash>), else the checkout's HEAD."""
    if given:
        return given
    m = re.fullmatch(r"remesh-([0-9a-f]{7,40})", REMESH.name)
    if m:
        return m.group(1)
    r = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    return (r.stdout.strip() or "unknown") + " (the checkout's HEAD at run time)"


def command_line():
    py = sys.executable
    if py.startswith(str(ROOT) + os.sep):
        py = os.path.relpath(py, ROOT)
    return f"REMESH_BIN={REMESH} {py} eval/points.py {shlex.join(sys.argv[1:])}".rstrip()


def cell(x):
    return str(x).replace("|", "/").replace("\n", " ")


def measure_cells(r):
    """The table cells after the row's labels: V .. s (or one error cell)."""
    if "error" in r:
        return [f"error: {cell(r['error'])[:160]}"] + [""] * 10
    f = lambda x, p: "–" if x is None else f"{x:.{p}f}"
    i = lambda x: "–" if x is None else str(x)
    return [
        i(r["vertices"]), i(r["components"]), i(r["genus"]), i(r["boundary_loops"]),
        "yes" if r["manifold"] else "no", i(r.get("crossings")),
        f(r["theta_min"], 1), f(r["q_ave"], 3), f(r["hausdorff"], 3), f(r["rms"], 4), f"{r['seconds']:.1f}",
    ]


MEASURE_HEAD = ["V", "parts", "genus", "loops", "manifold", "crossings", "θmin", "Qave", "Hausdorff", "RMS", "s"]


def table(labels, rows):
    lines = ["| " + " | ".join(labels + MEASURE_HEAD) + " |", "|---" * (len(labels) + len(MEASURE_HEAD)) + "|"]
    for labs, r in rows:
        lines.append("| " + " | ".join([cell(x) for x in labs] + measure_cells(r)) + " |")
    return lines


def load_note(rows):
    loads = [r["load1"] for r in rows if "load1" in r]
    if not loads:
        return "load not recorded"
    return (f"{os.cpu_count()} cores, 1-minute load average at the rows' ends {min(loads):.1f} to {max(loads):.1f} "
            "(the JSON has each row's)")


def run_scans(a, out):
    """Issue 39's scan inputs (eval/scans.py's cases), all three methods at the case's count."""
    import scans

    names = scans.DEFAULT_CASES if a.scans == "default" else a.scans
    rows = []
    with tempfile.TemporaryDirectory(prefix="eval-points-scans-") as tmp:
        work = Path(tmp)
        for case in names.split(","):
            kind, n, extra, ref = scans.CASES[case]
            base = {"case": case, "target": n}
            try:
                path = scans.make_points(kind, work)
                pts = scans.input_points(path)
                if kind == "face000":
                    ref_path, ref_name = scans.FACE000, "face000's own range-map mesh"
                    ml_path = work / "face000-points.ply"  # the vertices only: MeshLab gets no faces
                    write_points(ml_path, pts)
                else:
                    ml_path = path
                    if kind.startswith("spot"):
                        ref_path, ref_name = SHARED / "spot.obj", "spot.obj"
                    elif ref is not None:
                        ref_path, ref_name = Path(ref), Path(ref).name
                    else:
                        ref_path, ref_name = analytic_reference(kind, work), f"analytic {kind} mesh"
                has_normals = ply_has_normals(ml_path)
                base.update(points=len(pts), normals=has_normals, reference=ref_name)
            except Exception as e:
                for key in METHODS:
                    row = dict(base, method=key, error=f"input: {e}")
                    print(json.dumps(row), file=sys.stderr, flush=True)
                    rows.append(row)
                continue
            for key in METHODS:
                mesh = work / f"{case}-{key}.ply"
                try:
                    seconds = run_method(key, path if key == "ours" else ml_path, n, a.seed, has_normals, mesh,
                                         extra, a.timeout)
                    row = dict(base, method=key, seconds=seconds)
                    row.update(quality(mesh, ref_path))
                except Exception as e:  # a method failing is a row, not the end of the run
                    row = dict(base, method=key, error=str(e))
                row["load1"] = os.getloadavg()[0]
                print(json.dumps(row), file=sys.stderr, flush=True)
                rows.append(row)
    cmd, commit = command_line(), built_from(a.built_from)
    (out / "scans.json").write_text(json.dumps({"command": cmd, "built_from": commit, "seed": a.seed, "rows": rows},
                                               indent=1))
    refs = dict.fromkeys(f"{r['case']}: {r['reference']}" for r in rows if "reference" in r)
    lines = [
        "# Scan inputs to meshes: ours, MeshLab screened Poisson + isotropic, ball pivoting (issue 39)",
        "",
        f"Command: `{cmd}`; the remesh binary was built from commit {commit}. Seed {a.seed} (one run per "
        "method and case).",
        "",
        "Inputs: issue 39's scan cases, made by eval/scans.py's `make_points` (the same point sets as "
        "`eval/scans.py`): face000 = pymeshlab's range map read as points (ours: `--as-points`; MeshLab: its "
        "vertices written to a PLY without faces); square, hemisphere, band = uniform points of the "
        "surface, no normals; spot-2000/4000 = 5,000 area-uniform points of spot with normals (`remesh "
        "points`). Output count = the case's target (ours: `--points N`; Poisson + isotropic: the "
        "remeshing's edge length set from the area, tried at most twice to land within 2%; ball pivoting: "
        "a Poisson-disk subset of N points). MeshLab estimates normals (`compute_normal_for_point_clouds`, "
        "k = 10) where the points have none (all but the spot cases here). Measured by `remesh quality OUT --ref "
        "REF --json`: Hausdorff and RMS are two-sided, in bbox-100 units of REF; crossings = "
        "self-intersecting face pairs. References: " + "; ".join(refs) + ". The analytic meshes are "
        "the exact surfaces the points were drawn from: the unit square (201 x 201 grid), the unit "
        "hemisphere z >= 0 with no cap (180 rings x 720), the open band of radius 1 and height 1 "
        "(101 x 720). Screened Poisson (no density trim here) does not stop at the data's border: on the "
        "open inputs its surface runs on to the edge of its grid (the points' bounding cube scaled 1.1), where it "
        "is cut off, so its loops are that cut and its Hausdorff is the skirt's reach. The JSON also "
        "holds each side of the Hausdorff distance (forward: output to reference; backward: reference "
        "to output). Times: wall-clock seconds of the method alone (MeshLab's normal estimation "
        "included); " + load_note(rows) + ".",
        "",
    ]
    lines += table(["case", "points", "target", "method"],
                   [([r["case"], r.get("points", "–"), r["target"], r["method"]], r) for r in rows])
    lines += ["", "Methods:", ""] + [f"- `{k}`: {v}" for k, v in METHODS.items()]
    (out / "scans.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--models", default="horse")
    ap.add_argument("--count", type=int, default=1_000_000, help="input points")
    ap.add_argument("--points", type=int, default=10_000, help="output vertices")
    ap.add_argument("--variants", default="normals,no-normals,noisy")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--quick", action="store_true", help="spot, 200k -> 3k, with normals")
    ap.add_argument("--scans", metavar="CASES",
                    help="instead: eval/scans.py's cases (comma-separated, or `default`), all three methods; "
                         "writes scans.md and scans.json")
    ap.add_argument("--real", nargs="?", const="default", metavar="SCANS",
                    help="instead: the real scans (eval/points_real.py: milk, car6, table, bun000, face000; "
                         "comma-separated, or `default` for all) with ours at --seeds and MeshLab's and Open3D's "
                         "references once; writes eval/results/scans/NAME.md and NAME.json")
    ap.add_argument("--seeds", default="1-5", help="with --real: ours' seeds (1-5, or 1,3)")
    ap.add_argument("--name", default="real", help="with --real: the results' file name (default: real)")
    ap.add_argument("--no-references", dest="references", action="store_false",
                    help="with --real: ours only")
    ap.add_argument("--timeout", type=float, help="seconds a MeshLab method may take (default: no limit; "
                                                  "with --real, every run: default 600)")
    ap.add_argument("--built-from", help="the commit the remesh binary was built from (for the tables; default: "
                                         "from a binary named remesh-<hash>, else HEAD)")
    ap.add_argument("--out", default=str(ROOT / "eval" / "results" / "points"))
    a = ap.parse_args()
    if a.quick:
        a.models, a.count, a.points, a.variants = "spot", 200_000, 3000, "normals"
    if a.real:
        import points_real
        import scans

        a.real_scans = points_real.DEFAULT_SCANS if a.real == "default" else a.real
        out = Path(a.out) if a.out != ap.get_default("out") else ROOT / "eval" / "results" / "scans"
        out.mkdir(parents=True, exist_ok=True)
        points_real.run_real(a, out, scans.parse_seeds, command_line(), built_from(a.built_from))
        return
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    if a.scans:
        run_scans(a, out)
        return
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
                        seconds = run_method(key, path, a.points, a.seed, has_normals, mesh, (), a.timeout)
                        row = {"model": model, "variant": variant, "method": key, "seconds": seconds}
                        row.update(quality(mesh, SHARED / f"{model}.obj"))
                    except Exception as e:  # a method failing is a row, not the end of the run
                        row = {"model": model, "variant": variant, "method": key, "error": str(e)}
                    row["load1"] = os.getloadavg()[0]
                    print(json.dumps(row), file=sys.stderr, flush=True)
                    rows.append(row)
    (out / "points.json").write_text(json.dumps(rows, indent=1))
    lines = [
        "# Point sets to meshes",
        "",
        f"Command: `{command_line()}`; the remesh binary was built from commit {built_from(a.built_from)}.",
        "",
        f"{a.count} points drawn from each model (`remesh points`, seed {a.seed}), "
        f"remeshed to {a.points} vertices, measured by `remesh quality OUT --ref MODEL` (bbox-100 units; "
        "crossings = self-intersecting face pairs). "
        "Screened Poisson + isotropic: times include both (the remeshing is tried at most twice to land "
        "within 2% of the count). Variants: `normals` (as drawn), `no-normals` (dropped; MeshLab estimates them with k = 10), "
        "`noisy` (Gaussian noise 0.1% of the diagonal, 1% outliers in the bounding box, no normals). "
        "Times: wall-clock seconds of the method alone; " + load_note(rows) + ".",
        "",
    ]
    lines += table(["model", "input", "method"], [([r["model"], r["variant"], r["method"]], r) for r in rows])
    lines += ["", "Methods:", ""] + [f"- `{k}`: {v}" for k, v in METHODS.items()]
    (out / "points.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
