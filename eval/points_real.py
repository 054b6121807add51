"""Real scans beside the references (issue 58): `eval/points --real` runs the shared scans
(../shared/scans: milk, car6, the table scene, bun000) and pymeshlab's face000 range map through
ours (every seed) and, once per scan (they are deterministic), MeshLab's screened Poisson +
isotropic remeshing, MeshLab's ball pivoting and Open3D's screened Poisson, and measures every
output with one set of rulers against issue 58's acceptance.

    eval/points --real                                    # every scan, seeds 1-5
    eval/points --real --seeds 1 --scans milk,car6 --name real-seed1

Runs (each in its own process, `--timeout` seconds at most, 600 by default):
- `ours`: `remesh SCAN OUT.obj --points N --seed S -q --no-distance` on the scan's own file (face000:
  `--as-points`), timed as a whole process (reading the scan and writing the mesh included). The
  normals are ours to estimate: towards the PCD's VIEWPOINT, face000's camera, and for bun000.xyz
  (no viewpoint) outward by a spanning tree.
- `meshlab_poisson_isotropic`: eval/pointsets.py's `run_poisson_isotropic` (normals k = 10 turned
  towards the scan's viewpoint where it has one; screened Poisson depth 10 with preclean, no density
  trim; isotropic remeshing, 10 iterations, to about N vertices: at most five edge lengths, h ← h·√(V/N),
  until within 2%).
- `meshlab_ball_pivoting`: eval/pointsets.py's `run_ball_pivoting` (the same normals; Poisson-disk
  subset of N points, ball pivoting at its defaults).
- `open3d_poisson`: Open3D (`open3d-cpu` on PyPI, the project's CPU build): normals by
  `estimate_normals` (30 nearest neighbours) turned towards the viewpoint
  (`orient_normals_towards_camera_location`; bun000: `orient_normals_consistent_tangent_plane(10)`),
  `create_from_point_cloud_poisson(depth=10)`, the vertices below the 1% quantile of the density
  removed (Open3D's tutorial), then `simplify_quadric_decimation` to about N vertices (the triangle
  target scaled by N / vertices, once corrected) when the trimmed mesh has more than N.
The references' seconds are those of the library calls (normal estimation included), in their
child process after reading the points; ours' are the whole process.

The references read the scan's finite points written as a binary PLY (positions only): PCD read
by Open3D (`read_point_cloud`, NaN and infinite points removed), bun000.xyz by NumPy, face000's
vertices (its faces dropped). The viewpoint: a PCD's VIEWPOINT translation, face000's camera
(`view_px view_py view_pz`), none for bun000.

Definitions (every method of a scan is measured with the same spacing and the same data):
- output spacing h: the mean length of the edges of ours' output (each edge once), the median
  over the seeds run (the first other method's output if ours failed at every seed);
- parts: the output's faces joined when they share an edge (bit-identical positions welded
  first), counted when a part holds at least 1% of the faces (all parts in the JSON);
- data surfaces: the scan's points joined when closer than 2h (scipy's cKDTree.query_pairs and
  connected components), counted when a component holds at least 1% of the points; points in
  smaller components are the outliers;
- loops, θmin, Qave: `remesh quality OUT --json` (boundary loops; Table 1's θmin and Qave);
  θmin inner: the smallest angle of the faces with no vertex on the boundary;
- out→data: each output vertex's distance to the nearest data point, in h (max, and % farther
  than h); data→out: each data point's distance to the output surface (Open3D's
  RaycastingScene.compute_distance, exact point-to-triangle), in h (% farther than h among the
  points that are not outliers, the same among all points, and the 99th percentile);
- CGAL: eval/cgal_ruler.py's `check` (does_self_intersect and self_intersections on the file as
  written: crossing and folded pairs, a degenerate face as a pair of its own; no answer on a
  non-manifold mesh, which its Polyhedron_3 cannot hold); beside it our own ruler's count
  (`remesh quality`'s self-intersecting pairs, the same definition, any mesh);
- face000 also: the two-sided Hausdorff distance (bbox-100 of the reference) by
  `remesh quality OUT --ref REF` to the range map's own mesh with its pieces of fewer than 10
  vertices left out.

Acceptance (ours, every seed): parts ≤ data surfaces; 0 CGAL pairs; θmin inner ≥ 25; out→data max
≤ h; data→out: at most 1% of the non-outlier points farther than h; seconds ≤ 10 per 100k input
points; face000's Hausdorff ≤ 0.5. Writes eval/results/scans/NAME.md and NAME.json (NAME: `real` by
default); meshes go to a temporary folder.
"""

