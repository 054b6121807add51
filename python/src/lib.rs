//! The `spectral_remesh` Python module: the library's reading, remeshing and quality report on
//! numpy arrays, and the sampling of point sets near a manifold of any dimension in R^d
//! (`sample`, `resample`; `python/spectral_remesh.pyi` documents it for Python users).
//!
//! Every function copies its arrays into the library's types with the GIL held, then releases
//! the GIL (`Python::detach`) for the work. Errors become Python exceptions carrying the
//! library's one-line message ([`to_py_err`]); a panic (a bug) is caught before it reaches the
//! interpreter and raised as `RuntimeError`. A Python callable `project` of `resample` is the
//! one exception: each of its calls takes the GIL again ([`CallableProjection`]), and what it
//! raises reaches the caller unchanged.
//!
//! Arrays in: any array-like numpy can read (`numpy.asarray`). Positions of any real dtype are
//! converted to `float64`, face and sample indices of any integer dtype checked against the
//! vertex or point count; non-contiguous arrays (slices, transposes) are read through their
//! strides. Wrong shapes, non-numeric dtypes, non-finite coordinates and indices out of range are
//! `ValueError`s.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::Mutex;

use glam::DVec3;
use numpy::ndarray::{Array1, Array2};
use numpy::{
    IntoPyArray, PyArray2, PyArrayDescrMethods, PyReadonlyArray2, PyReadonlyArrayDyn,
    PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{
    PyFileNotFoundError, PyIsADirectoryError, PyOSError, PyPermissionError, PyRuntimeError,
    PyTypeError, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use spectral::{
    DataProjection, Error, ManifoldProjection, ManifoldResampleParams, ManifoldSampleParams,
    PointSet, QualityReport, RemeshOptions, TriMesh,
};

/// A library error as the Python exception a caller expects, with the library's one-line
/// message: `OSError` (or its `FileNotFoundError`, `PermissionError`, `IsADirectoryError`) when
/// the operating system refused a file, `ValueError` for input that cannot be used (an
/// unsupported format, a file that does not parse, a mesh that fails the checks, a parameter
/// out of range), `RuntimeError` for an internal failure (and `strict=True` refusing an
/// output).
fn to_py_err(e: Error) -> PyErr {
    let message = e.to_string();
    match &e {
        Error::Io { source, .. } => match source.kind() {
            std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
            std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
            std::io::ErrorKind::IsADirectory => PyIsADirectoryError::new_err(message),
            _ => PyOSError::new_err(message),
        },
        Error::Write { .. } => PyOSError::new_err(message),
        Error::UnsupportedFormat { .. }
        | Error::Parse { .. }
        | Error::InvalidMesh { .. }
        | Error::InvalidParameter { .. } => PyValueError::new_err(message),
        Error::Internal { .. } => PyRuntimeError::new_err(message),
    }
}

/// Runs `work` without the GIL, catching a panic: the library's result, or the panic as a
/// `RuntimeError` naming it a bug. (The panic's message and place are also on standard error,
/// from Rust's panic hook, which is left as it is: replacing a process-wide hook from several
/// Python threads at once would race.)
fn without_gil<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> spectral::Result<T> + Send,
) -> PyResult<T> {
    let result = py.detach(|| catch_unwind(AssertUnwindSafe(work)));
    match result {
        Ok(r) => r.map_err(to_py_err),
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown cause".into());
            Err(PyRuntimeError::new_err(format!(
                "panic: {} (a bug: please report it)",
                what.replace('\n', " ")
            )))
        }
    }
}

/// `value` as a numpy array of shape `(rows, 3)`: `numpy.asarray(value)`, its shape checked.
/// `name` names it in errors, `rows` the number of rows (`n`, `m`).
fn array_n3<'py>(
    py: Python<'py>,
    name: &str,
    rows: &str,
    value: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    let array = py
        .import("numpy")?
        .call_method1("asarray", (value,))?
        .cast_into::<PyUntypedArray>()?;
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{name} must be an array of shape ({rows}, 3), got shape {}",
            shape_text(shape)
        )));
    }
    Ok(array)
}

/// A 2-D array of a real dtype (floating point or integer) as `float64` (`numpy.asarray(array,
/// "float64")`); `name` names it in the error for another dtype.
fn real_f64<'py>(
    py: Python<'py>,
    name: &str,
    array: Bound<'py, PyUntypedArray>,
) -> PyResult<PyReadonlyArray2<'py, f64>> {
    let dtype = array.dtype();
    if !matches!(dtype.kind(), b'f' | b'i' | b'u') {
        return Err(PyValueError::new_err(format!(
            "{name} must hold real numbers (a float or integer dtype), got dtype {}",
            dtype.str()?
        )));
    }
    py.import("numpy")?
        .call_method1("asarray", (array, "float64"))?
        .extract()
}

/// A shape as Python prints it: `(4,)`, `(4, 2)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Vertex positions from an array-like of shape `(n, 3)` and a real dtype (floating point or
/// integer; converted to `float64`). Finiteness is checked by the library
/// ([`spectral::remesh_mesh`], [`spectral::quality_mesh`]) with the vertex named.
fn positions(py: Python<'_>, name: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<DVec3>> {
    let array = real_f64(py, name, array_n3(py, name, "n", value)?)?;
    Ok(array
        .as_array()
        .rows()
        .into_iter()
        .map(|r| DVec3::new(r[0], r[1], r[2]))
        .collect())
}

/// Triangles from an array-like of shape `(m, 3)` and an integer dtype, each index checked to
/// name one of `vertices` vertices (0-based).
fn triangles(
    py: Python<'_>,
    name: &str,
    value: &Bound<'_, PyAny>,
    vertices: usize,
) -> PyResult<Vec<[u32; 3]>> {
    let array = array_n3(py, name, "m", value)?;
    if u32::try_from(vertices).is_err() {
        return Err(PyValueError::new_err(format!(
            "{vertices} vertices are more than 32-bit indices can name"
        )));
    }
    let values = integer_values(py, name, "vertex indices", array)?;
    let mut out = Vec::with_capacity(values.len() / 3);
    for (row, r) in values.chunks_exact(3).enumerate() {
        let mut t = [0u32; 3];
        for (col, &v) in r.iter().enumerate() {
            t[col] = match usize::try_from(v) {
                Ok(i) if i < vertices => i as u32,
                _ if vertices == 0 => {
                    return Err(PyValueError::new_err(format!(
                        "{name}[{row}, {col}] = {v} is not a vertex index: there are no vertices \
                         (the vertex array is empty)"
                    )))
                }
                _ => {
                    return Err(PyValueError::new_err(format!(
                        "{name}[{row}, {col}] = {v} is not a vertex index: the vertices are \
                         numbered 0 to {} (0-based)",
                        vertices - 1
                    )))
                }
            };
        }
        out.push(t);
    }
    Ok(out)
}

