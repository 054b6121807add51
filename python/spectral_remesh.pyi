"""Spectral sampling of manifolds (Öztireli, Alexa, Gross 2010): remeshing of triangle meshes,
and sampling of point sets near a manifold of any dimension in R^d, numpy in, numpy out.

Triangle meshes: `read`, `write`, `remesh` and `quality`, as the `remesh` command line does
them (`remesh` also meshes a point set of R^3 given without faces).
Point sets of shape (n, d), d from 1 to 16 (a curve in the plane, a surface in R^3 or R^4, a
3-manifold in R^4, ...): `sample` chooses an even subset of the points, `resample` moves the
samples into blue noise on the manifold.

Arrays in: anything ``numpy.asarray`` reads. Positions of any real dtype are converted to
float64; face and sample indices of any integer dtype are checked against the vertex or point
count (a float array of indices is refused); non-contiguous arrays (slices, transposes,
negative strides) are read through their strides, never refused. Errors carry the library's
one-line message: ValueError for input or options that cannot be used, OSError for files the
operating system refuses, RuntimeError for an internal failure (a bug) or a strict refusal.
The GIL is released while the library works (but for the calls of a Python `project`)."""

from os import PathLike
from typing import Any, Callable, Dict, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

# What `resample`'s `project` takes: Y (m, d) -> Y2 (m, d), or with normals -> (Y2, N2).
_ProjectPoints = Callable[[npt.NDArray[np.float64]], npt.ArrayLike]
_ProjectPointsAndNormals = Callable[
    [npt.NDArray[np.float64]], Tuple[npt.ArrayLike, npt.ArrayLike]
]

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

def read_points(
    path: Union[str, "PathLike[str]"], /
) -> Tuple[npt.NDArray[np.float64], Optional[npt.NDArray[np.float64]]]:
    """Read a point set through the library's point readers, as `remesh` reads a scan.

    Parameters
    ----------
    path : str or os.PathLike
        A point-set file: .ply (vertices, no faces), .pcd (ascii, binary or binary_compressed),
        .las or .laz, .e57 (every scan posed into the file's frame), or .xyz / .csv / .txt text,
        told by its extension; a file's header sizes are checked against the file before
        anything is allocated.

    Returns
    -------
    P : numpy.ndarray of float64, shape (n, 3)
        The points with finite coordinates, in the file's own units and order.
    N : numpy.ndarray of float64, shape (n, 3), or None
        Their unit normals (zero where the file's are missing) when the file has normals.

    Raises
    ------
    OSError
        The file cannot be opened or read (FileNotFoundError, PermissionError or
        IsADirectoryError where that is the cause).
    ValueError
        The extension names no point-set format, or the content does not parse or promises more
        than the file holds.
    """
    ...

