"""Tests of `sample` and `resample`: point sets near manifolds of other dimensions in R^d.

The figures are measured on the manifold, with its own (geodesic) distances, as the Rust tests
in tests/manifold_sampling.rs measure them (there at seeds 1-5 on data of their own):

- the circle: the gap ratio, the largest angular gap between consecutive samples over the
  smallest;
- the others: the normalized Poisson-disk radius rho = d_min / d_max (Lagae and Dutré 2008),
  d_min the smallest geodesic distance between two samples, d_max that of n points in the
  densest packing of the manifold's volume V: sqrt(2 V / (sqrt(3) n)) on a surface (hexagonal),
  (sqrt(2) V / n)^(1/3) on a 3-manifold (face-centred cubic).

Run with `-s` to see the figures. Needs no data files.
"""


import numpy as np
import pytest

import spectral_remesh as sr

TAU = 2 * np.pi


# --- Manifolds and their figures -------------------------------------------------------------


def circle(seed, n=100_000):
    """n points on the unit circle in R^2 at uniform random angles."""
    t = np.random.default_rng(seed).uniform(0, TAU, n)
    return np.c_[np.cos(t), np.sin(t)]


def gap_ratio(Y):
    """The largest angular gap between consecutive points of Y (on the unit circle) over the
    smallest."""
    a = np.sort(np.arctan2(Y[:, 1], Y[:, 0]))
    gaps = np.diff(np.r_[a, a[0] + TAU])
    return gaps.max() / gaps.min()


def rho(d_min, n, m, volume):
    """rho of n points with smallest distance d_min on a manifold of dimension m (2 or 3) and
    volume `volume`."""
    if m == 2:
        d_max = np.sqrt(2 * volume / (np.sqrt(3) * n))
    else:
        d_max = (np.sqrt(2) * volume / n) ** (1 / 3)
    return d_min / d_max


def min_pair(D):
    """The smallest off-diagonal entry of a square distance matrix."""
    D = D.copy()
    np.fill_diagonal(D, np.inf)
    return D.min()


def wrap(d):
    """Angle differences wrapped to [0, pi]."""
    d = np.mod(d, TAU)
    return np.minimum(d, TAU - d)


R_TORUS = np.sqrt(0.5)


def clifford_torus(seed, n=100_000):
    """(cos a, sin a, cos b, sin b) / sqrt(2) in R^4: flat, area 2 pi^2."""
    a, b = np.random.default_rng(seed).uniform(0, TAU, (2, n))
    return R_TORUS * np.c_[np.cos(a), np.sin(a), np.cos(b), np.sin(b)]


def torus_rho(Y):
    a = np.arctan2(Y[:, 1], Y[:, 0])
    b = np.arctan2(Y[:, 3], Y[:, 2])
    D = R_TORUS * np.hypot(wrap(a[:, None] - a[None]), wrap(b[:, None] - b[None]))
    return rho(min_pair(D), len(Y), 2, 2 * np.pi**2)


def spiral_length(t):
    """The arc length of the spiral (t cos t, t sin t) from 0 to t."""
    return 0.5 * (t * np.sqrt(1 + t * t) + np.arcsinh(t))


T0, T1, HEIGHT = 1.5 * np.pi, 4.5 * np.pi, 21.0
S0, S1 = spiral_length(T0), spiral_length(T1)


def swiss_roll(seed, n=100_000):
    """(t cos t, h, t sin t), t in [1.5 pi, 4.5 pi], h in [0, 21], uniform in arc length and h,
    so uniform on the surface."""
    rng = np.random.default_rng(seed)
    s = rng.uniform(S0, S1, n)
    h = rng.uniform(0, HEIGHT, n)
    t = T0 + (s - S0) / (S1 - S0) * (T1 - T0)
    for _ in range(30):  # Newton on spiral_length(t) = s; ds/dt = sqrt(1 + t^2)
        t -= (spiral_length(t) - s) / np.sqrt(1 + t * t)
    return np.c_[t * np.cos(t), h, t * np.sin(t)]