/// The values of an integer array in logical (row-major) order, whatever its strides, as i128
/// (every int64 and uint64 value exactly); `name` and `what` ("vertex indices") name it in the
/// error for another dtype.
fn integer_values(
    py: Python<'_>,
    name: &str,
    what: &str,
    array: Bound<'_, PyUntypedArray>,
) -> PyResult<Vec<i128>> {
    let dtype = array.dtype();
    let (kind, size) = (dtype.kind(), dtype.itemsize());
    if !matches!(kind, b'i' | b'u') {
        return Err(PyValueError::new_err(format!(
            "{name} must hold {what} (an integer dtype), got dtype {}",
            dtype.str()?
        )));
    }
    let np = py.import("numpy")?;
    if kind == b'u' && size == 8 {
        // uint64 does not fit int64: read as it is.
        let array: PyReadonlyArrayDyn<u64> =
            np.call_method1("asarray", (array, "uint64"))?.extract()?;
        Ok(array.as_array().iter().map(|&v| i128::from(v)).collect())
    } else {
        let array: PyReadonlyArrayDyn<i64> =
            np.call_method1("asarray", (array, "int64"))?.extract()?;
        Ok(array.as_array().iter().map(|&v| i128::from(v)).collect())
    }
}

/// A mesh from the arrays `v` and `f` (named `v_name`, `f_name` in errors).
fn mesh_from(
    py: Python<'_>,
    (v_name, v): (&str, &Bound<'_, PyAny>),
    (f_name, f): (&str, &Bound<'_, PyAny>),
) -> PyResult<TriMesh> {
    let positions = positions(py, v_name, v)?;
    let triangles = triangles(py, f_name, f, positions.len())?;
    Ok(TriMesh::new(positions, triangles))
}

/// A mesh as numpy arrays: `V` float64 (n, 3), `F` int64 (m, 3).
type MeshArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>);

/// A mesh as the arrays `(V: float64[n, 3], F: int64[m, 3])`.
fn mesh_arrays<'py>(py: Python<'py>, mesh: TriMesh) -> MeshArrays<'py> {
    let n = mesh.positions.len();
    let m = mesh.triangles.len();
    let v: Vec<f64> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
    let f: Vec<i64> = mesh
        .triangles
        .iter()
        .flat_map(|t| t.map(i64::from))
        .collect();
    // The lengths are 3n and 3m by construction.
    let v = Array2::from_shape_vec((n, 3), v).unwrap_or_else(|_| Array2::zeros((0, 3)));
    let f = Array2::from_shape_vec((m, 3), f).unwrap_or_else(|_| Array2::zeros((0, 3)));
    (v.into_pyarray(py), f.into_pyarray(py))
}

/// A report as the dict `json.loads` makes of the command line's JSON report.
fn report_dict<'py>(py: Python<'py>, report: &QualityReport) -> PyResult<Bound<'py, PyDict>> {
    Ok(py
        .import("json")?
        .call_method1("loads", (report.to_json(),))?
        .cast_into::<PyDict>()?)
}

/// Read a mesh file through the library's readers, as `remesh` reads its input.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     A mesh file: .obj, .ply (ascii or binary), .gltf or .glb, .stl or .off, told by its
///     extension.
///
/// Returns
/// -------
/// V : numpy.ndarray of float64, shape (n, 3)
///     Vertex positions in the file's own (model) units.
/// F : numpy.ndarray of int64, shape (m, 3)
///     Triangles as 0-based indices into V. Polygons are triangulated, vertices at identical
///     positions welded and vertices no triangle uses removed, as for `remesh`.
///
/// Raises
/// ------
/// OSError
///     The file cannot be opened or read (FileNotFoundError, PermissionError or
///     IsADirectoryError where that is the cause).
/// ValueError
///     The extension names no mesh format, the content does not parse, or the mesh cannot be
///     used (no triangles, an index out of range, a non-finite coordinate).
#[pyfunction]
#[pyo3(signature = (path, /))]
fn read<'py>(py: Python<'py>, path: PathBuf) -> PyResult<MeshArrays<'py>> {
    let (mesh, _) = without_gil(py, move || spectral::read_mesh(&path))?;
    Ok(mesh_arrays(py, mesh))
}

/// Read a point set through the library's point readers, as `remesh` reads a scan.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     A point-set file: .ply (vertices, no faces), .pcd (ascii, binary or binary_compressed),
///     .las or .laz, .e57 (every scan posed into the file's frame), or .xyz / .csv / .txt text,
///     told by its extension; a file's header sizes are checked against the file before
///     anything is allocated.
///
/// Returns
/// -------
/// P : numpy.ndarray of float64, shape (n, 3)
///     The points with finite coordinates, in the file's own units and order.
/// N : numpy.ndarray of float64, shape (n, 3), or None
///     Their unit normals (zero where the file's are missing) when the file has normals.
///
/// Raises
/// ------
/// OSError
///     The file cannot be opened or read (FileNotFoundError, PermissionError or
///     IsADirectoryError where that is the cause).
/// ValueError
///     The extension names no point-set format, or the content does not parse or promises more
///     than the file holds.
#[pyfunction]
#[pyo3(signature = (path, /))]
#[allow(clippy::type_complexity)]
fn read_points<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Option<Bound<'py, PyArray2<f64>>>)> {
    let (positions, normals) = without_gil(py, move || {
        use spectral::internal::PointReader;
        let mut reader = PointReader::open(&path)?;
        let has_normals = reader.has_normals();
        let (mut positions, mut normals, mut chunk) = (Vec::new(), Vec::new(), Vec::new());
        while reader.read_chunk(&mut chunk, 1 << 16)? > 0 {
            for p in &chunk {
                positions.extend(p.position.to_array());
                if has_normals {
                    normals.extend(p.normal.to_array());
                }
            }
        }
        Ok((positions, has_normals.then_some(normals)))
    })?;
    Ok((
        rows_array(py, &positions, 3),
        normals.map(|n| rows_array(py, &n, 3)),
    ))
}