def write(
    path: Union[str, "PathLike[str]"],
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    /,
) -> None:
    """Write a triangle mesh to a file through the library's writers, as `remesh` writes its output.

    The format is the extension's: .obj and .off (coordinates in the shortest text that reads
    back to the same float64), .ply (binary, coordinates as double), .glb and .gltf (glTF 2.0),
    .stl (binary). The file is written atomically: to a temporary file beside it, then renamed
    into place, so a failure leaves nothing at the path (an existing file stays as it was).

    Parameters
    ----------
    path : str or os.PathLike
        The file to write.
    V : array_like, shape (n, 3)
        Vertex positions, any real dtype (converted to float64), in model units.
    F : array_like, shape (m, 3)
        Triangles as 0-based indices into V, any integer dtype.

    Raises
    ------
    ValueError
        An array of the wrong shape or dtype, a non-finite coordinate (naming the vertex), an
        index out of range, or an extension that names no mesh format.
    OSError
        The file cannot be written (missing folder, no permission, disk full).
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
    F: Optional[npt.ArrayLike] = None,
    *,
    normals: Optional[npt.ArrayLike] = None,
    viewpoint: Optional[Sequence[float]] = None,
    points: Optional[int] = None,
    sigma_p: Optional[float] = None,
    edge_length: Optional[float] = None,
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
    progress: Optional[Callable[[str], Any]] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], Dict[str, Any]]:
    """Remesh a triangle mesh, or mesh a point set, by spectral sampling, as the `remesh` command
    line does.

    The same arrays and options give the same output, bit for bit, as `remesh IN OUT` on a file
    holding the arrays (`remesh` writes .ply, .obj and .off exactly; a point set: a text file of
    `x y z [nx ny nz]` lines). Each option is the command line's flag of that name; None takes
    the command line's default. Lengths are in bbox-100 units: the input scaled so its bounding
    box's longest side is 100. The GIL is released during the work.

    Parameters
    ----------
    V : array_like, shape (n, 3)
        Vertex positions, any real dtype (converted to float64), in model units; with F None,
        the points of a point set (a scan), meshed through the RIMLS surface of the points as
        `remesh scan.xyz out.ply` does.
    F : array_like, shape (m, 3), or None
        Triangles as 0-based indices into V, any integer dtype. Vertices at identical positions
        are welded and vertices no triangle uses removed first, as the reader does. None: V is
        a point set (it then needs points or sigma_p; lfs_factor and chord_error are not
        available).
    normals : array_like, shape (n, 3), or None
        A point set's normals, one per point (any length but zero). None: estimated, and
        oriented outward (or towards viewpoint). Only with F None.
    viewpoint : sequence of 3 floats or None
        Orient a point set's estimated normals towards this point (a single scan's sensor, model
        units; `--viewpoint`). Only with F None and no normals.
    points : int or None
        About this many output vertices (within 1%); sigma_p is searched for. 4 to 20 million.
        With neither points nor sigma_p: as many as the input has vertices.
    sigma_p : float or None
        The kernel width in bbox-100 units, instead of points.
    edge_length : float or None
        Output edges about this long, in the input's own units, instead of points or sigma_p:
        for a mesh the count of equilateral triangles of that edge on the input's area, for a
        point set sigma_p = that length / 1.2 in bbox-100 units (its sampling's mean edge is
        1.2 sigma_p); the report's notes give it.
    sigma_n : float or None
        The normal width; finite values give feature-adaptive sampling. None: infinity.
    seed : int
        Seed of every random choice.
    iterations : int or None
        Gradient-ascent sweeps (10).
    lfs_factor : float or None
        ε of the sizing field (meshes): the spacing follows the local feature size,
        h = ε · lfs where that is below sigma_p, in absolute units, so walls, tubes, holes and
        gaps narrower than the spacing get the samples they need and the count may grow (at
        most 4 times; strict refuses). 2.5 is the bound of the topological ball property; 0,
        the default, turns it off.
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
        "restricted" (restricted Delaunay, the default; also "restricted-refined"),
        "restricted-clipped" (its cells clipped exactly from the input's facets) or "umbrellas".
    distance : bool
        Measure the Hausdorff and RMS distance to the input (False is `--no-distance`).
    strict : bool
        Raise RuntimeError instead of returning an output that breaks an invariant or whose
        topology differs from the input's.
    max_memory : int, str or None
        The most memory the job may take, in bytes or as a size ("512M", "8G", "2GiB"); a job
        whose estimated peak is larger is refused at once. None: the smallest of the machine's
        physical memory and the process's memory limits (cgroup, address space).
    progress : callable or None
        Called with each stage's name (str: "read", "linear scan", "gradient ascent",
        "triangulate", ...) as the stage starts, with the GIL taken for the call. An exception it
        raises stops further calls and is raised again, unchanged, when the job returns.

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
        no triangles (no points), a normal of length zero, normals or viewpoint with F given, an
        option out of its range or two that exclude each other (named as the command line names
        it), or a job over max_memory.
    RuntimeError
        With strict=True, an output that breaks an invariant or changes the topology; or an
        internal failure.
    """
    ...

@overload
def sample(
    X: npt.ArrayLike,
    normals: Optional[npt.ArrayLike] = None,
    *,
    sigma_p: Optional[float] = None,
    count: Optional[int] = None,
    sigma_n: Optional[float] = None,
    seed: int = 1,
    epsilon: float = 0.5,
    dim: Optional[int] = None,
    return_report: Literal[False] = False,
) -> npt.NDArray[np.int64]: ...
@overload
def sample(
    X: npt.ArrayLike,
    normals: Optional[npt.ArrayLike] = None,
    *,
    sigma_p: Optional[float] = None,
    count: Optional[int] = None,
    sigma_n: Optional[float] = None,
    seed: int = 1,
    epsilon: float = 0.5,
    dim: Optional[int] = None,
    return_report: Literal[True],
) -> Tuple[npt.NDArray[np.int64], Dict[str, Any]]: ...
@overload
def sample(
    X: npt.ArrayLike,
    normals: Optional[npt.ArrayLike] = None,
    *,
    sigma_p: Optional[float] = None,
    count: Optional[int] = None,
    sigma_n: Optional[float] = None,
    seed: int = 1,
    epsilon: float = 0.5,
    dim: Optional[int] = None,
    return_report: bool = False,
) -> Union[npt.NDArray[np.int64], Tuple[npt.NDArray[np.int64], Dict[str, Any]]]:
    """Choose samples of a point set near a manifold of any dimension, by the randomized linear
    scan (Algorithm 1 of the paper).

    The points are visited in a random order (seeded) and kept when the spectral measure of the
    Gaussian kernel exp(-|x - y|²), x = [p / sigma_p, n / sigma_n], over the points kept so far
    exceeds epsilon: an even (blue-noise) subset of the rows of X, about sigma_p apart, on
    curves, surfaces, volumes and higher-dimensional manifolds alike. With `count`, sigma_p is
    searched for (a few scans). Lengths are in X's own units (no rescaling). The GIL is released
    during the work.

    Parameters
    ----------
    X : array_like, shape (n, d)
        The points, any real dtype (converted to float64), n >= 1, d from 1 to 16.
    normals : array_like, shape (n, d), or None
        A direction per point (a hypersurface's normal, or any direction field the kernel should
        tell apart), normalized here; used with a finite sigma_n (then d at most 8).
    sigma_p : float or None
        The kernel width in X's units: samples end up about this far apart.
    count : int or None
        About this many samples (within 0.5% when the search reaches it: the report's
        `reached`), sigma_p searched for; 1 to n. Give exactly one of sigma_p and count.
    sigma_n : float or None
        The normal width (> 0; needs normals): finite values keep points whose normals differ
        close together (denser where the normals turn). None: infinity, positions only.
    seed : int
        Seed of the visit order and of the dimension estimate (0 to 2^64 - 1).
    epsilon : float
        The acceptance threshold of the measure, in (0, 1): lower takes more samples.
    dim : int or None
        The dimension m of the manifold the points lie near (1 to d), for the count search's
        first step. None: estimated from the points (Levina and Bickel).
    return_report : bool
        Also return the report.

    Returns
    -------
    indices : numpy.ndarray of int64, shape (k,)
        The samples as rows of X, increasing.
    report : dict
        With return_report=True: `sigma_p` (the width used, X's units), `sigma_n` (None for
        infinity), `dim` (the manifold dimension used or estimated; None when sigma_p was given
        without dim), `reached` (the count within its tolerance; True with sigma_p), `search`
        (every scan of the search as a pair (sigma_p, count), in order), `count` (k),
        `rejected_by_nearest` and `measured` (the chosen scan's points rejected by their nearest
        sample alone, and those whose measure was evaluated).

    Raises
    ------
    ValueError
        An array of the wrong shape or dtype, a coordinate that is not finite or a normal of
        length 0 (naming its row), neither or both of sigma_p and count, a count outside 1 to n,
        a finite sigma_n without normals, or a parameter out of its range.

    Warns
    -----
    UserWarning
        When count is not reached (the report's `reached` is False), saying how many samples
        were taken and, when X repeats rows, how many distinct rows it has.
    """
    ...


@overload
def resample(
    X: npt.ArrayLike,
    indices: npt.ArrayLike,
    normals: None = None,
    *,
    sigma_p: float,
    sigma_n: Optional[float] = None,
    iterations: int = 10,
    seed: int = 1,
    dim: Optional[int] = None,
    project: Optional[_ProjectPoints] = None,
    return_report: Literal[False] = False,
) -> npt.NDArray[np.float64]: ...
@overload
def resample(
    X: npt.ArrayLike,
    indices: npt.ArrayLike,
    normals: npt.ArrayLike,
    *,
    sigma_p: float,
    sigma_n: Optional[float] = None,
    iterations: int = 10,
    seed: int = 1,
    dim: Optional[int] = None,
    project: Optional[_ProjectPointsAndNormals] = None,
    return_report: Literal[False] = False,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
@overload
def resample(
    X: npt.ArrayLike,
    indices: npt.ArrayLike,
    normals: None = None,
    *,
    sigma_p: float,
    sigma_n: Optional[float] = None,
    iterations: int = 10,
    seed: int = 1,
    dim: Optional[int] = None,
    project: Optional[_ProjectPoints] = None,
    return_report: Literal[True],
) -> Tuple[npt.NDArray[np.float64], Dict[str, Any]]: ...
@overload
def resample(
    X: npt.ArrayLike,
    indices: npt.ArrayLike,
    normals: npt.ArrayLike,
    *,
    sigma_p: float,
    sigma_n: Optional[float] = None,
    iterations: int = 10,
    seed: int = 1,
    dim: Optional[int] = None,
    project: Optional[_ProjectPointsAndNormals] = None,
    return_report: Literal[True],
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], Dict[str, Any]]: ...
@overload
def resample(
    X: npt.ArrayLike,
    indices: npt.ArrayLike,
    normals: Optional[npt.ArrayLike] = None,
    *,
    sigma_p: float,
    sigma_n: Optional[float] = None,
    iterations: int = 10,
    seed: int = 1,
    dim: Optional[int] = None,
    project: Optional[Callable[[npt.NDArray[np.float64]], Any]] = None,
    return_report: bool = False,
) -> Union[
    npt.NDArray[np.float64],
    Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]],
    Tuple[npt.NDArray[np.float64], Dict[str, Any]],
    Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], Dict[str, Any]],
]:
    """Move samples of a point set into an even (blue-noise) arrangement on its manifold, by
    gradient ascent on the spectral measure (eq. 11 of the paper).

    The samples X[indices] (usually from `sample`) move for `iterations` sweeps, each sample in a
    seeded random order along the gradient of its measure over its neighbours, and each move is
    projected onto the manifold: onto the point set X itself (a local quadratic fit to the
    nearest rows of X; the normal of the nearest row) or by the callable `project`. Lengths are
    in X's own units. The GIL is released during the work, but for the calls of `project`.

    Parameters
    ----------
    X : array_like, shape (n, d)
        The points, any real dtype (converted to float64), n >= 1, d from 1 to 16.
    indices : array_like, shape (k,)
        The samples as rows of X (0-based), any integer dtype, each row once.
    normals : array_like, shape (n, d), or None
        A direction per point, normalized here; the samples' normals follow their moves.
    sigma_p : float
        The kernel width in X's units, the one the samples were chosen with (`sample`'s
        report).
    sigma_n : float or None
        The normal width (> 0; needs normals; then d at most 8). None: infinity, positions only.
    iterations : int
        Sweeps over all samples (>= 0).
    seed : int
        Seed of the visit order and of the dimension estimate (0 to 2^64 - 1).
    dim : int or None
        The dimension m of the manifold (1 to d) for the projection onto X. None: estimated from
        the points. Not with `project`.
    project : callable or None
        `project(Y) -> Y2`: projects each row of a float64 array Y of shape (m, d) onto the
        manifold and returns an array-like of the same shape; with normals it returns a pair
        (Y2, N2), N2 the normals at Y2 (normalized here). Called with the GIL held, for batches
        of samples of which no two are neighbours. None: the projection onto X.
    return_report : bool
        Also return the report.

    Returns
    -------
    Y : numpy.ndarray of float64, shape (k, d)
        The moved samples, in the order of indices.
    N : numpy.ndarray of float64, shape (k, d)
        Only with normals: their unit normals.
    report : dict
        With return_report=True, last: `sigma_p`, `sigma_n` (None for infinity), `iterations`,
        `dim` (the manifold dimension of the projection onto X; None with `project`), and per
        sweep `mean_move` (the mean move, X's units), `mean_s` and `min_s` (the mean and the
        least measure before the sweep's moves).

    Raises
    ------
    ValueError
        An array of the wrong shape or dtype, a coordinate that is not finite or a normal of
        length 0 (naming its row), an index out of range or repeated, a finite sigma_n without
        normals, a parameter out of its range, or `project` returning the wrong shape or a
        coordinate that is not finite.
    TypeError
        `project` is not callable.
    Exception
        Whatever `project` raises, unchanged.
    """
    ...
