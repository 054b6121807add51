"""`remesh` on a point set (F=None): the command line's point-set path from numpy arrays, the
same mesh as `remesh` on a text file of the same points, and its refusals."""

import subprocess

import numpy as np
import pytest

import spectral_remesh as sr


def sphere_points(n, seed, radius=3.7, centre=(0.1, -2.3, 5.0)):
    """`n` points uniform on a sphere and their outward unit normals."""
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return v * radius + np.asarray(centre), v


def write_xyz(path, points, normals=None):
    """A text point file, each value written so it reads back to the same float64."""
    rows = points if normals is None else np.hstack([points, normals])
    with open(path, "w") as f:
        for row in rows:
            f.write(" ".join(repr(float(x)) for x in row) + "\n")


@pytest.mark.parametrize("with_normals,seed", [(True, 1), (False, 2)])
def test_points_give_the_command_lines_mesh(tmp_path, remesh_bin, with_normals, seed):
    points, normals = sphere_points(20_000, seed)
    given = normals if with_normals else None
    xyz = tmp_path / ("p.xyzn" if with_normals else "p.xyz")
    write_xyz(xyz, points, given)
    out = tmp_path / "out.ply"
    subprocess.run(
        [remesh_bin, xyz, out, "--points", "800", "--seed", str(seed), "-q"], check=True
    )
    V0, F0 = sr.read(out)
    V, F, report = sr.remesh(points, normals=given, points=800, seed=seed)
    assert np.array_equal(V, V0) and np.array_equal(F, F0)
    topo = report["topology"]
    assert topo["components"] == 1 and topo["boundary_edges"] == 0
    assert topo["euler_characteristic"] == 2
    assert report["extra"]["had_normals"] == with_normals
    # On the sphere, to the RIMLS surface's bias sigma_p^2 / (2R), about 0.6% of R at 800
    # points: every vertex within 2% of the radius.
    r = np.linalg.norm(V - np.array([0.1, -2.3, 5.0]), axis=1)
    assert np.all(np.abs(r - 3.7) < 0.02 * 3.7)


def test_a_viewpoint_orients_the_estimated_normals(tmp_path):
    # An open cap of a sphere seen from far above: the output faces the sensor.
    rng = np.random.default_rng(5)
    v = rng.normal(size=(40_000, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    cap = v[v[:, 2] > 0.5] * 10.0
    V, F, _ = sr.remesh(cap, points=600, viewpoint=(0.0, 0.0, 100.0), distance=False)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    n = np.cross(b - a, c - a)
    assert np.mean(n[:, 2] > 0) > 0.99


def test_point_set_refusals_are_value_errors():
    points, normals = sphere_points(2000, 3)
    F = np.array([[0, 1, 2]])
    with pytest.raises(ValueError, match="for a point set"):
        sr.remesh(points, F, normals=normals, points=100)
    with pytest.raises(ValueError, match="for a point set"):
        sr.remesh(points, F, viewpoint=(0, 0, 1), points=100)
    with pytest.raises(ValueError, match="not with normals"):
        sr.remesh(points, normals=normals, viewpoint=(0, 0, 1), points=100)
    with pytest.raises(ValueError, match="viewpoint"):
        sr.remesh(points, viewpoint=(0, 1), points=100)
    with pytest.raises(ValueError, match="viewpoint"):
        sr.remesh(points, viewpoint=(0, np.nan, 1), points=100)
    with pytest.raises(ValueError, match=r"normals must have the shape of V"):
        sr.remesh(points, normals=normals[:10], points=100)
    bad = points.copy()
    bad[7, 1] = np.nan
    with pytest.raises(ValueError, match="point 7"):
        sr.remesh(bad, points=100)
    zero = normals.copy()
    zero[3] = 0.0
    with pytest.raises(ValueError, match="normal 3"):
        sr.remesh(points, normals=zero, points=100)
    with pytest.raises(ValueError, match="input points"):
        sr.remesh(points)
    with pytest.raises(ValueError, match="lfs_factor"):
        sr.remesh(points, points=100, lfs_factor=0.75)
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        sr.remesh(points[:, :2], points=100)


def test_parts_far_apart_are_meshed_each(tmp_path, remesh_bin):
    # Two spheres 10^6 apart (each under 1e-3 of the whole): one scale cannot hold both, so each
    # is meshed on its own; the array gives what the file gives.
    a, _ = sphere_points(3000, 7, radius=5.0, centre=(0.0, 0.0, 0.0))
    b, _ = sphere_points(3000, 8, radius=5.0, centre=(1e6, 0.0, 0.0))
    points = np.vstack([a, b])
    xyz = tmp_path / "two.xyz"
    write_xyz(xyz, points)
    out = tmp_path / "two.ply"
    subprocess.run([remesh_bin, xyz, out, "--points", "400", "-q"], check=True)
    V0, F0 = sr.read(out)
    V, F, report = sr.remesh(points, points=400)
    assert np.array_equal(V, V0) and np.array_equal(F, F0)
    topo = report["topology"]
    assert topo["components"] == 2 and topo["boundary_edges"] == 0
    assert topo["euler_characteristic"] == 4
    assert len(report["extra"]["separate_parts"]) == 2
    near_a = np.linalg.norm(V, axis=1) < 1e5
    assert 0.4 < near_a.mean() < 0.6


def _pcd(path, points, normals=None, data="ascii"):
    fields = "x y z" + (" normal_x normal_y normal_z" if normals is not None else "")
    k = len(fields.split())
    rows = points if normals is None else np.hstack([points, normals])
    head = (
        f"VERSION .7\nFIELDS {fields}\nSIZE {' '.join(['4'] * k)}\nTYPE {' '.join(['F'] * k)}\n"
        f"COUNT {' '.join(['1'] * k)}\nWIDTH {len(rows)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
        f"POINTS {len(rows)}\nDATA {data}\n"
    )
    if data == "ascii":
        body = "".join(" ".join(f"{v:.6f}" for v in r) + "\n" for r in rows).encode()
    else:
        body = np.asarray(rows, dtype=np.float32).tobytes()
    path.write_bytes(head.encode() + body)


def test_read_points_reads_the_point_formats_of_the_command_line(tmp_path):
    # Issue 76 (R15): sr.read opened no .pcd, .las, .laz or .e57; sr.read_points reads what the
    # command line reads, and a missing file is an OSError, not a ValueError.
    rng = np.random.default_rng(3)
    p = rng.normal(size=(50, 3))
    n = p / np.linalg.norm(p, axis=1)[:, None]
    _pcd(tmp_path / "a.pcd", p, n, data="binary")
    P, N = sr.read_points(tmp_path / "a.pcd")
    assert P.shape == (50, 3) and N.shape == (50, 3)
    np.testing.assert_allclose(P, p.astype(np.float32), rtol=0, atol=0)
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-6)
    np.savetxt(tmp_path / "b.xyz", p)
    P, N = sr.read_points(tmp_path / "b.xyz")
    assert N is None
    np.testing.assert_allclose(P, p, atol=1e-12)
    with pytest.raises(FileNotFoundError, match="missing.pcd"):
        sr.read_points(tmp_path / "missing.pcd")
    with pytest.raises(FileNotFoundError, match="missing.laz"):
        sr.read_points(tmp_path / "missing.laz")
    # A header promising more than the file holds: a ValueError naming the file.
    bad = tmp_path / "bad.pcd"
    bad.write_bytes(b"VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 9\n"
                    b"HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1000000000000\nDATA binary\n" + bytes(90))
    with pytest.raises(ValueError, match="bad.pcd"):
        sr.read_points(bad)