/// Write a triangle mesh to a file through the library's writers, as `remesh` writes its output.
///
/// The format is the extension's: .obj and .off (coordinates in the shortest text that reads
/// back to the same float64), .ply (binary, coordinates as double), .glb and .gltf (glTF 2.0),
/// .stl (binary). The file is written atomically: to a temporary file beside it, then renamed
/// into place, so a failure leaves nothing at the path (an existing file stays as it was).
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     The file to write.
/// V : array_like, shape (n, 3)
///     Vertex positions, any real dtype (converted to float64), in model units.
/// F : array_like, shape (m, 3)
///     Triangles as 0-based indices into V, any integer dtype.
///
/// Raises
/// ------
/// ValueError
///     An array of the wrong shape or dtype, a non-finite coordinate (naming the vertex), an
///     index out of range, or an extension that names no mesh format.
/// OSError
///     The file cannot be written (missing folder, no permission, disk full).
#[pyfunction]
#[pyo3(signature = (path, V, F, /))]
#[allow(non_snake_case)]
fn write(
    py: Python<'_>,
    path: PathBuf,
    V: &Bound<'_, PyAny>,
    F: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let mesh = mesh_from(py, ("V", V), ("F", F))?;
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "V[{i}] has a coordinate that is not finite"
        )));
    }
    without_gil(py, move || spectral::write_mesh(&path, &mesh))
}

/// The quality report of a triangle mesh, as `remesh quality --json` gives it.
///
/// The mesh (and the reference) get the reader's checks and clean-up first (vertices at
/// identical positions welded, vertices no triangle uses removed), so the report equals the
/// command line's for files holding the same arrays, but for the stage times.
///
/// Parameters
/// ----------
/// V : array_like, shape (n, 3)
///     Vertex positions, any real dtype (converted to float64), in model units.
/// F : array_like, shape (m, 3)
///     Triangles as 0-based indices into V, any integer dtype.
/// ref : tuple (V0, F0) or None
///     A reference surface (usually a remesher's input) as two such arrays. It sets the
///     bbox-100 frame of every length, and the report gains the distance between the two.
/// seed : int
///     Seed of the distance's random points.
///
/// Returns
/// -------
/// dict
///     The JSON report as `json.loads` reads it: `triangles` (Table 1: `theta_min`,
///     `theta_min_ave`, `theta_max` in degrees, `q_min`, `q_ave`, `pct_theta_below_30` in
///     percent of the triangles, `p30` in percent of the angles, `faces_measured`), `topology`,
///     `self_intersections`, `invariant_violations`, `distance` (None without `ref`;
///     `hausdorff`, `rms`, `mean` and the one-sided values in bbox-100 units, the reference
///     scaled so its bounding box's longest side is 100), `input_topology` (the reference's),
///     `topology_changes`, `stages` (wall and processor seconds), `notes`, `extra`.
///
/// Raises
/// ------
/// ValueError
///     An array of the wrong shape or dtype, a non-finite coordinate, an index out of range,
///     no triangles, or a mesh without area.
#[pyfunction]
#[pyo3(signature = (V, F, r#ref = None, seed = 1))]
#[allow(non_snake_case)]
fn quality<'py>(
    py: Python<'py>,
    V: &Bound<'py, PyAny>,
    F: &Bound<'py, PyAny>,
    r#ref: Option<&Bound<'py, PyAny>>,
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let mesh = mesh_from(py, ("V", V), ("F", F))?;
    let reference = match r#ref {
        None => None,
        Some(r) => {
            let pair: (Bound<'py, PyAny>, Bound<'py, PyAny>) = r.extract().map_err(|_| {
                PyValueError::new_err("ref must be a pair (V0, F0) of arrays, or None")
            })?;
            Some(mesh_from(py, ("ref[0]", &pair.0), ("ref[1]", &pair.1))?)
        }
    };
    let report = without_gil(py, move || spectral::quality_mesh(mesh, reference, seed))?;
    report_dict(py, &report)
}

/// `max_memory` as bytes: an int, a size such as `"8G"`, or `None` for the smallest of the
/// machine's physical memory and the process's limits (the command line's default); a size
/// given is held to the process's limits too (`effective_memory_limit`).
fn memory_limit(value: Option<&Bound<'_, PyAny>>) -> PyResult<Option<u64>> {
    let given = match value {
        None => None,
        Some(value) => Some(if let Ok(text) = value.extract::<String>() {
            spectral::internal::parse_bytes(&text)
                .map_err(|e| PyValueError::new_err(format!("invalid parameter max_memory: {e}")))?
        } else {
            match value.extract::<i128>() {
                Ok(n) if (0..=u64::MAX as i128).contains(&n) => n as u64,
                _ => return Err(PyValueError::new_err(
                    "invalid parameter max_memory: give a number of bytes >= 0 or a size such as \"8G\"",
                )),
            }
        }),
    };
    Ok(spectral::internal::effective_memory_limit(given))
}

/// A count option: an int >= 0 (named as the command line names it in the error).
fn count(name: &str, value: i128) -> PyResult<usize> {
    usize::try_from(value).map_err(|_| {
        PyValueError::new_err(format!(
            "invalid parameter {name}: must be an integer >= 0, got {value}"
        ))
    })
}

/// The payload a job unwinds with when [`Progress::stage`] stops it.
struct Stopped;

/// `remesh`'s `progress`: a Python callable given each stage's name, called with the GIL taken,
/// after Python's signal handlers; the first exception of either stops the job and is raised.
struct Progress {
    callable: Option<Py<PyAny>>,
    raised: Mutex<Option<PyErr>>,
}

impl Progress {
    /// `progress` checked: None or a callable.
    fn new(progress: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let callable = match progress {
            Some(p) if !p.is_none() => {
                if !p.is_callable() {
                    return Err(PyTypeError::new_err(format!(
                        "progress must be callable (or None), got {}",
                        p.get_type().name()?
                    )));
                }
                Some(p.clone().unbind())
            }
            _ => None,
        };
        Ok(Progress {
            callable,
            raised: Mutex::new(None),
        })
    }

    /// The library's `on_stage`: Python's signal handlers run (Ctrl-C raises
    /// `KeyboardInterrupt` there), then the callable on `stage`. An exception from either
    /// stops the job at once: it unwinds with [`Stopped`] (without the panic hook: nothing is
    /// printed), and [`Progress::result_of`] raises the exception.
    fn stage(&self, stage: &str) {
        let mut raised = self.raised.lock().unwrap_or_else(|p| p.into_inner());
        if raised.is_some() {
            std::panic::resume_unwind(Box::new(Stopped));
        }
        let result = Python::attach(|py| {
            py.check_signals()?;
            match &self.callable {
                Some(callable) => callable.bind(py).call1((stage,)).map(|_| ()),
                None => Ok(()),
            }
        });
        if let Err(e) = result {
            *raised = Some(e);
            drop(raised);
            std::panic::resume_unwind(Box::new(Stopped));
        }
    }

