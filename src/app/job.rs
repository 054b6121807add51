//! A remeshing job: the files and the pipeline's parameters, and the mesh a job held in memory
//! gives back.

use std::path::PathBuf;

use crate::io::MeshFormat;
use crate::mesh::TriMesh;
use crate::pipeline::RemeshParams;
use crate::report::QualityReport;

/// A remeshing job: input and output files and the pipeline's parameters.
#[derive(Debug, Clone)]
pub struct RemeshJob {
    /// Input mesh (.obj, .ply, .gltf, .glb, .stl, .off) or point set.
    pub input: PathBuf,
    /// Output mesh (.obj, .ply, .gltf, .glb), format by extension; `-`
    /// ([`STDOUT`](crate::internal::STDOUT)) writes it to standard output instead, in `format`.
    pub output: PathBuf,
    /// The output's format: `None` takes it from `output`'s extension, or OBJ for standard
    /// output. Given with a file, it must agree with the extension; the binary formats (PLY,
    /// GLB) go to standard output only when asked for here, and never to a terminal.
    pub format: Option<MeshFormat>,
    /// Pipeline parameters (`Density::InputVertices`: as many as the input has vertices).
    pub params: RemeshParams,
    /// Whether to measure the distance to the input (Hausdorff, RMS).
    pub measure_distance: bool,
    /// Whether a violated output invariant ([`check_invariants`](crate::check_invariants):
    /// manifold, oriented, no degenerate, duplicate or intersecting faces) or a topology that
    /// differs from the input's ([`topology_changes`](crate::internal::topology_changes):
    /// components, Euler characteristic, boundary loops) is an error, with nothing written, rather
    /// than a note of the report.
    pub strict: bool,
    /// The most memory the job may take, in bytes: a job whose estimated peak
    /// ([`estimate_remesh_bytes`](crate::internal::estimate_remesh_bytes)) is larger is refused
    /// before it starts (and an input file too large to fit is refused before it is read). `None`:
    /// no limit.
    pub max_memory: Option<u64>,
    /// Whether the input is read as a point set (its faces ignored) even when it has faces:
    /// `--as-points` (a PLY file). A text, PCD, LAS, LAZ or E57 point file or a PLY file without
    /// faces is read as a point set either way ([`is_point_set`](crate::internal::is_point_set)).
    pub as_points: bool,
    /// For a point set without normals: the estimated normals face this point (model units; a
    /// single scan's sensor) instead of being oriented outward by a spanning tree. `None`: the
    /// sensor the file gives when it gives one (a PLY range map's camera, a PCD's `VIEWPOINT`, an
    /// E57's single scan: [`PointSource::viewpoint`](crate::PointSource::viewpoint)) and the
    /// points look seen from there ([`PointSource::orientation`](crate::PointSource::orientation)),
    /// else the spanning tree. Not used for meshes.
    pub viewpoint: Option<glam::DVec3>,
    /// Where the JSON report goes as well (`--report`): written with the mesh, both only once
    /// everything has been written. `None`: nowhere.
    pub report: Option<PathBuf>,
}

impl RemeshJob {
    /// The job of an input held in memory ([`remesh_mesh`](crate::remesh_mesh),
    /// [`remesh_point_set`](crate::remesh_point_set)): `input` names it (or is the temporary file
    /// holding it); the output is handed back, not written.
    pub(super) fn in_memory(
        input: PathBuf,
        params: &RemeshParams,
        measure_distance: bool,
        strict: bool,
        max_memory: Option<u64>,
        viewpoint: Option<glam::DVec3>,
    ) -> Self {
        RemeshJob {
            input,
            output: PathBuf::from("the output mesh"),
            format: None,
            params: *params,
            measure_distance,
            strict,
            max_memory,
            as_points: false,
            viewpoint,
            report: None,
        }
    }
}

/// The output of [`remesh_mesh`](crate::remesh_mesh): the remeshed mesh and its report.
#[derive(Debug, Clone)]
pub struct RemeshedMesh {
    /// The output mesh in the input's (model) units: what [`run_remesh`](crate::run_remesh) writes
    /// to a file (as PLY, OBJ or OFF, which store it exactly).
    pub mesh: TriMesh,
    /// The report, as [`run_remesh`](crate::run_remesh) gives it (its `write` stage is the
    /// hand-over of the mesh).
    pub report: QualityReport,
}