import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SCANS_DIR = ROOT.parent / "shared" / "scans"
REMESH = Path(os.environ.get("REMESH_BIN", ROOT / "target" / "release" / "remesh"))

# name: (file, output vertices for ours and the references, ours' extra arguments)
SCANS = {
    "milk": ("milk.pcd", 3000, []),
    "car6": ("car6.pcd", 2000, []),
    "table": ("table_scene_mug_stereo_textured.pcd", 20000, []),
    "bun000": ("bun000.xyz", 5000, []),
    "face000": (None, 20000, ["--as-points"]),  # pymeshlab's range map, as eval/scans.py
}
DEFAULT_SCANS = "milk,car6,table,bun000,face000"
METHODS = {
    "ours": "remesh (spectral sampling on RIMLS), whole process",
    "meshlab_poisson_isotropic": "MeshLab screened Poisson (depth 10, no trim) + isotropic remeshing (10 it.) to N",
    "meshlab_ball_pivoting": "MeshLab Poisson-disk subset of N points + ball pivoting (defaults)",
    "open3d_poisson": "Open3D Poisson (depth 10), density trimmed at its 1% quantile, quadric decimation to N",
}
REFERENCES = [k for k in METHODS if k != "ours"]
NOTES = [
    "A reference's V is what it made after its tries at N. MeshLab's isotropic remeshing keeps edges sharper "
    "than its default featuredeg = 30°, and the Poisson surface of car6's sparse LiDAR rings is full of them: "
    "measured once by hand on car6's Poisson mesh (38,741 vertices), edge lengths 1, 2 and 4 times the one for "
    "2,000 vertices gave 12,259, 11,424 and 11,277 vertices (with featuredeg = 180: 2,851, 1,822, 1,710). The "
    "rows keep MeshLab's default, as eval/run and eval/points' other modes do.",
    "Screened Poisson closes the surface: MeshLab's (untrimmed) runs on past the data, and Open3D's after the "
    "1% density trim still does (the out→data columns); their loops are where the trim or the grid cut it.",
    "Ball pivoting's vertices are data points (out→data 0); its V is the triangulated part of the N-point "
    "subset; where its mesh is non-manifold CGAL gives no answer (our ruler's count beside it).",
]


def face000_path():
    import trimesh

    return Path(trimesh.__file__).parent.parent / "pymeshlab/tests/sample_meshes/rangemaps/face000.ply"


def scan_path(name):
    f = SCANS[name][0]
    return face000_path() if f is None else SCANS_DIR / f


def pcd_viewpoint(path):
    """The translation of a PCD header's VIEWPOINT (tx ty tz qw qx qy qz), or None."""
    with open(path, "rb") as fh:
        for line in fh:
            words = line.decode(errors="replace").split()
            if words[:1] == ["VIEWPOINT"]:
                return [float(x) for x in words[1:4]]
            if words[:1] == ["DATA"]:
                return None
    return None


def ply_camera(path):
    """A binary PLY range map's camera position (view_px, view_py, view_pz), or None."""
    raw = Path(path).read_bytes()[:65536]
    header = raw[: raw.index(b"end_header\n")].decode(errors="replace").split("\n")
    start = raw.index(b"end_header\n") + len(b"end_header\n")
    sizes = {"float": 4, "int": 4, "float32": 4, "int32": 4, "uchar": 1, "uint8": 1, "double": 8}
    props, in_camera = [], False
    for line in header:
        w = line.split()
        if w[:1] == ["element"]:
            if in_camera:
                break
            in_camera = w[1] == "camera"
            if not in_camera and not props:
                return None  # the camera comes first when there is one
        elif w[:1] == ["property"] and in_camera:
            props.append((w[2], w[1]))
    if not props:
        return None
    offset, out = start, {}
    for name, kind in props:
        if name in ("view_px", "view_py", "view_pz"):
            out[name] = float(np.frombuffer(raw[offset : offset + 4], "<f4")[0])
        offset += sizes[kind]
    return [out["view_px"], out["view_py"], out["view_pz"]]