    /// The job's result, or the callable's exception when it raised one.
    fn result_of<T>(progress: &Progress, out: PyResult<T>) -> PyResult<T> {
        match progress
            .raised
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .take()
        {
            Some(e) => Err(e),
            None => out,
        }
    }
}

/// `remesh`'s result: the output's `V` and `F` and the report.
type Remeshed<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyDict>,
);

/// Remesh a triangle mesh, or mesh a point set, by spectral sampling, as the `remesh` command
/// line does.
///
/// The same arrays and options give the same output, bit for bit, as `remesh IN OUT` on a file
/// holding the arrays (`remesh` writes .ply, .obj and .off exactly; a point set: a text file of
/// `x y z [nx ny nz]` lines). Each option is the command line's flag of that name; None takes
/// the command line's default. Lengths are in bbox-100 units: the input scaled so its bounding
/// box's longest side is 100. The GIL is released during the work.
///
/// Parameters
/// ----------
/// V : array_like, shape (n, 3)
///     Vertex positions, any real dtype (converted to float64), in model units; with F None,
///     the points of a point set (a scan), meshed through the RIMLS surface of the points as
///     `remesh scan.xyz out.ply` does.
/// F : array_like, shape (m, 3), or None
///     Triangles as 0-based indices into V, any integer dtype. Vertices at identical positions
///     are welded and vertices no triangle uses removed first, as the reader does. None: V is
///     a point set (it then needs points or sigma_p; lfs_factor and chord_error are not
///     available).
/// normals : array_like, shape (n, 3), or None
///     A point set's normals, one per point (any length but zero). None: estimated, and
///     oriented outward (or towards viewpoint). Only with F None.
/// viewpoint : sequence of 3 floats or None
///     Orient a point set's estimated normals towards this point (a single scan's sensor, model
///     units; `--viewpoint`). Only with F None and no normals.
/// points : int or None
///     About this many output vertices (within 1%); sigma_p is searched for. 4 to 20 million.
///     With neither points nor sigma_p: as many as the input has vertices.
/// sigma_p : float or None
///     The kernel width in bbox-100 units, instead of points.
/// edge_length : float or None
///     Output edges about this long, in the input's own units, instead of points or sigma_p:
///     for a mesh the count of equilateral triangles of that edge on the input's area, for a
///     point set sigma_p = that length / 1.2 in bbox-100 units (its sampling's mean edge is
///     1.2 sigma_p); the report's notes give it.
/// sigma_n : float or None
///     The normal width; finite values give feature-adaptive sampling. None: infinity.
/// seed : int
///     Seed of every random choice.
/// iterations : int or None
///     Gradient-ascent sweeps (10).
/// lfs_factor : float or None
///     ε of the sizing field (meshes): the spacing follows the local feature size,
///     h = ε · lfs where that is below sigma_p, in absolute units, so walls, tubes, holes and
///     gaps narrower than the spacing get the samples they need and the count may grow (at
///     most 4 times; strict refuses). 2.5 is the bound of the topological ball property; 0,
///     the default, turns it off.
/// chord_error : float or None
///     Curved parts: the spacing follows the curvature (0: off, the default; 0.003 for CAD
///     parts).
/// fit : bool
///     The least-squares vertex placement (True, the default; False is `--no-fit`).
/// smooth : int or None
///     Iterations of the finishing relaxation (10).
/// min_angle, max_angle : float or None
///     The angle bounds in degrees the last optimization pass works towards (35, 100).
/// feature_angle : float or None
///     Keep every crease found at this angle in degrees (0 to 180). None: automatic at 20°.
/// features : bool
///     False: no crease detection (`--no-features`; not with feature_angle).
/// triangulation : str or None
///     "restricted" (restricted Delaunay, the default; also "restricted-refined"),
///     "restricted-clipped" (its cells clipped exactly from the input's facets) or "umbrellas".
/// distance : bool
///     Measure the Hausdorff and RMS distance to the input (False is `--no-distance`).
/// strict : bool
///     Raise RuntimeError instead of returning an output that breaks an invariant or whose
///     topology differs from the input's.
/// max_memory : int, str or None
///     The most memory the job may take, in bytes or as a size ("512M", "8G", "2GiB"); a job
///     whose estimated peak is larger is refused at once. None: the smallest of the machine's
///     physical memory and the process's memory limits (cgroup, address space).
/// progress : callable or None
///     Called with each stage's name (str: "read", "linear scan", "gradient ascent",
///     "triangulate", ...) as the stage starts, with the GIL taken for the call. An exception it
///     raises stops further calls and is raised again, unchanged, when the job returns.
///
/// Returns
/// -------
/// V : numpy.ndarray of float64, shape (k, 3)
///     The output's vertex positions, in the input's units.
/// F : numpy.ndarray of int64, shape (l, 3)
///     The output's triangles, 0-based indices into V, oriented consistently (closed parts
///     outward).
/// report : dict
///     The JSON report of `remesh --report` as `json.loads` reads it (see `quality`), with the
///     input's topology, and in `extra` sigma_p, the sigma_p search, the seed and the stages'
///     statistics.
///
/// Raises
/// ------
/// ValueError
///     An array of the wrong shape or dtype, a non-finite coordinate, an index out of range,
///     no triangles (no points), a normal of length zero, normals or viewpoint with F given, an
///     option out of its range or two that exclude each other (named as the command line names
///     it), or a job over max_memory.
/// RuntimeError
///     With strict=True, an output that breaks an invariant or changes the topology; or an
///     internal failure.
#[pyfunction]
#[pyo3(signature = (
    V, F = None, *, normals = None, viewpoint = None, points = None, sigma_p = None,
    edge_length = None, sigma_n = None, seed = 1, iterations = None,
    lfs_factor = None, chord_error = None, fit = true, smooth = None, min_angle = None,
    max_angle = None, feature_angle = None, features = true, triangulation = None,
    distance = true, strict = false, max_memory = None, progress = None
))]
#[allow(non_snake_case, clippy::too_many_arguments)]
fn remesh<'py>(
    py: Python<'py>,
    V: &Bound<'py, PyAny>,
    F: Option<&Bound<'py, PyAny>>,
    normals: Option<&Bound<'py, PyAny>>,
    viewpoint: Option<&Bound<'py, PyAny>>,
    points: Option<i128>,
    sigma_p: Option<f64>,
    edge_length: Option<f64>,
    sigma_n: Option<f64>,
    seed: i128,
    iterations: Option<i128>,
    lfs_factor: Option<f64>,
    chord_error: Option<f64>,
    fit: bool,
    smooth: Option<i128>,
    min_angle: Option<f64>,
    max_angle: Option<f64>,
    feature_angle: Option<f64>,
    features: bool,
    triangulation: Option<String>,
    distance: bool,
    strict: bool,
    max_memory: Option<&Bound<'py, PyAny>>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Remeshed<'py>> {
    let progress = Progress::new(progress)?;
    let defaults = RemeshOptions::default();
    let seed = u64::try_from(seed).map_err(|_| {
        PyValueError::new_err(format!(
            "invalid parameter seed: must be an integer from 0 to 2^64 - 1, got {seed}"
        ))
    })?;
    let options = RemeshOptions {
        points: points.map(|n| count("points", n)).transpose()?,
        sigma_p,
        edge_length,
        sigma_n,
        lfs_factor: lfs_factor.unwrap_or(defaults.lfs_factor),
        chord_error: chord_error.unwrap_or(defaults.chord_error),
        no_fit: !fit,
        smooth: smooth
            .map(|n| count("smooth", n))
            .transpose()?
            .unwrap_or(defaults.smooth),
        min_angle: min_angle.unwrap_or(defaults.min_angle),
        max_angle: max_angle.unwrap_or(defaults.max_angle),
        feature_angle,
        no_features: !features,
        triangulation: triangulation.unwrap_or(defaults.triangulation),
        iterations: iterations
            .map(|n| count("iterations", n))
            .transpose()?
            .unwrap_or(defaults.iterations),
        seed,
    };
    let params = options.params().map_err(to_py_err)?;
    let max_memory = memory_limit(max_memory)?;
    let Some(F) = F else {
        // A point set.
        let points = positions(py, "V", V)?;
        let normals = match normals {
            None => None,
            Some(n) => {
                let n = positions(py, "normals", n)?;
                if n.len() != points.len() {
                    return Err(PyValueError::new_err(format!(
                        "normals must have the shape of V, ({}, 3), got ({}, 3)",
                        points.len(),
                        n.len()
                    )));
                }
                Some(n)
            }
        };
        let viewpoint = viewpoint.map(point3).transpose()?;
        if viewpoint.is_some() && normals.is_some() {
            return Err(PyValueError::new_err(
                "viewpoint orients estimated normals: not with normals given",
            ));
        }
        let progress = &progress;
        let out = without_gil(py, move || {
            spectral::remesh_point_set(
                &points,
                normals.as_deref(),
                &params,
                viewpoint,
                distance,
                strict,
                max_memory,
                &|stage| progress.stage(stage),
            )
        });
        let out = Progress::result_of(progress, out)?;
        let (v, f) = mesh_arrays(py, out.mesh);
        return Ok((v, f, report_dict(py, &out.report)?));
    };
    if normals.is_some() || viewpoint.is_some() {
        return Err(PyValueError::new_err(
            "normals and viewpoint are for a point set (F=None), not for a mesh",
        ));
    }
    let mesh = mesh_from(py, ("V", V), ("F", F))?;
    let out = without_gil(py, || {
        spectral::remesh_mesh(mesh, &params, distance, strict, max_memory, &|stage| {
            progress.stage(stage)
        })
    });
    let out = Progress::result_of(&progress, out)?;
    let (v, f) = mesh_arrays(py, out.mesh);
    Ok((v, f, report_dict(py, &out.report)?))
}

