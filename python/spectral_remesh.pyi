"""Spectral sampling and remeshing of triangle meshes (Öztireli, Alexa, Gross 2010: Spectral
Sampling of Manifolds), numpy in, numpy out.

Arrays in: anything ``numpy.asarray`` reads. Positions of any real dtype are converted to
float64; face indices of any integer dtype are checked against the vertex count (a float
array of indices is refused); non-contiguous arrays (slices, transposes, negative strides) are
read through their strides, never refused. Errors carry the library's one-line message:
ValueError for input or options that cannot be used, OSError for files the operating system
refuses, RuntimeError for an internal failure (a bug) or a strict refusal. The GIL is released
while the library works.
"""

from os import PathLike
from typing import Any, Dict, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

def read(
    path: Union[str, "PathLike[str]"], /
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Read a mesh file through the library's readers, as `remesh` reads its input.

    Parameters
    ----------
    path : str or os.PathLike
        A mesh file: .obj, .ply (ascii or binary), .gltf or .glb, .stl or .off, told by its
        extension.

    Returns
    -------
    V : numpy.ndarray of float64, shape (n, 3)
        Vertex positions in the file's own (model) units.
    F : numpy.ndarray of int64, shape (m, 3)
        Triangles as 0-based indices into V. Polygons are triangulated, vertices at identical
        positions welded and vertices no triangle uses removed, as for `remesh`.

    Raises
    ------
    OSError
        The file cannot be opened or read (FileNotFoundError, PermissionError or
        IsADirectoryError where that is the cause).
    ValueError
        The extension names no mesh format, the content does not parse, or the mesh cannot be
        used (no triangles, an index out of range, a non-finite coordinate).
    """
    ...

def quality(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    ref: Optional[Tuple[npt.ArrayLike, npt.ArrayLike]] = None,
    seed: int = 1,
) -> Dict[str, Any]:
    """The quality report of a triangle mesh, as `remesh quality --json` gives it.

    The mesh (and the reference) get the reader's checks and clean-up first (vertices at
    identical positions welded, vertices no triangle uses removed), so the report equals the
    command line's for files holding the same arrays, but for the stage times.

    Parameters
    ----------
    V : array_like, shape (n, 3)
        Vertex positions, any real dtype (converted to float64), in model units.
    F : array_like, shape (m, 3)
        Triangles as 0-based indices into V, any integer dtype.
    ref : tuple (V0, F0) or None
        A reference surface (usually a remesher's input) as two such arrays. It sets the
        bbox-100 frame of every length, and the report gains the distance between the two.
    seed : int
        Seed of the distance's random points.

    Returns
    -------
    dict
        The JSON report as `json.loads` reads it: `triangles` (Table 1: `theta_min`,
        `theta_min_ave`, `theta_max` in degrees, `q_min`, `q_ave`, `pct_theta_below_30` in
        percent of the triangles, `p30` in percent of the angles, `faces_measured`), `topology`,
        `self_intersections`, `invariant_violations`, `distance` (None without `ref`;
        `hausdorff`, `rms`, `mean` and the one-sided values in bbox-100 units, the reference
        scaled so its bounding box's longest side is 100), `input_topology` (the reference's),
        `topology_changes`, `stages` (wall and processor seconds), `notes`, `extra`.

    Raises
    ------
    ValueError
        An array of the wrong shape or dtype, a non-finite coordinate, an index out of range,
        no triangles, or a mesh without area.
    """
    ...

def remesh(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    *,
    points: Optional[int] = None,
    sigma_p: Optional[float] = None,
    sigma_n: Optional[float] = None,
    seed: int = 1,
    iterations: Optional[int] = None,
    lfs_factor: Optional[float] = None,
    chord_error: Optional[float] = None,
    fit: bool = True,
    smooth: Optional[int] = None,
    min_angle: Optional[float] = None,
    max_angle: Optional[float] = None,
    feature_angle: Optional[float] = None,
    features: bool = True,
    triangulation: Optional[str] = None,
    distance: bool = True,
    strict: bool = False,
    max_memory: Union[int, str, None] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], Dict[str, Any]]:
    """Remesh a triangle mesh by spectral sampling, as the `remesh` command line does.

    The same arrays and options give the same output, bit for bit, as `remesh IN OUT` on a file
    holding the arrays (`remesh` writes .ply, .obj and .off exactly). Each option is the command
    line's flag of that name; None takes the command line's default. Lengths are in bbox-100
    units: the input scaled so its bounding box's longest side is 100. The GIL is released
    during the work.

    Parameters
    ----------
    V : array_like, shape (n, 3)
        Vertex positions, any real dtype (converted to float64), in model units.
    F : array_like, shape (m, 3)
        Triangles as 0-based indices into V, any integer dtype. Vertices at identical positions
        are welded and vertices no triangle uses removed first, as the reader does.
    points : int or None
        About this many output vertices (within 1%); sigma_p is searched for. 4 to 20 million.
        With neither points nor sigma_p: as many as the input has vertices.
    sigma_p : float or None
        The kernel width in bbox-100 units, instead of points.
    sigma_n : float or None
        The normal width; finite values give feature-adaptive sampling. None: infinity.
    seed : int
        Seed of every random choice.
    iterations : int or None
        Gradient-ascent sweeps (10).
    lfs_factor : float or None
        Thin parts: the kernel width follows the local thickness (0: off, the default; 0.75 is
        the measured setting).
    chord_error : float or None
        Curved parts: the spacing follows the curvature (0: off, the default; 0.003 for CAD
        parts).
    fit : bool
        The least-squares vertex placement (True, the default; False is `--no-fit`).
    smooth : int or None
        Iterations of the finishing relaxation (10).
    min_angle, max_angle : float or None
        The angle bounds in degrees the last optimization pass works towards (35, 100).
    feature_angle : float or None
        Keep every crease found at this angle in degrees (0 to 180). None: automatic at 20°.
    features : bool
        False: no crease detection (`--no-features`; not with feature_angle).
    triangulation : str or None
        "restricted" (restricted Delaunay, the default) or "umbrellas".
    distance : bool
        Measure the Hausdorff and RMS distance to the input (False is `--no-distance`).
    strict : bool
        Raise RuntimeError instead of returning an output that breaks an invariant or whose
        topology differs from the input's.
    max_memory : int, str or None
        The most memory the job may take, in bytes or as a size ("512M", "8G", "2GiB"); a job
        whose estimated peak is larger is refused at once. None: the machine's physical memory.

    Returns
    -------
    V : numpy.ndarray of float64, shape (k, 3)
        The output's vertex positions, in the input's units.
    F : numpy.ndarray of int64, shape (l, 3)
        The output's triangles, 0-based indices into V, oriented consistently (closed parts
        outward).
    report : dict
        The JSON report of `remesh --report` as `json.loads` reads it (see `quality`), with the
        input's topology, and in `extra` sigma_p, the sigma_p search, the seed and the stages'
        statistics.

    Raises
    ------
    ValueError
        An array of the wrong shape or dtype, a non-finite coordinate, an index out of range,
        no triangles, an option out of its range or two that exclude each other (named as the
        command line names it), or a job over max_memory.
    RuntimeError
        With strict=True, an output that breaks an invariant or changes the topology; or an
        internal failure.
    """
    ...
