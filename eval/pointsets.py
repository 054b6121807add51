"""What the point-set drivers (eval/points.py, eval/points_real.py, eval/scans.py) share: reading
and writing PLY point sets, MeshLab's two reconstructions of them, and a child process's last line.
One module below the three, so none of them imports another's internals (the drivers import this,
never each other, but for eval/points.py dispatching to the other two)."""

import math
import subprocess
import time

import numpy as np


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


def meshlab_set(points, has_normals, viewpoint=None):
    """The points in a MeshSet, with normals estimated (k = 10) when they have none: turned towards
    `viewpoint` (x, y, z: a single scan's sensor) when given, else MeshLab's own orientation."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(points))
    if not has_normals:
        if viewpoint is None:
            ms.compute_normal_for_point_clouds(k=10)
        else:
            ms.compute_normal_for_point_clouds(k=10, flipflag=True, viewpos=np.asarray(viewpoint, dtype=np.float64))
    return ms


def run_poisson_isotropic(points, n, has_normals, out, viewpoint=None, tries=2):
    """Screened Poisson (depth 10) then isotropic remeshing at the edge length that gives about n
    vertices (at most `tries` edge lengths, each corrected from the last try's count)."""
    import pymeshlab

    t = time.perf_counter()
    ms = meshlab_set(points, has_normals, viewpoint)
    ms.generate_surface_reconstruction_screened_poisson(depth=10, preclean=True)
    poisson = ms.current_mesh_id()
    area = ms.get_geometric_measures()["surface_area"]
    h = math.sqrt(2.0 * area / (math.sqrt(3.0) * n))
    for _ in range(tries):
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


def run_ball_pivoting(points, n, has_normals, out, viewpoint=None):
    """Ball pivoting on a Poisson-disk subset of n points (MeshLab's point-cloud simplification)."""
    t = time.perf_counter()
    ms = meshlab_set(points, has_normals, viewpoint)
    ms.generate_simplified_point_cloud(samplenum=int(n))
    ms.generate_surface_reconstruction_ball_pivoting()
    seconds = time.perf_counter() - t
    ms.save_current_mesh(str(out), save_vertex_normal=False)
    return seconds


def child_last_line(args, timeout, who):
    """The last line a child process (`args`) prints: a timeout, a signal or a non-zero exit raises
    RuntimeError (`who` names the child in a signal's message)."""
    try:
        r = subprocess.run(args, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        raise RuntimeError(f"timed out after {timeout:.0f} s") from None
    if r.returncode != 0:
        if r.returncode < 0:
            raise RuntimeError(f"{who} killed by signal {-r.returncode}")
        raise RuntimeError((r.stderr.strip().splitlines() or [f"exit status {r.returncode}"])[-1])
    return r.stdout.strip().splitlines()[-1]