/// A point of R^3 from a sequence of three finite numbers (`viewpoint`).
fn point3(value: &Bound<'_, PyAny>) -> PyResult<DVec3> {
    let bad = || {
        PyValueError::new_err(format!(
            "viewpoint must be three finite numbers (x, y, z), got {}",
            value
                .repr()
                .map(|r| r.to_string())
                .unwrap_or_else(|_| "?".into())
        ))
    };
    let v: Vec<f64> = value.extract().map_err(|_| bad())?;
    match v[..] {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(DVec3::new(x, y, z)),
        _ => Err(bad()),
    }
}

/// The largest space dimension d of a point set (the library's kernel space, K = d).
const MAX_DIM: usize = spectral::internal::MAX_KERNEL_DIMENSION;

/// `value` as a numpy array (`numpy.asarray(value)`).
fn asarray<'py>(
    py: Python<'py>,
    value: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    Ok(py
        .import("numpy")?
        .call_method1("asarray", (value,))?
        .cast_into::<PyUntypedArray>()?)
}

/// Points from an array-like of shape `(n, d)`, n >= 1 and 1 <= d <= 16 (or exactly `like`,
/// the shape of X, for normals) and a real dtype (converted to `float64`): the values row-major,
/// read through the array's strides, and `(n, d)`. Finiteness is checked by the library
/// ([`PointSet::new`], naming the row).
fn point_rows(
    py: Python<'_>,
    name: &str,
    value: &Bound<'_, PyAny>,
    like: Option<(usize, usize)>,
) -> PyResult<(Vec<f64>, usize, usize)> {
    let array = asarray(py, value)?;
    let shape = array.shape();
    match like {
        None => {
            if shape.len() != 2 || shape[0] == 0 || shape[1] == 0 || shape[1] > MAX_DIM {
                return Err(PyValueError::new_err(format!(
                    "{name} must be an array of shape (n, d): n >= 1 points of 1 to {MAX_DIM} \
                     coordinates, got shape {}",
                    shape_text(shape)
                )));
            }
        }
        Some((n, d)) => {
            if shape != [n, d] {
                return Err(PyValueError::new_err(format!(
                    "{name} must be an array of the shape of X, ({n}, {d}), got shape {}",
                    shape_text(shape)
                )));
            }
        }
    }
    let (n, d) = (shape[0], shape[1]);
    let array = real_f64(py, name, array)?;
    // Logical (row-major) order whatever the strides.
    Ok((array.as_array().iter().copied().collect(), n, d))
}

/// Sample indices from a 1-D array-like of an integer dtype: each names one of the `points`
/// rows of X (0-based), none twice.
fn sample_indices(py: Python<'_>, value: &Bound<'_, PyAny>, points: usize) -> PyResult<Vec<usize>> {
    let array = asarray(py, value)?;
    let shape = array.shape();
    if shape.len() != 1 {
        return Err(PyValueError::new_err(format!(
            "indices must be an array of shape (k,), got shape {}",
            shape_text(shape)
        )));
    }
    if shape[0] == 0 {
        return Err(PyValueError::new_err(
            "indices must name at least one point, got shape (0,)",
        ));
    }
    let values = integer_values(py, "indices", "point indices", array)?;
    // Each index checked against the point count and the ones before it.
    let mut first = vec![usize::MAX; points];
    let mut out = Vec::with_capacity(values.len());
    for (pos, &v) in values.iter().enumerate() {
        let i = match usize::try_from(v) {
            Ok(i) if i < points => i,
            _ => {
                return Err(PyValueError::new_err(format!(
                    "indices[{pos}] = {v} is not a point index: the points of X are numbered 0 \
                     to {} (0-based)",
                    points as i128 - 1
                )))
            }
        };
        if first[i] != usize::MAX {
            return Err(PyValueError::new_err(format!(
                "indices[{pos}] = {i} repeats indices[{}]: each sample must be a different point",
                first[i]
            )));
        }
        first[i] = pos;
        out.push(i);
    }
    Ok(out)
}