def swiss_roll_rho(Y):
    """rho in the unrolled (s, h) rectangle, isometric to the roll and convex: the geodesic
    distance is the distance there."""
    radius = np.hypot(Y[:, 0], Y[:, 2])
    angle = np.mod(np.arctan2(Y[:, 2], Y[:, 0]), TAU)
    turns = np.round((radius - angle) / TAU)
    flat = np.c_[spiral_length(angle + turns * TAU), Y[:, 1]]
    D = np.sqrt(((flat[:, None] - flat[None]) ** 2).sum(-1))
    return rho(min_pair(D), len(Y), 2, (S1 - S0) * HEIGHT)


def three_sphere(seed, n=400_000):
    """Uniform on S^3 in R^4 (normalized Gaussian vectors), volume 2 pi^2."""
    v = np.random.default_rng(seed).standard_normal((n, 4))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def three_sphere_rho(Y):
    D = np.arccos(np.clip(Y @ Y.T, -1, 1))
    return rho(min_pair(D), len(Y), 3, 2 * np.pi**2)


def sphere_with_normals(seed, n=20_000):
    """n points on the unit sphere in R^3 and their outward normals (the same vectors)."""
    v = np.random.default_rng(seed).standard_normal((n, 3))
    X = v / np.linalg.norm(v, axis=1, keepdims=True)
    return X, X.copy()


def unit_rows(Y):
    """The sphere's projection: each row divided by its norm."""
    return Y / np.linalg.norm(Y, axis=1, keepdims=True)


def sample_and_resample(X, count, seed, **resample_options):
    """`count` samples of X by the linear scan, then resampled, both with `seed`: the samples
    before and after, and the two reports."""
    indices, picked = sr.sample(X, count=count, seed=seed, return_report=True)
    assert picked["reached"], picked["search"]
    Y, moved = sr.resample(
        X, indices, sigma_p=picked["sigma_p"], seed=seed, return_report=True, **resample_options
    )
    return X[indices], Y, picked, moved


# --- The manifolds -----------------------------------------------------------------------------


@pytest.mark.parametrize("seed", [1, 2, 3, 4, 5])
def test_a_circle_in_r2_is_sampled_evenly(seed):
    X = circle(seed)
    scanned, Y, picked, moved = sample_and_resample(X, 200, seed)
    assert picked["dim"] == 1 and moved["dim"] == 1
    assert abs(len(Y) - 200) <= 1
    assert np.abs(np.hypot(Y[:, 0], Y[:, 1]) - 1).max() < 1e-6
    before, after = gap_ratio(scanned), gap_ratio(Y)
    print(f"circle seed {seed}: gap ratio {before:.3f} after the scan, {after:.3f} resampled")
    assert after <= 1.5


@pytest.mark.parametrize("seed", [1, 2, 3, 4, 5])
def test_a_clifford_torus_in_r4_gets_blue_noise(seed):
    scanned, Y, picked, moved = sample_and_resample(clifford_torus(seed), 1000, seed)
    assert picked["dim"] == 2 and moved["dim"] == 2
    before, after = torus_rho(scanned), torus_rho(Y)
    print(f"Clifford torus seed {seed}: rho {before:.3f} after the scan, {after:.3f} resampled")
    assert after >= 0.7


@pytest.mark.parametrize("seed", [1, 2, 3, 4, 5])
def test_a_swiss_roll_in_r3_gets_blue_noise(seed):
    scanned, Y, picked, moved = sample_and_resample(swiss_roll(seed), 1000, seed)
    assert picked["dim"] == 2 and moved["dim"] == 2
    before, after = swiss_roll_rho(scanned), swiss_roll_rho(Y)
    print(f"Swiss roll seed {seed}: rho {before:.3f} after the scan, {after:.3f} resampled")
    assert after >= 0.7