def load_scan(name):
    """The scan's finite points (float64, n x 3) and its viewpoint (or None)."""
    path = scan_path(name)
    if path.suffix == ".pcd":
        import open3d as o3d

        pc = o3d.io.read_point_cloud(str(path), remove_nan_points=True, remove_infinite_points=True)
        return np.asarray(pc.points, dtype=np.float64), pcd_viewpoint(path)
    if path.suffix == ".xyz":
        P = np.loadtxt(path)[:, :3]
        return P[np.isfinite(P).all(1)], None
    import trimesh

    m = trimesh.load(path, process=False)
    return np.asarray(m.vertices, dtype=np.float64), ply_camera(path)


# ---- the references, each run in a child process ----


def meshlab_poisson_isotropic(points, n, viewpoint, out):
    import pointsets as pts

    return {"seconds": pts.run_poisson_isotropic(Path(points), n, False, Path(out), viewpoint, tries=5)}


def meshlab_ball_pivoting(points, n, viewpoint, out):
    import pointsets as pts

    return {"seconds": pts.run_ball_pivoting(Path(points), n, False, Path(out), viewpoint)}


def open3d_poisson(points, n, viewpoint, out, depth=10, quantile=0.01):
    import open3d as o3d

    pcd = o3d.io.read_point_cloud(str(points))
    t = time.perf_counter()
    pcd.estimate_normals(search_param=o3d.geometry.KDTreeSearchParamKNN(knn=30))
    if viewpoint is not None:
        pcd.orient_normals_towards_camera_location(np.asarray(viewpoint, dtype=np.float64))
    else:
        pcd.orient_normals_consistent_tangent_plane(10)
    mesh, dens = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=depth)
    dens = np.asarray(dens)
    mesh.remove_vertices_by_mask(dens < np.quantile(dens, quantile))
    poisson_v = len(mesh.vertices)
    if poisson_v > n:
        base, target = mesh, len(mesh.triangles) * n / poisson_v
        for _ in range(2):
            mesh = base.simplify_quadric_decimation(target_number_of_triangles=int(round(target)))
            v = len(mesh.vertices)
            if abs(v - n) <= 0.02 * n:
                break
            target *= n / v
        mesh.remove_unreferenced_vertices()
    seconds = time.perf_counter() - t
    o3d.io.write_triangle_mesh(str(out), mesh, write_vertex_normals=False, write_vertex_colors=False,
                               write_triangle_uvs=False)
    return {"seconds": seconds, "poisson_vertices_after_trim": poisson_v}


CHILD = ("import sys, json; sys.path.insert(0, sys.argv[1]); import points_real as r; "
         "a = json.loads(sys.argv[2]); print(json.dumps(getattr(r, a['f'])(**a['kw'])))")


def run_child(key, points, n, viewpoint, out, timeout):
    """A reference in a child process: its result dict; a crash or a timeout raises."""
    import pointsets as pts

    arg = json.dumps({"f": key, "kw": {"points": str(points), "n": n, "viewpoint": viewpoint, "out": str(out)}})
    return json.loads(pts.child_last_line([sys.executable, "-c", CHILD, str(HERE), arg], timeout, "child"))


def run_ours(path, n, seed, out, extra, timeout):
    t = time.perf_counter()
    try:
        r = subprocess.run([str(REMESH), str(path), str(out), "--points", str(n), "--seed", str(seed),
                            "--no-distance", "-q"] + list(extra), capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        raise RuntimeError(f"timed out after {timeout:.0f} s") from None
    seconds = time.perf_counter() - t
    if r.returncode != 0:
        raise RuntimeError((r.stderr.strip().splitlines() or [f"exit status {r.returncode}"])[-1])
    return {"seconds": seconds}


# ---- measures ----


def read_welded(path):
    """Vertices and faces of a mesh file, bit-identical positions welded, unreferenced vertices
    dropped."""
    import trimesh

    m = trimesh.load(str(path), process=False, force="mesh")
    V, F = np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)
    U, inv = np.unique(V, axis=0, return_inverse=True)
    F = inv.reshape(-1)[F]
    used = np.unique(F)
    remap = np.full(len(U), -1)
    remap[used] = np.arange(len(used))
    return U[used], remap[F]