/// `seed` as the library's u64.
fn seed_value(seed: i128) -> PyResult<u64> {
    u64::try_from(seed).map_err(|_| {
        PyValueError::new_err(format!(
            "invalid parameter seed: must be an integer from 0 to 2^64 - 1, got {seed}"
        ))
    })
}

/// The manifold's dimension `dim` in a space of dimension `d` (the library checks 1..=d; this
/// refuses what does not fit a usize, with the library's message).
fn manifold_dim(dim: Option<i128>, d: usize) -> PyResult<Option<usize>> {
    dim.map(|m| {
        usize::try_from(m).map_err(|_| {
            PyValueError::new_err(format!(
                "invalid parameter dim: the manifold's dimension must be from 1 to the space's \
                 {d}, got {m}"
            ))
        })
    })
    .transpose()
}

/// The kernel's widths checked with their Python names (the library names them as the command
/// line spells them, `--sigma-p`): sigma_p positive and finite when given, sigma_n positive
/// (infinity allowed) when given. Returns sigma_n as the library takes it: None is infinity
/// (positions only).
fn kernel_widths(sigma_p: Option<f64>, sigma_n: Option<f64>) -> PyResult<f64> {
    if let Some(s) = sigma_p.filter(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(PyValueError::new_err(format!(
            "invalid parameter sigma_p: must be a positive number, got {s}"
        )));
    }
    if let Some(s) = sigma_n.filter(|s| !(*s > 0.0)) {
        return Err(PyValueError::new_err(format!(
            "invalid parameter sigma_n: must be positive (or None for infinity), got {s}"
        )));
    }
    Ok(sigma_n.unwrap_or(f64::INFINITY))
}

/// A normal width as a report gives it: None for infinity.
fn width_or_none(sigma_n: f64) -> Option<f64> {
    sigma_n.is_finite().then_some(sigma_n)
}

/// Row-major `values` as a float64 array of shape `(values.len() / d, d)`.
fn rows_array<'py>(py: Python<'py>, values: &[f64], d: usize) -> Bound<'py, PyArray2<f64>> {
    // The length is a multiple of d by construction (a PointSet's).
    Array2::from_shape_vec((values.len() / d, d), values.to_vec())
        .unwrap_or_else(|_| Array2::zeros((0, d)))
        .into_pyarray(py)
}

/// Choose samples of a point set near a manifold of any dimension, by the randomized linear
/// scan (Algorithm 1 of the paper).
///
/// The points are visited in a random order (seeded) and kept when the spectral measure of the
/// Gaussian kernel exp(-|x - y|²), x = [p / sigma_p, n / sigma_n], over the points kept so far
/// exceeds epsilon: an even (blue-noise) subset of the rows of X, about sigma_p apart, on
/// curves, surfaces, volumes and higher-dimensional manifolds alike. With `count`, sigma_p is
/// searched for (a few scans). Lengths are in X's own units (no rescaling). The GIL is released
/// during the work.
///
/// Parameters
/// ----------
/// X : array_like, shape (n, d)
///     The points, any real dtype (converted to float64), n >= 1, d from 1 to 16.
/// normals : array_like, shape (n, d), or None
///     A direction per point (a hypersurface's normal, or any direction field the kernel should
///     tell apart), normalized here; used with a finite sigma_n (then d at most 8).
/// sigma_p : float or None
///     The kernel width in X's units: samples end up about this far apart.
/// count : int or None
///     About this many samples (within 0.5% when the search reaches it: the report's
///     `reached`), sigma_p searched for; 1 to n. Give exactly one of sigma_p and count.
/// sigma_n : float or None
///     The normal width (> 0; needs normals): finite values keep points whose normals differ
///     close together (denser where the normals turn). None: infinity, positions only.
/// seed : int
///     Seed of the visit order and of the dimension estimate (0 to 2^64 - 1).
/// epsilon : float
///     The acceptance threshold of the measure, in (0, 1): lower takes more samples.
/// dim : int or None
///     The dimension m of the manifold the points lie near (1 to d), for the count search's
///     first step. None: estimated from the points (Levina and Bickel).
/// return_report : bool
///     Also return the report.
///
/// Returns
/// -------
/// indices : numpy.ndarray of int64, shape (k,)
///     The samples as rows of X, increasing.
/// report : dict
///     With return_report=True: `sigma_p` (the width used, X's units), `sigma_n` (None for
///     infinity), `dim` (the manifold dimension used or estimated; None when sigma_p was given
///     without dim), `reached` (the count within its tolerance; True with sigma_p), `search`
///     (every scan of the search as a pair (sigma_p, count), in order), `count` (k),
///     `rejected_by_nearest` and `measured` (the chosen scan's points rejected by their nearest
///     sample alone, and those whose measure was evaluated).
///
/// Raises
/// ------
/// ValueError
///     An array of the wrong shape or dtype, a coordinate that is not finite or a normal of
///     length 0 (naming its row), neither or both of sigma_p and count, a count outside 1 to n,
///     a finite sigma_n without normals, or a parameter out of its range.
///
/// Warns
/// -----
/// UserWarning
///     When count is not reached (the report's `reached` is False), saying how many samples
///     were taken and, when X repeats rows, how many distinct rows it has.
#[pyfunction]
#[pyo3(signature = (
    X, normals = None, *, sigma_p = None, count = None, sigma_n = None, seed = 1, epsilon = 0.5,
    dim = None, return_report = false
))]
#[allow(non_snake_case, clippy::too_many_arguments)]
fn sample<'py>(
    py: Python<'py>,
    X: &Bound<'py, PyAny>,
    normals: Option<&Bound<'py, PyAny>>,
    sigma_p: Option<f64>,
    count: Option<i128>,
    sigma_n: Option<f64>,
    seed: i128,
    epsilon: f64,
    dim: Option<i128>,
    return_report: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (positions, n, d) = point_rows(py, "X", X, None)?;
    let normals = normals
        .map(|v| point_rows(py, "normals", v, Some((n, d))).map(|r| r.0))
        .transpose()?;
    let count = count
        .map(|c| {
            usize::try_from(c).map_err(|_| {
                PyValueError::new_err(format!(
                    "invalid parameter count: must be from 1 to the {n} points, got {c}"
                ))
            })
        })
        .transpose()?;
    let params = ManifoldSampleParams {
        sigma_p,
        count,
        sigma_n: kernel_widths(sigma_p, sigma_n)?,
        epsilon,
        dimension: manifold_dim(dim, d)?,
        seed: seed_value(seed)?,
        ..Default::default()
    };
    // Coincident rows are one point to the measure: a count above theirs cannot be reached.
    let distinct = {
        let mut rows: Vec<Vec<u64>> = positions
            .chunks_exact(d.max(1))
            .map(|r| r.iter().map(|v| (v + 0.0).to_bits()).collect())
            .collect();
        rows.sort_unstable();
        rows.dedup();
        rows.len()
    };
    let picked = without_gil(py, move || {
        let points = PointSet::new(d, positions, normals)?;
        spectral::sample_manifold(&points, &params)
    })?;
    if let (Some(c), false) = (count, picked.reached) {
        let why = if distinct < n {
            format!(" (X has {distinct} distinct rows of {n}: coincident rows are one point)")
        } else {
            String::new()
        };
        let message = format!(
            "count={c} not reached: {} samples{why}",
            picked.indices.len()
        );
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &std::ffi::CString::new(message).unwrap_or_default(),
            1,
        )?;
    }
    let indices = Array1::from_iter(picked.indices.iter().map(|&i| i as i64)).into_pyarray(py);
    if !return_report {
        return Ok(indices.into_any());
    }
    let report = PyDict::new(py);
    report.set_item("sigma_p", picked.sigma_p)?;
    report.set_item("sigma_n", width_or_none(picked.sigma_n))?;
    report.set_item("dim", picked.dimension)?;
    report.set_item("reached", picked.reached)?;
    report.set_item("search", picked.search)?;
    report.set_item("count", picked.indices.len())?;
    report.set_item("rejected_by_nearest", picked.rejected_by_nearest)?;
    report.set_item("measured", picked.measured)?;
    Ok(PyTuple::new(py, [indices.into_any(), report.into_any()])?.into_any())
}