@pytest.mark.parametrize("seed", [1, 2])
def test_a_three_sphere_in_r4_gets_blue_noise(seed):
    scanned, Y, picked, moved = sample_and_resample(three_sphere(seed), 1000, seed)
    assert picked["dim"] == 3 and moved["dim"] == 3
    assert np.abs(np.linalg.norm(Y, axis=1) - 1).max() < 1e-4
    before, after = three_sphere_rho(scanned), three_sphere_rho(Y)
    print(f"3-sphere seed {seed}: rho {before:.3f} after the scan, {after:.3f} resampled")
    assert after >= 0.7


def test_the_reports():
    X = circle(1, 20_000)
    indices, picked = sr.sample(X, count=100, return_report=True)
    assert set(picked) == {
        "sigma_p", "sigma_n", "dim", "reached", "search", "count", "rejected_by_nearest",
        "measured",
    }
    assert indices.dtype == np.int64 and indices.shape == (picked["count"],)
    assert (np.diff(indices) > 0).all() and indices[0] >= 0 and indices[-1] < len(X)
    assert picked["sigma_n"] is None and picked["dim"] == 1 and picked["reached"] is True
    assert all(isinstance(s, float) and isinstance(c, int) for s, c in picked["search"])
    assert picked["search"][-1] == (picked["sigma_p"], picked["count"])
    assert picked["rejected_by_nearest"] + picked["measured"] <= len(X)
    # With sigma_p: one scan, no dimension needed.
    same, given = sr.sample(X, sigma_p=picked["sigma_p"], return_report=True)
    assert np.array_equal(same, indices)
    assert given["dim"] is None and given["search"] == [(picked["sigma_p"], len(indices))]
    Y, moved = sr.resample(X, indices, sigma_p=picked["sigma_p"], iterations=3, return_report=True)
    assert set(moved) == {
        "sigma_p", "sigma_n", "iterations", "dim", "mean_move", "mean_s", "min_s",
    }
    assert moved["iterations"] == 3 and moved["dim"] == 1 and moved["sigma_n"] is None
    assert len(moved["mean_move"]) == len(moved["mean_s"]) == len(moved["min_s"]) == 3
    assert Y.dtype == np.float64 and Y.shape == (len(indices), 2) and Y.flags.c_contiguous
    # No sweep: the samples as they are.
    assert np.array_equal(sr.resample(X, indices, sigma_p=picked["sigma_p"], iterations=0), X[indices])
    # The dimension given is the one used.
    _, given = sr.sample(X, count=100, dim=2, return_report=True)
    assert given["dim"] == 2


def test_normals_with_a_finite_sigma_n():
    X, N = sphere_with_normals(1)
    indices, picked = sr.sample(X, N, count=400, sigma_n=0.8, return_report=True)
    assert picked["sigma_n"] == 0.8 and picked["dim"] == 2
    Y, N2, moved = sr.resample(
        X, indices, N, sigma_p=picked["sigma_p"], sigma_n=0.8, return_report=True
    )
    assert moved["sigma_n"] == 0.8
    assert Y.shape == N2.shape == (len(indices), 3)
    assert np.abs(np.linalg.norm(N2, axis=1) - 1).max() < 1e-12
    # On the sphere (the projection onto the points) with the normals of the nearest points.
    assert np.abs(np.linalg.norm(Y, axis=1) - 1).max() < 1e-3
    assert (np.sum(Y * N2, axis=1) > 0.99).all()
    # The same seed, the same arrays; the normals change the samples.
    again = sr.sample(X, N, count=400, sigma_n=0.8)
    assert np.array_equal(again, indices)
    Y3, N3 = sr.resample(X, indices, N, sigma_p=picked["sigma_p"], sigma_n=0.8)
    assert np.array_equal(Y3, Y) and np.array_equal(N3, N2)
    assert not np.array_equal(sr.sample(X, count=400), indices)
    # Normals without sigma_n are carried along: (Y, N) still.
    Y4, N4 = sr.resample(X, indices, N, sigma_p=picked["sigma_p"], iterations=2)
    assert Y4.shape == N4.shape == (len(indices), 3)