def mean_edge(V, F):
    e = np.unique(np.sort(np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1), axis=0)
    return float(np.linalg.norm(V[e[:, 0]] - V[e[:, 1]], axis=1).mean())


def edge_parts(F):
    """Component label of each face, faces joined when they share an edge."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nf = len(F)
    e = np.sort(np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, eid = np.unique(e, axis=0, return_inverse=True)
    eid = eid.reshape(-1)
    face = np.tile(np.arange(nf), 3)
    g = coo_matrix((np.ones(len(face)), (face, nf + eid)), shape=(nf + eid.max() + 1,) * 2)
    _, labels = connected_components(g, directed=False)
    return labels[:nf]


def data_surfaces(P, h):
    """(count of components with >= 1% of the points, outlier mask): points joined closer than 2h."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pairs = cKDTree(P).query_pairs(2.0 * h, output_type="ndarray")
    g = coo_matrix((np.ones(len(pairs), dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(len(P), len(P)))
    k, labels = connected_components(g, directed=False)
    sizes = np.bincount(labels, minlength=k)
    big = sizes >= 0.01 * len(P)
    return int(big.sum()), ~big[labels], int(k)


def points_to_surface(P, V, F):
    """Each point's distance to the triangles (Open3D RaycastingScene, float32 about the centre)."""
    import open3d as o3d

    c = V.mean(0)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor((V - c).astype(np.float32)), o3d.core.Tensor(F.astype(np.uint32)))
    return scene.compute_distance(o3d.core.Tensor((P - c).astype(np.float32))).numpy().astype(np.float64)


def quality(path, ref=None):
    cmd = [str(REMESH), "quality", str(path), "--json"] + (["--ref", str(ref)] if ref else [])
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError("remesh quality: " + (r.stderr.strip().splitlines() or ["failed"])[-1])
    return json.loads(r.stdout)


def measure(path, P, outliers, h, hausdorff_ref=None):
    import cgal_ruler
    from scipy.spatial import cKDTree

    import scans

    V, F = read_welded(path)
    if len(F) == 0:
        raise RuntimeError("no faces written")
    q = quality(path)
    topo, tri = q["topology"], q["triangles"]
    labels = edge_parts(F)
    sizes = np.bincount(labels)
    th = np.nan_to_num(scans.angles(V, F), nan=0.0)
    on_b = np.zeros(len(V), bool)
    on_b[scans.boundary_vertices(F)] = True
    inner = ~on_b[F].any(1)
    d_out = cKDTree(P).query(V)[0] / h
    d_in = points_to_surface(P, V, F) / h
    cg = cgal_ruler.check(path, timeout=600)
    row = {
        "vertices": int(len(V)),
        "faces": int(len(F)),
        "spacing": h,
        "parts": int((sizes >= 0.01 * len(F)).sum()),
        "parts_all": int(len(sizes)),
        "loops": topo["boundary_loops"],
        "non_manifold": topo["non_manifold_edges"] + topo["non_manifold_vertices"],
        "theta_min": tri["theta_min"],
        "theta_min_inner": float(th[inner].min()) if inner.any() else None,
        "q_ave": tri["q_ave"],
        "out_to_data_max": float(d_out.max()),
        "out_to_data_pct_far": 100.0 * float((d_out > 1.0).mean()),
        "data_to_out_pct_far": 100.0 * float((d_in[~outliers] > 1.0).mean()),
        "data_to_out_pct_far_all": 100.0 * float((d_in > 1.0).mean()),
        "data_to_out_p99": float(np.quantile(d_in, 0.99)),
        "cgal_pairs": cg.get("pairs"),
        "cgal_error": cg.get("error"),
        "our_crossings": q["self_intersections"]["pairs"],
    }
    if hausdorff_ref is not None:
        row["hausdorff"] = quality(path, hausdorff_ref)["distance"]["hausdorff"]
    return row


def face000_reference(work):
    """face000's range-map mesh without its pieces of fewer than 10 vertices (PLY in `work`)."""
    import trimesh

    out = work / "face000-reference.ply"
    m = trimesh.load(face000_path(), process=False)
    keep = np.zeros(len(m.vertices), bool)
    for c in trimesh.graph.connected_components(m.edges, nodes=np.arange(len(m.vertices))):
        if len(c) >= 10:
            keep[c] = True
    faces = m.faces[keep[m.faces].all(1)]
    r = trimesh.Trimesh(m.vertices, faces, process=False)
    r.remove_unreferenced_vertices()
    r.export(out)
    return out


# ---- the run ----

LOW_IS_WORSE = {"theta_min", "theta_min_inner", "q_ave"}
COLS = [  # key, head, format
    ("vertices", "V", "d"), ("parts", "parts", "d"), ("loops", "loops", "d"), ("theta_min", "θmin", ".1f"),
    ("theta_min_inner", "θmin inner", ".1f"), ("q_ave", "Qave", ".3f"), ("out_to_data_max", "out→data max (h)", ".2f"),
    ("out_to_data_pct_far", "out→data >h %", ".2f"), ("data_to_out_pct_far", "data→out >h % (no outliers)", ".2f"),
    ("data_to_out_pct_far_all", "data→out >h % (all)", ".2f"), ("data_to_out_p99", "data→out p99 (h)", ".2f"),
    ("cgal_pairs", "CGAL pairs", "d"), ("our_crossings", "crossings (ours' ruler)", "d"), ("seconds", "s", ".1f"), ("s_per_100k", "s / 100k pts", ".1f"),
    ("hausdorff", "Hausdorff", ".3f"),
]


def checks(row, surfaces, name):
    """Issue 58's acceptance items for one of ours' rows: {item: (passed, value)}."""
    c = {
        "V in 2k–20k (±1%)": (0.99 * 2000 <= row["vertices"] <= 1.01 * 20000, row["vertices"]),
        "parts ≤ surfaces": (row["parts"] <= surfaces, row["parts"]),
        "0 CGAL pairs": (row["cgal_pairs"] == 0, row["cgal_pairs"]),
        "θmin inner ≥ 25": (row["theta_min_inner"] is not None and row["theta_min_inner"] >= 25.0,
                            row["theta_min_inner"]),
        "out→data ≤ h": (row["out_to_data_max"] <= 1.0, row["out_to_data_max"]),
        "data→out >h ≤ 1%": (row["data_to_out_pct_far"] <= 1.0, row["data_to_out_pct_far"]),
        "≤ 10 s / 100k pts": (row["s_per_100k"] <= 10.0, row["s_per_100k"]),
    }
    if name == "face000":
        c["Hausdorff ≤ 0.5"] = (row.get("hausdorff") is not None and row["hausdorff"] <= 0.5, row.get("hausdorff"))
    return c


def fmt(x, f):
    if x is None:
        return "–"
    if f == "d":
        return str(int(round(x)))
    return format(x, f)


def run_real(a, out_dir, parse_seeds, command, commit):
    from pointsets import write_points

    seeds = parse_seeds(a.seeds)
    names = a.real_scans.split(",")
    timeout = a.timeout or 600.0
    results = []
    with tempfile.TemporaryDirectory(prefix="eval-points-real-") as tmp:
        work = Path(tmp)
        for name in names:
            fname, n, extra = SCANS[name]
            src = scan_path(name)
            P, viewpoint = load_scan(name)
            pts_ply = work / f"{name}-points.ply"
            write_points(pts_ply, P)
            entry = {"scan": name, "file": str(src.name), "points": int(len(P)), "target": n, "viewpoint": viewpoint,
                     "runs": []}
            print(f"{name}: {len(P)} points, viewpoint {viewpoint}", file=sys.stderr, flush=True)
            runs = []
            for seed in seeds:
                mesh = work / f"{name}-ours-{seed}.obj"
                try:
                    runs.append(dict(method="ours", seed=seed, mesh=mesh, **run_ours(src, n, seed, mesh, extra, timeout)))
                except Exception as e:
                    runs.append(dict(method="ours", seed=seed, error=str(e)))
                runs[-1]["load1"] = os.getloadavg()[0]
                print(f"  ours seed {seed}: {runs[-1].get('seconds', runs[-1].get('error'))}", file=sys.stderr,
                      flush=True)
            for key in REFERENCES if a.references else []:
                mesh = work / f"{name}-{key}.obj"
                try:
                    runs.append(dict(method=key, mesh=mesh, **run_child(key, pts_ply, n, viewpoint, mesh, timeout)))
                except Exception as e:
                    runs.append(dict(method=key, error=str(e)))
                runs[-1]["load1"] = os.getloadavg()[0]
                print(f"  {key}: {runs[-1].get('seconds', runs[-1].get('error'))}", file=sys.stderr, flush=True)
            # the output spacing: ours' mean edge length, median over the seeds
            edges = []
            for r in runs:
                if "mesh" in r and r["method"] == "ours":
                    try:
                        edges.append(mean_edge(*read_welded(r["mesh"])))
                    except Exception:
                        pass
            spacing_from = "ours"
            if not edges:
                for r in runs:
                    if "mesh" in r:
                        edges, spacing_from = [mean_edge(*read_welded(r["mesh"]))], r["method"]
                        break
            if not edges:
                entry.update(error="no method wrote a mesh", runs=[{k: v for k, v in r.items() if k != "mesh"}
                                                                    for r in runs])
                results.append(entry)
                continue
            h = statistics.median(edges)
            surfaces, outliers, comps = data_surfaces(P, h)
            entry.update(spacing=h, spacing_from=spacing_from, data_surfaces=surfaces, data_components=comps,
                         outliers=int(outliers.sum()))
            href = face000_reference(work) if name == "face000" else None
            for r in runs:
                mesh = r.pop("mesh", None)
                if mesh is not None:
                    try:
                        r.update(measure(mesh, P, outliers, h, href))
                        r["s_per_100k"] = r["seconds"] / (len(P) / 1e5)
                    except Exception as e:
                        r["error"] = f"measure: {e}"
                if r["method"] == "ours" and "error" not in r:
                    r["checks"] = {k: v[0] for k, v in checks(r, surfaces, name).items()}
                print("  " + json.dumps(r), file=sys.stderr, flush=True)
                entry["runs"].append(r)
            results.append(entry)
    report = {"command": command, "built_from": commit, "seeds": seeds, "timeout": timeout, "results": results}
    (out_dir / f"{a.name}.json").write_text(json.dumps(report, indent=1))
    lines = write_table(report, out_dir / f"{a.name}.md")
    print("\n".join(lines))


def agg(vals, key):
    vals = [v for v in vals if v is not None]
    if not vals:
        return None, None
    worst = min(vals) if key in LOW_IS_WORSE else max(vals)
    return statistics.median(vals), worst


def load_note(report):
    loads = [r["load1"] for e in report["results"] for r in e.get("runs", []) if "load1" in r]
    if not loads:
        return "load not recorded"
    return (f"{os.cpu_count()} cores shared with another job, 1-minute load average at the runs' ends "
            f"{min(loads):.1f} to {max(loads):.1f}")


def write_table(report, path):
    seeds = report["seeds"]
    seed_text = f"seeds {seeds[0]}-{seeds[-1]}" if len(seeds) > 1 and seeds == list(range(seeds[0], seeds[-1] + 1)) \
        else "seed" + ("s " if len(seeds) > 1 else " ") + ", ".join(map(str, seeds))
    lines = [
        "# Real scans to meshes beside the references (issue 58)",
        "",
        f"Command: `{report['command']}`; the remesh binary was built from {report['built_from']}. Ours at "
        f"{seed_text} (a cell of ours: median / worst over the seeds; θmin, θmin inner, Qave: lowest is worst, the "
        f"rest: largest); the references once per scan (deterministic). Every run in its own process, "
        f"{report['timeout']:.0f} s at most.",
        "",
        "h = the output spacing: the mean edge length of ours' output (median over the seeds), the same for "
        "every method of a scan. Parts: faces joined by shared edges, counted with ≥ 1% of the faces. Data "
        "surfaces: the scan's points joined when closer than 2h, components with ≥ 1% of the points (the points "
        "in smaller ones are the outliers). out→data: output vertices to the nearest point; data→out: points to "
        "the output's triangles (exact). CGAL pairs: eval/cgal_ruler.py (crossings and folds; a degenerate face "
        "counts as a pair; none on a non-manifold mesh, where CGAL builds no polyhedron); crossings (ours' ruler): `remesh quality`'s self-intersecting pairs (the same definition, any mesh). θmin inner: faces with no vertex on the boundary. Hausdorff (face000 only): two-sided, "
        "bbox-100, to the range map's own mesh without its pieces of fewer than 10 vertices. Seconds: ours, the "
        "whole process; the references, their library calls; " + load_note(report) + ". The definitions in "
        "full: eval/points_real.py's docstring.",
        "",
    ]
    head = ["scan", "points", "N", "h", "data surfaces", "method"] + [c[1] for c in COLS]
    lines += ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    accept = []
    for e in report["results"]:
        lab = [e["scan"], str(e["points"]), str(e["target"]), fmt(e.get("spacing"), ".4g"),
               f"{e.get('data_surfaces', '–')} ({e.get('outliers', '–')} outliers)"]
        if "error" in e:
            lines.append("| " + " | ".join(lab + [f"error: {e['error']}"] + [""] * len(COLS)) + " |")
            continue
        ours = [r for r in e["runs"] if r["method"] == "ours"]
        ok = [r for r in ours if "error" not in r]
        cells = []
        for key, _, f in COLS:
            med, worst = agg([r.get(key) for r in ok], key)
            if med is None:
                cells.append("–")
            elif len(ok) == 1:
                cells.append(fmt(med, f))
            else:
                cells.append(f"{fmt(med, '.1f' if f == 'd' and med != int(med) else f)} / {fmt(worst, f)}")
        failed = [f"seed {r['seed']}: {r['error']}" for r in ours if "error" in r]
        m = "ours" + (f" ({len(failed)} failed: {'; '.join(failed)})" if failed else "")
        lines.append("| " + " | ".join(lab + [m] + cells) + " |")
        for r in e["runs"]:
            if r["method"] == "ours":
                continue
            if "error" in r:
                lines.append("| " + " | ".join(lab + [r["method"], "error: " + str(r["error"]).replace("|", "/")[:200]]
                                               + [""] * (len(COLS) - 1)) + " |")
            else:
                lines.append("| " + " | ".join(lab + [r["method"]] + [fmt(r.get(k), f) for k, _, f in COLS]) + " |")
        if ok:
            items = {}
            for r in ok:
                for k, (passed, value) in checks(r, e["data_surfaces"], e["scan"]).items():
                    items.setdefault(k, []).append((passed, value, r["seed"]))
            accept.append((e["scan"], items, len(ours) - len(ok)))
    lines += ["", "Acceptance for ours (every seed must pass; the worst seed's value in brackets, the failing "
              "seeds after it):", ""]
    keys = list(dict.fromkeys(k for _, items, _ in accept for k in items))
    lines += ["| scan | " + " | ".join(keys) + " | runs failed |", "|---" * (len(keys) + 2) + "|"]
    for scan, items, nfailed in accept:
        cells = []
        for k in keys:
            if k not in items:
                cells.append("n/a")
                continue
            vals = items[k]
            bad = [s for p, _, s in vals if not p]
            nums = [v for _, v, _ in vals if v is not None]
            worst = None if not nums else (min(nums) if "θ" in k else max(nums))
            w = "–" if worst is None else (f"{worst:.3g}" if isinstance(worst, float) else str(worst))
            cells.append(("PASS" if not bad else "FAIL") + f" ({w})" + (f" seeds {','.join(map(str, bad))}" if bad
                                                                        else ""))
        lines.append(f"| {scan} | " + " | ".join(cells) + f" | {nfailed} |")
    lines += ["", "Methods:", ""] + [f"- `{k}`: {v}" for k, v in METHODS.items()]
    lines += ["", "Notes:", ""] + [f"- {x}" for x in NOTES]
    errs = [(e["scan"], r["method"], r["cgal_error"]) for e in report["results"] for r in e.get("runs", [])
            if r.get("cgal_error")]
    if errs:
        lines += ["", "CGAL gave no answer for: " + "; ".join(f"{s} {m} ({x})" for s, m, x in errs) + "."]
    path.write_text("\n".join(lines) + "\n")
    return lines