/// A Python callable `project(Y) -> Y2` (or `(Y2, N2)` with normals) as the library's
/// projection: each call takes the GIL again, hands the callable a fresh float64 array (m, d)
/// and copies its answer back, shapes checked. An exception the callable raises is kept in
/// `raised`, to be raised again unchanged when the library returns.
struct CallableProjection {
    project: Py<PyAny>,
    dim: usize,
    raised: Mutex<Option<PyErr>>,
}

impl CallableProjection {
    /// One call of the callable on `positions` (rows of `dim`), its answer written back.
    fn call(
        &self,
        py: Python<'_>,
        positions: &mut [f64],
        normals: Option<&mut [f64]>,
    ) -> PyResult<()> {
        let d = self.dim;
        let m = positions.len() / d;
        let y = rows_array(py, positions, d);
        let out = self.project.bind(py).call1((y,))?;
        match normals {
            None => copy_back(py, "project(Y)", &out, positions, (m, d)),
            Some(normals) => {
                let pair = match out.cast::<PyTuple>() {
                    Ok(t) if t.len() == 2 => Some((t.get_item(0)?, t.get_item(1)?)),
                    _ => match out.cast::<PyList>() {
                        Ok(l) if l.len() == 2 => Some((l.get_item(0)?, l.get_item(1)?)),
                        _ => None,
                    },
                };
                let Some((y2, n2)) = pair else {
                    return Err(PyValueError::new_err(format!(
                        "project must return a pair (Y2, N2) of arrays of shape ({m}, {d}) when \
                         normals are given, got {}",
                        out.get_type().name()?
                    )));
                };
                copy_back(py, "project(Y)[0]", &y2, positions, (m, d))?;
                copy_back(py, "project(Y)[1]", &n2, normals, (m, d))
            }
        }
    }
}

/// The callable's answer `value` (named `what`) read as float64 of shape `(m, d)` into `out`.
fn copy_back(
    py: Python<'_>,
    what: &str,
    value: &Bound<'_, PyAny>,
    out: &mut [f64],
    (m, d): (usize, usize),
) -> PyResult<()> {
    let array = py
        .import("numpy")?
        .call_method1("asarray", (value, "float64"))
        .and_then(|a| Ok(a.cast_into::<PyUntypedArray>()?))
        .map_err(|e| {
            PyValueError::new_err(format!(
                "{what} must be an array of float64 of shape ({m}, {d}), and numpy cannot read \
                 it as one: {e}"
            ))
        })?;
    if array.shape() != [m, d] {
        return Err(PyValueError::new_err(format!(
            "{what} must have the shape of Y, ({m}, {d}), got shape {}",
            shape_text(array.shape())
        )));
    }
    let array: PyReadonlyArray2<f64> = array.extract()?;
    for (o, v) in out.iter_mut().zip(array.as_array().iter()) {
        *o = *v;
    }
    Ok(())
}

impl ManifoldProjection for CallableProjection {
    fn dim(&self) -> usize {
        self.dim
    }

    fn project(&self, positions: &mut [f64], normals: Option<&mut [f64]>) -> spectral::Result<()> {
        Python::attach(|py| self.call(py, positions, normals)).map_err(|e| {
            *self.raised.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
            Error::InvalidParameter {
                name: "project",
                message: "the callable raised an exception".into(),
            }
        })
    }
}