def test_the_same_seed_gives_the_same_bytes():
    X = clifford_torus(7, 20_000)
    a = sr.sample(X, count=300, seed=3)
    b = sr.sample(X, count=300, seed=3)
    c = sr.sample(X, count=300, seed=4)
    assert a.tobytes() == b.tobytes()
    assert a.shape != c.shape or a.tobytes() != c.tobytes()
    sigma_p = sr.sample(X, count=300, seed=3, return_report=True)[1]["sigma_p"]
    Ya = sr.resample(X, a, sigma_p=sigma_p, seed=3)
    Yb = sr.resample(X, a, sigma_p=sigma_p, seed=3)
    Yc = sr.resample(X, a, sigma_p=sigma_p, seed=4)
    assert Ya.tobytes() == Yb.tobytes()
    assert Ya.tobytes() != Yc.tobytes()


def test_other_dimensions_of_the_space():
    rng = np.random.default_rng(5)
    # A segment in R^1: the projection keeps points as they are (m = d).
    X = rng.uniform(0, 1, (5000, 1))
    indices, picked = sr.sample(X, count=50, return_report=True)
    Y = sr.resample(X, indices, sigma_p=picked["sigma_p"])
    assert picked["dim"] == 1 and Y.shape == (len(indices), 1)
    assert (Y >= -0.1).all() and (Y <= 1.1).all()
    # A plane in R^16.
    basis = np.linalg.qr(rng.standard_normal((16, 2)))[0]
    X = rng.uniform(-1, 1, (5000, 2)) @ basis.T
    indices, picked = sr.sample(X, count=100, return_report=True)
    Y, moved = sr.resample(X, indices, sigma_p=picked["sigma_p"], return_report=True)
    assert picked["dim"] == 2 and moved["dim"] == 2 and Y.shape == (len(indices), 16)
    # Still in the plane.
    assert np.abs(Y - (Y @ basis) @ basis.T).max() < 1e-9
    # Normals with a finite sigma_n up to R^8.
    X = rng.standard_normal((2000, 8))
    assert len(sr.sample(X, X, sigma_p=1.0, sigma_n=1.0)) > 0


# --- A callable projection ---------------------------------------------------------------------


def test_a_callable_projection():
    X, N = sphere_with_normals(2, 5000)
    indices, picked = sr.sample(X, count=200, return_report=True)
    calls = []

    def project(Y):
        calls.append(Y.shape)
        assert Y.dtype == np.float64 and Y.ndim == 2 and Y.shape[1] == 3
        return unit_rows(Y)

    Y, moved = sr.resample(
        X, indices, sigma_p=picked["sigma_p"], project=project, return_report=True
    )
    assert calls and sum(m for m, _ in calls) == 10 * len(indices)
    assert moved["dim"] is None
    assert np.abs(np.linalg.norm(Y, axis=1) - 1).max() < 1e-12
    # A list of lists, float32 or a transposed view are read as arrays.
    for convert in (lambda a: a.tolist(), lambda a: a.astype(np.float32), lambda a: a.T.copy().T):
        Y2 = sr.resample(
            X, indices, sigma_p=picked["sigma_p"], iterations=2,
            project=lambda Y: convert(unit_rows(Y)),
        )
        assert np.abs(np.linalg.norm(Y2, axis=1) - 1).max() < 1e-6
    # With normals: a pair (Y2, N2), the normals normalized.
    Y3, N3 = sr.resample(
        X, indices, N, sigma_p=picked["sigma_p"], project=lambda Y: (unit_rows(Y), 2 * Y)
    )
    assert np.abs(np.linalg.norm(Y3, axis=1) - 1).max() < 1e-12
    assert np.abs(N3 - Y3).max() < 1e-12
    # The same seed, the same bytes.
    again = sr.resample(X, indices, sigma_p=picked["sigma_p"], project=unit_rows)
    assert again.tobytes() == sr.resample(X, indices, sigma_p=picked["sigma_p"], project=unit_rows).tobytes()


class ProjectionFailed(Exception):
    pass


