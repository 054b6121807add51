"""Spectral sampling of point sets near manifolds of other dimensions: a circle in R^2 and a
Clifford torus in R^4, each subsampled by `sample` (the linear scan) and moved into blue noise
by `resample` (gradient ascent, projected onto the point set itself).

    pip install ./python
    python python/examples/sample_manifolds.py

Prints the circle's gap ratio (the largest angular gap between consecutive samples over the
smallest; 1 is perfectly even) and the torus's normalized Poisson-disk radius rho (the smallest
geodesic distance between two samples over that of the densest packing; blue noise is above
0.7), each after the scan and after the resampling.
"""

import numpy as np

import spectral_remesh as sr

TAU = 2 * np.pi
rng = np.random.default_rng(1)


def gap_ratio(Y):
    angles = np.sort(np.arctan2(Y[:, 1], Y[:, 0]))
    gaps = np.diff(np.r_[angles, angles[0] + TAU])
    return gaps.max() / gaps.min()


# 100k points on the unit circle, 200 samples.
t = rng.uniform(0, TAU, 100_000)
X = np.c_[np.cos(t), np.sin(t)]
indices, report = sr.sample(X, count=200, return_report=True)
Y = sr.resample(X, indices, sigma_p=report["sigma_p"])
print(
    f"circle in R^2: {len(Y)} samples (manifold dimension {report['dim']}), sigma_p "
    f"{report['sigma_p']:.4f}; gap ratio {gap_ratio(X[indices]):.2f} after the scan, "
    f"{gap_ratio(Y):.2f} resampled"
)


def torus_rho(Y):
    """rho on the Clifford torus (flat, area 2 pi^2): geodesic distances from the two angles."""
    r = np.sqrt(0.5)
    a, b = np.arctan2(Y[:, 1], Y[:, 0]), np.arctan2(Y[:, 3], Y[:, 2])
    wrap = lambda d: np.minimum(np.mod(d, TAU), TAU - np.mod(d, TAU))  # noqa: E731
    D = r * np.hypot(wrap(a[:, None] - a), wrap(b[:, None] - b))
    np.fill_diagonal(D, np.inf)
    d_max = np.sqrt(2 * (2 * np.pi**2) / (np.sqrt(3) * len(Y)))
    return D.min() / d_max


# 100k points on (cos a, sin a, cos b, sin b) / sqrt(2) in R^4, 1000 samples.
a, b = rng.uniform(0, TAU, (2, 100_000))
X = np.sqrt(0.5) * np.c_[np.cos(a), np.sin(a), np.cos(b), np.sin(b)]
indices, report = sr.sample(X, count=1000, return_report=True)
Y, moved = sr.resample(X, indices, sigma_p=report["sigma_p"], return_report=True)
print(
    f"Clifford torus in R^4: {len(Y)} samples (manifold dimension {moved['dim']}), sigma_p "
    f"{report['sigma_p']:.4f}; rho {torus_rho(X[indices]):.3f} after the scan, "
    f"{torus_rho(Y):.3f} resampled"
)