/// Move samples of a point set into an even (blue-noise) arrangement on its manifold, by
/// gradient ascent on the spectral measure (eq. 11 of the paper).
///
/// The samples X[indices] (usually from `sample`) move for `iterations` sweeps, each sample in a
/// seeded random order along the gradient of its measure over its neighbours, and each move is
/// projected onto the manifold: onto the point set X itself (a local quadratic fit to the
/// nearest rows of X; the normal of the nearest row) or by the callable `project`. Lengths are
/// in X's own units. The GIL is released during the work, but for the calls of `project`.
///
/// Parameters
/// ----------
/// X : array_like, shape (n, d)
///     The points, any real dtype (converted to float64), n >= 1, d from 1 to 16.
/// indices : array_like, shape (k,)
///     The samples as rows of X (0-based), any integer dtype, each row once.
/// normals : array_like, shape (n, d), or None
///     A direction per point, normalized here; the samples' normals follow their moves.
/// sigma_p : float
///     The kernel width in X's units, the one the samples were chosen with (`sample`'s
///     report).
/// sigma_n : float or None
///     The normal width (> 0; needs normals; then d at most 8). None: infinity, positions only.
/// iterations : int
///     Sweeps over all samples (>= 0).
/// seed : int
///     Seed of the visit order and of the dimension estimate (0 to 2^64 - 1).
/// dim : int or None
///     The dimension m of the manifold (1 to d) for the projection onto X. None: estimated from
///     the points. Not with `project`.
/// project : callable or None
///     `project(Y) -> Y2`: projects each row of a float64 array Y of shape (m, d) onto the
///     manifold and returns an array-like of the same shape; with normals it returns a pair
///     (Y2, N2), N2 the normals at Y2 (normalized here). Called with the GIL held, for batches
///     of samples of which no two are neighbours. None: the projection onto X.
/// return_report : bool
///     Also return the report.
///
/// Returns
/// -------
/// Y : numpy.ndarray of float64, shape (k, d)
///     The moved samples, in the order of indices.
/// N : numpy.ndarray of float64, shape (k, d)
///     Only with normals: their unit normals.
/// report : dict
///     With return_report=True, last: `sigma_p`, `sigma_n` (None for infinity), `iterations`,
///     `dim` (the manifold dimension of the projection onto X; None with `project`), and per
///     sweep `mean_move` (the mean move, X's units), `mean_s` and `min_s` (the mean and the
///     least measure before the sweep's moves).
///
/// Raises
/// ------
/// ValueError
///     An array of the wrong shape or dtype, a coordinate that is not finite or a normal of
///     length 0 (naming its row), an index out of range or repeated, a finite sigma_n without
///     normals, a parameter out of its range, or `project` returning the wrong shape or a
///     coordinate that is not finite.
/// TypeError
///     `project` is not callable.
/// Exception
///     Whatever `project` raises, unchanged.
#[pyfunction]
#[pyo3(signature = (
    X, indices, normals = None, *, sigma_p, sigma_n = None, iterations = 10, seed = 1, dim = None,
    project = None, return_report = false
))]
#[allow(non_snake_case, clippy::too_many_arguments)]
fn resample<'py>(
    py: Python<'py>,
    X: &Bound<'py, PyAny>,
    indices: &Bound<'py, PyAny>,
    normals: Option<&Bound<'py, PyAny>>,
    sigma_p: f64,
    sigma_n: Option<f64>,
    iterations: i128,
    seed: i128,
    dim: Option<i128>,
    project: Option<&Bound<'py, PyAny>>,
    return_report: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (positions, n, d) = point_rows(py, "X", X, None)?;
    let normals = normals
        .map(|v| point_rows(py, "normals", v, Some((n, d))).map(|r| r.0))
        .transpose()?;
    let with_normals = normals.is_some();
    let indices = sample_indices(py, indices, n)?;
    let seed = seed_value(seed)?;
    let dim = manifold_dim(dim, d)?;
    let params = ManifoldResampleParams {
        sigma_n: kernel_widths(Some(sigma_p), sigma_n)?,
        iterations: count("iterations", iterations)?,
        seed,
        ..ManifoldResampleParams::new(sigma_p)
    };
    if let Some(f) = project {
        if !f.is_callable() {
            return Err(PyTypeError::new_err(format!(
                "project must be a callable project(Y) -> Y2, or None, got {}",
                f.get_type().name()?
            )));
        }
        if dim.is_some() {
            return Err(PyValueError::new_err(
                "invalid parameter dim: the manifold's dimension is for the projection onto X; \
                 give dim or project, not both",
            ));
        }
    }
    let callable = project.map(|f| CallableProjection {
        project: f.clone().unbind(),
        dim: d,
        raised: Mutex::new(None),
    });
    let result = without_gil(py, || {
        let data = PointSet::new(d, positions, normals)?;
        let samples = data.subset(&indices);
        match &callable {
            Some(f) => {
                let (out, ascent) = spectral::resample_manifold(&samples, f, &params)?;
                Ok((out, ascent, None))
            }
            None => {
                let projection = DataProjection::new(&data, dim, seed)?;
                let (out, ascent) = spectral::resample_manifold(&samples, &projection, &params)?;
                Ok((out, ascent, Some(projection.manifold_dim())))
            }
        }
    });
    // The callable's own exception, as it raised it.
    if let Some(raised) =
        callable.and_then(|c| c.raised.into_inner().unwrap_or_else(|p| p.into_inner()))
    {
        return Err(raised);
    }
    let (out, ascent, manifold) = result?;
    let mut items = vec![rows_array(py, out.positions(), d).into_any()];
    if let (true, Some(n)) = (with_normals, out.normals()) {
        items.push(rows_array(py, n, d).into_any());
    }
    if return_report {
        let report = PyDict::new(py);
        report.set_item("sigma_p", params.sigma_p)?;
        report.set_item("sigma_n", width_or_none(params.sigma_n))?;
        report.set_item("iterations", params.iterations)?;
        report.set_item("dim", manifold)?;
        report.set_item("mean_move", ascent.mean_move)?;
        report.set_item("mean_s", ascent.mean_s)?;
        report.set_item("min_s", ascent.min_s)?;
        items.push(report.into_any());
    }
    if items.len() == 1 {
        Ok(items.swap_remove(0))
    } else {
        Ok(PyTuple::new(py, items)?.into_any())
    }
}

/// Spectral sampling of manifolds (Öztireli, Alexa, Gross 2010): remeshing of triangle meshes,
/// and sampling of point sets near a manifold of any dimension in R^d, numpy in, numpy out.
///
/// Triangle meshes: `read`, `write`, `remesh` and `quality`, as the `remesh` command line does
/// them (`remesh` also meshes a point set of R^3 given without faces).
/// Point sets of shape (n, d), d from 1 to 16 (a curve in the plane, a surface in R^3 or R^4, a
/// 3-manifold in R^4, ...): `sample` chooses an even subset of the points, `resample` moves the
/// samples into blue noise on the manifold.
///
/// Arrays in: anything ``numpy.asarray`` reads. Positions of any real dtype are converted to
/// float64; face and sample indices of any integer dtype are checked against the vertex or point
/// count (a float array of indices is refused); non-contiguous arrays (slices, transposes,
/// negative strides) are read through their strides, never refused. Errors carry the library's
/// one-line message: ValueError for input or options that cannot be used, OSError for files the
/// operating system refuses, RuntimeError for an internal failure (a bug) or a strict refusal.
/// The GIL is released while the library works (but for the calls of a Python `project`).
#[pymodule]
fn spectral_remesh(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(read_points, m)?)?;
    m.add_function(wrap_pyfunction!(write, m)?)?;
    m.add_function(wrap_pyfunction!(quality, m)?)?;
    m.add_function(wrap_pyfunction!(remesh, m)?)?;
    m.add_function(wrap_pyfunction!(sample, m)?)?;
    m.add_function(wrap_pyfunction!(resample, m)?)?;
    Ok(())
}