def test_an_exception_in_the_callable_reaches_the_caller_unchanged():
    X = circle(3, 5000)
    indices = sr.sample(X, sigma_p=0.1)
    calls, raised = [], []

    def project(Y):
        calls.append(len(Y))
        if len(calls) == 3:  # the third call fails
            raised.append(ProjectionFailed("no manifold here", 42))
            raise raised[0]
        return Y

    with pytest.raises(ProjectionFailed) as info:
        sr.resample(X, indices, sigma_p=0.1, project=project)
    # The very exception object, and no call after it.
    assert info.value is raised[0] and len(calls) == 3
    assert info.value.args == ("no manifold here", 42)

    # A KeyboardInterrupt or a KeyError alike.
    def interrupt(Y):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sr.resample(X, indices, sigma_p=0.1, project=interrupt)
    with pytest.raises(KeyError, match="'k'"):
        sr.resample(X, indices, sigma_p=0.1, project=lambda Y: {}["k"])
    # The module still works afterwards.
    assert sr.resample(X, indices, sigma_p=0.1, iterations=1).shape == (len(indices), 2)


@pytest.mark.parametrize(
    "project, normals, error, pattern",
    [
        (lambda Y: Y[:-1], False, ValueError,
         r"project\(Y\) must have the shape of Y, \(\d+, 2\), got shape \(\d+, 2\)"),
        (lambda Y: Y.ravel(), False, ValueError, r"project\(Y\) must have the shape of Y, \(\d+, 2\), got shape \(\d+,\)"),
        (lambda Y: Y[:, :1], False, ValueError, r"got shape \(\d+, 1\)"),
        (lambda Y: None, False, ValueError, r"project\(Y\) must have the shape of Y, \(\d+, 2\), got shape \(\)"),
        (lambda Y: [["a", "b"]] * len(Y), False, ValueError, r"project\(Y\) must be an array of float64 of shape \(\d+, 2\), and numpy cannot read it"),
        (lambda Y: Y * np.nan, False, ValueError, r"invalid parameter project: the projection gave sample \d+ a coordinate that is not finite"),
        (lambda Y: Y, True, ValueError, r"project must return a pair \(Y2, N2\) of arrays of shape \(\d+, 2\) when normals are given, got ndarray"),
        (lambda Y: (Y, Y[:, :1]), True, ValueError, r"project\(Y\)\[1\] must have the shape of Y"),
        (lambda Y: (Y, 0 * Y), True, ValueError, r"invalid parameter project: the projection gave sample \d+ a normal with no direction"),
        (3, False, TypeError, r"project must be a callable project\(Y\) -> Y2, or None, got int"),
    ],
)
def test_a_callable_projection_answering_wrong(project, normals, error, pattern):
    X = circle(4, 3000)
    indices = sr.sample(X, sigma_p=0.2)
    with pytest.raises(error, match=pattern):
        sr.resample(X, indices, X if normals else None, sigma_p=0.2, project=project)


# --- Arrays and options ------------------------------------------------------------------------


def test_non_contiguous_arrays_are_read_alike():
    X = clifford_torus(9, 10_000)
    for view in (X[:, ::-1], X.T.copy().T, X[::2], np.asfortranarray(X)[::-1]):
        copy = np.ascontiguousarray(view)
        assert np.array_equal(view, copy)
        a, report = sr.sample(view, count=200, return_report=True)
        b = sr.sample(copy, count=200)
        assert a.tobytes() == b.tobytes()
        Ya = sr.resample(view, a[::-1], sigma_p=report["sigma_p"], iterations=2)
        Yb = sr.resample(copy, a[::-1].copy(), sigma_p=report["sigma_p"], iterations=2)
        assert Ya.tobytes() == Yb.tobytes()
    # Other dtypes and lists: converted to float64; indices of any integer dtype.
    Xi = np.round(X * 100).astype(np.int32)
    a = sr.sample(Xi, count=100)
    assert a.tobytes() == sr.sample(Xi.astype(np.float64), count=100).tobytes()
    assert a.tobytes() == sr.sample(Xi.tolist(), count=100).tobytes()
    for idx in (a.astype(np.uint64), a.astype(np.int32), a.astype(np.uint16), a.tolist()):
        Y = sr.resample(Xi, idx, sigma_p=10.0, iterations=1)
        assert Y.tobytes() == sr.resample(Xi, a, sigma_p=10.0, iterations=1).tobytes()


def bad_normals(n, d):
    N = np.ones((n, d))
    N[4] = 0
    return N


@pytest.mark.parametrize(
    "X, normals, options, pattern",
    [
        (np.zeros(12), None, {}, r"X must be an array of shape \(n, d\): n >= 1 points of 1 to 16 coordinates, got shape \(12,\)"),
        (np.zeros((5, 0)), None, {}, r"got shape \(5, 0\)"),
        (np.zeros((5, 17)), None, {}, r"got shape \(5, 17\)"),
        (np.zeros((0, 3)), None, {}, r"got shape \(0, 3\)"),
        (np.zeros((2, 3, 4)), None, {}, r"got shape \(2, 3, 4\)"),
        (np.array([["a", "b"]]), None, {}, r"X must hold real numbers \(a float or integer dtype\), got dtype <U1"),
        (np.ones((5, 2), dtype=complex), None, {}, r"X must hold real numbers"),
        (np.where(np.arange(20).reshape(10, 2) == 7, np.nan, 1.0), None, {}, r"invalid parameter X: point 3 has a coordinate that is not finite"),
        (np.where(np.arange(20).reshape(10, 2) == 18, np.inf, 1.0), None, {}, r"point 9 has a coordinate that is not finite"),
        (np.ones((10, 2)), np.ones((10, 3)), {}, r"normals must be an array of the shape of X, \(10, 2\), got shape \(10, 3\)"),
        (np.ones((10, 2)), np.ones(20), {}, r"normals must be an array of the shape of X, \(10, 2\), got shape \(20,\)"),
        (np.ones((10, 2)), bad_normals(10, 2), {}, r"invalid parameter normals: normal 4 has no direction"),
        (np.ones((10, 2)), None, {"count": 5, "sigma_p": 1.0}, r"invalid parameter count: give sigma_p or count, not both"),
        (np.ones((10, 2)), None, {"count": None}, r"invalid parameter count: give sigma_p or count"),
        (np.ones((10, 2)), None, {"count": 0}, r"invalid parameter count: must be from 1 to the 10 points, got 0"),
        (np.ones((10, 2)), None, {"count": 11}, r"must be from 1 to the 10 points, got 11"),
        (np.ones((10, 2)), None, {"count": -5}, r"must be from 1 to the 10 points, got -5"),
        (np.ones((10, 2)), None, {"sigma_p": -1.0}, r"invalid parameter sigma_p: must be a positive number, got -1"),
        (np.ones((10, 2)), None, {"sigma_p": float("nan")}, r"invalid parameter sigma_p"),
        (np.ones((10, 2)), None, {"sigma_p": float("inf")}, r"invalid parameter sigma_p"),
        (np.ones((10, 2)), None, {"count": 5, "sigma_n": 0.0}, r"invalid parameter sigma_n: must be positive"),
        (np.ones((10, 2)), None, {"count": 5, "sigma_n": 0.8}, r"invalid parameter sigma_n: a finite normal width needs normals"),
        (np.ones((10, 9)), np.ones((10, 9)), {"count": 5, "sigma_n": 0.8}, r"invalid parameter sigma_n: a finite normal width in 9 dimensions"),
        (np.ones((10, 2)), None, {"count": 5, "epsilon": 1.0}, r"invalid parameter epsilon: must be in \(0, 1\)"),
        (np.ones((10, 2)), None, {"count": 5, "dim": 3}, r"invalid parameter dim: the manifold's dimension must be from 1 to the space's 2, got 3"),
        (np.ones((10, 2)), None, {"count": 5, "dim": -1}, r"invalid parameter dim: .* got -1"),
        (np.ones((10, 2)), None, {"count": 5, "seed": -1}, r"invalid parameter seed: must be an integer from 0 to 2\^64 - 1, got -1"),
    ],
)
def test_sample_refuses_bad_input(X, normals, options, pattern):
    options = {"sigma_p": 1.0, **options} if "count" not in options else options
    with pytest.raises(ValueError, match=pattern):
        sr.sample(X, normals, **options)


@pytest.mark.parametrize(
    "indices, options, pattern",
    [
        ([0, 10], {}, r"indices\[1\] = 10 is not a point index: the points of X are numbered 0 to 9 \(0-based\)"),
        ([-1], {}, r"indices\[0\] = -1 is not a point index"),
        (np.array([3, 2**63], dtype=np.uint64), {}, r"indices\[1\] = 9223372036854775808 is not a point index"),
        ([3, 5, 3], {}, r"indices\[2\] = 3 repeats indices\[0\]: each sample must be a different point"),
        (np.array([1.0, 2.0]), {}, r"indices must hold point indices \(an integer dtype\), got dtype float64"),
        (np.array([True, False]), {}, r"indices must hold point indices"),
        ([[1, 2]], {}, r"indices must be an array of shape \(k,\), got shape \(1, 2\)"),
        (3, {}, r"indices must be an array of shape \(k,\), got shape \(\)"),
        ([], {}, r"indices must name at least one point, got shape \(0,\)"),
        ([1, 2], {"iterations": -1}, r"invalid parameter iterations: must be an integer >= 0, got -1"),
        ([1, 2], {"sigma_p": 0.0}, r"invalid parameter sigma_p"),
        ([1, 2], {"sigma_n": 0.5}, r"invalid parameter sigma_n: a finite normal width needs normals"),
        ([1, 2], {"dim": 0}, r"invalid parameter dim: the manifold's dimension must be from 1"),
        ([1, 2], {"dim": 1, "project": unit_rows}, r"invalid parameter dim: .* give dim or project, not both"),
        ([1, 2], {"seed": 2**64}, r"invalid parameter seed"),
    ],
)
def test_resample_refuses_bad_input(indices, options, pattern):
    X = circle(1, 10)
    with pytest.raises(ValueError, match=pattern):
        sr.resample(X, indices, **{"sigma_p": 0.5, **options})


def test_resample_refuses_bad_points_as_sample_does():
    X = np.where(np.arange(20).reshape(10, 2) == 7, np.nan, 1.0)
    with pytest.raises(ValueError, match=r"invalid parameter X: point 3 has a coordinate that is not finite"):
        sr.resample(X, [0, 1], sigma_p=0.5)
    with pytest.raises(ValueError, match=r"X must be an array of shape \(n, d\).*got shape \(5, 17\)"):
        sr.resample(np.zeros((5, 17)), [0, 1], sigma_p=0.5)
    with pytest.raises(ValueError, match=r"normals must be an array of the shape of X"):
        sr.resample(np.ones((10, 2)), [0, 1], np.ones((9, 2)), sigma_p=0.5)


def test_wrong_arguments_raise_type_error():
    X = circle(1, 100)
    with pytest.raises(TypeError):
        sr.sample(X, count=5, sigma=1.0)
    with pytest.raises(TypeError):
        sr.sample(X, None, 1.0)  # sigma_p is keyword-only
    with pytest.raises(TypeError):
        sr.resample(X, [0, 1])  # sigma_p is required
    with pytest.raises(TypeError):
        sr.sample(X, count="100")


def test_gil_is_released(gil_released):
    """Another Python thread runs while sample and resample work."""
    X = clifford_torus(11)

    def work():
        indices, report = sr.sample(X, count=3000, return_report=True)
        sr.resample(X, indices, sigma_p=report["sigma_p"])

    gil_released(work)


def test_a_count_coincident_rows_cannot_reach_is_said():
    # 10 distinct points, each row 100 times: 10 samples at most, and a warning saying why.
    P = circle(1, n=10)
    X = np.repeat(P, 100, axis=0)
    with pytest.warns(UserWarning, match=r"count=50 not reached: \d+ samples \(X has 10 distinct rows of 1000"):
        picked = sr.sample(X, count=50)
    assert len(np.unique(X[picked], axis=0)) == len(picked) <= 10
