//! Everything the pipeline reports about an output mesh, printed as a table or saved as JSON.

use std::fmt;

use serde::Serialize;

#[cfg(doc)]
use super::distance::surface_distance;
use super::distance::SurfaceDistance;
use super::triangle_quality::{triangle_quality, TriangleQuality};
use crate::check::{
    check_all, surface_topology, topology, topology_changes, SelfIntersections, Topology,
    TopologyChange, Violation,
};
#[cfg(doc)]
use crate::check::{check_invariants, self_intersections};
use crate::geometry::PairKind;
use crate::mesh::TriMesh;

/// The wall-clock time of one pipeline stage.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StageTime {
    /// The stage's name (`read`, `normalize`, `linear scan`, ...).
    pub stage: String,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Processor seconds (all threads, user and system) over the stage; divided by `seconds`, the
    /// cores it kept busy on average.
    pub cpu_seconds: f64,
}

/// Everything the pipeline reports about an output mesh: the Table 1 triangle measures, its
/// topology, optionally the input's topology and the distance to the input, stage timings, notes
/// and free-form extra values (e.g. `sigma_p`). Printed as a table by `Display`, saved as JSON by
/// [`QualityReport::to_json`].
///
/// This is the project's one ruler: the `remesh` binary prints it, and the evaluation harness
/// measures every remesher (ours and the ones we compare with) with the same functions. Every
/// measure is defined in the docs of the item that computes it, with its units and its source.
///
/// # Measures
///
/// | measure | function | source |
/// |---|---|---|
/// | θmin, θmin,ave, Qmin, Qave, %θ<30 | [`triangle_quality`] | Öztireli et al. 2010, Sec. 7.1 and Table 1, after Yan et al. 2009 and Valette et al. 2008 |
/// | P30 (share of angles below 30°) | [`triangle_quality`] | the tables of Yan et al. 2009 and ACVD (Valette et al. 2008) |
/// | counts, χ, genus, boundary loops, manifoldness, orientation | [`topology`] | standard combinatorial topology (e.g. Botsch et al. 2010, *Polygon Mesh Processing*, Ch. 1) |
/// | Hausdorff, RMS and mean distance | [`surface_distance`] | Metro (Cignoni, Rocchini, Scopigno 1998), as used for Table 2 of the paper |
/// | invariants every triangulation must keep | [`check_invariants`] | this project (STYLE.md, practice 7) |
///
/// # Determinism
/// Every function of the report returns the same numbers for the same input on every run and
/// every thread count: reductions run sequentially in index order, random samples come from a
/// seeded ChaCha8 stream, and no output depends on hash-map iteration order.
///
/// # References
/// - A. C. Öztireli, M. Alexa, M. Gross. *Spectral Sampling of Manifolds*. ACM Trans. Graph.
///   29(6), 2010 (SIGGRAPH Asia). doi:10.1145/1882261.1866190. Sec. 7.1, Tables 1 and 2.
/// - D.-M. Yan, B. Lévy, Y. Liu, F. Sun, W. Wang. *Isotropic Remeshing with Fast and Exact
///   Computation of Restricted Voronoi Diagram*. Computer Graphics Forum 28(5), 2009 (SGP).
///   The paper's "YR".
/// - S. Valette, J.-M. Chassery, R. Prost. *Generic Remeshing of 3D Triangular Meshes with
///   Metric-Dependent Discrete Voronoi Diagrams*. IEEE TVCG 14(2), 2008. The paper's "VR"
///   (ACVD).
/// - P. J. Frey, H. Borouchaki. *Surface mesh quality evaluation*. Int. J. Numer. Meth. Engng
///   45, 1999 (shape measures of the kind `S / (p h)`).
/// - P. Cignoni, C. Rocchini, R. Scopigno. *Metro: Measuring Error on Simplified Surfaces*.
///   Computer Graphics Forum 17(2), 1998 (the paper cites the Metro tool as
///   \[Cignoni et al. 2001\]).
///
/// The paper's text of Sec. 7.1 for Table 1: "θmin is the smallest angle in the mesh, θmin,ave
/// is the average of minimum angles of all triangles, and θ < 30° is the percentage of triangles
/// with minimum angle below 30°. Q denotes quality of a triangle and measured as
/// 6 S_t / (√3 p_t h_t), where S_t is the area of the triangle t, p_t is its half-perimeter, and
/// h_t is the length of the longest edge. Qmin and Qave are the minimum and average of Q's of
/// all triangles in the mesh."
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct QualityReport {
    /// Table 1 measures of the output ([`triangle_quality`]).
    pub triangles: TriangleQuality,
    /// Topology of the output ([`topology`]).
    pub topology: Topology,
    /// Pairs of output faces that intersect, by kind ([`self_intersections`]).
    pub self_intersections: SelfIntersections,
    /// The output's violated invariants ([`check_invariants`]), one per kind; empty when all
    /// hold. Serialized with a `kind` tag and the variant's fields.
    pub invariant_violations: Vec<Violation>,
    /// Distance between output (side A, "forward") and input (side B), in bbox-100 units
    /// ([`surface_distance`]); `None` when not measured.
    pub distance: Option<SurfaceDistance>,
    /// Topology of the input, for comparison; `None` when not given.
    pub input_topology: Option<Topology>,
    /// How the output's components, Euler characteristic and boundary loops differ from the
    /// input surface's ([`topology_changes`], [`QualityReport::set_input`]); empty when they are
    /// equal or no input is given.
    /// Serialized with a `kind` tag and the two values.
    pub topology_changes: Vec<TopologyChange>,
    /// Per-stage wall-clock times, in pipeline order.
    pub stages: Vec<StageTime>,
    /// Free-text remarks (warnings, repairs made, targets not reached).
    pub notes: Vec<String>,
    /// Extra named values (parameters such as `sigma_p`, counts), printed and serialized in
    /// serde_json's map order (sorted by key unless its `preserve_order` feature is on).
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl QualityReport {
    /// The report of `mesh` with its triangle measures and topology; no distance, input
    /// topology, stages, notes or extras yet.
    pub fn new(mesh: &TriMesh) -> Self {
        Self::with_crossings_on(mesh, mesh)
    }

    /// [`QualityReport::new`], with the self-intersections (and the `Crossing` violation)
    /// decided on `stored`: the same faces at the coordinates the file stores, where `mesh` is
    /// the file mapped into a bbox-100 frame (whose rounding can make two faces that touch in the
    /// file apart, or the reverse; the exact test is only as exact as the coordinates it is
    /// given).
    pub fn with_crossings_on(mesh: &TriMesh, stored: &TriMesh) -> Self {
        let (topology, crossings, violations) = check_all(mesh, stored);
        QualityReport {
            triangles: triangle_quality(mesh),
            invariant_violations: violations,
            self_intersections: crossings,
            topology,
            distance: None,
            input_topology: None,
            topology_changes: Vec::new(),
            stages: Vec::new(),
            notes: Vec::new(),
            extra: serde_json::Map::new(),
        }
    }

    /// Sets the input's topology ([`topology`] of `input`) and compares the output's with its
    /// surface's ([`surface_topology`]: without zero-area, repeated-index or duplicate faces,
    /// and split at vertices where parts touch at a point, as a manifold output must be):
    /// every difference of components, Euler characteristic and boundary loops goes into
    /// [`QualityReport::topology_changes`] and, in words, into one note.
    pub fn set_input(&mut self, input: &TriMesh) {
        let raw = topology(input);
        let surface = if raw.degenerate_faces == 0
            && raw.duplicate_faces == 0
            && raw.non_manifold_vertices == 0
        {
            raw.clone()
        } else {
            surface_topology(input)
        };
        self.topology_changes = topology_changes(&surface, &self.topology);
        if !self.topology_changes.is_empty() {
            self.notes.push(format!(
                "the output's topology differs from the input's: {}",
                self.topology_changes_text()
            ));
        }
        self.input_topology = Some(raw);
    }

    /// [`QualityReport::topology_changes`] in words, separated by "; ".
    pub fn topology_changes_text(&self) -> String {
        self.topology_changes
            .iter()
            .map(|c| c.to_string())
            .collect::<Vec<_>>()
            .join("; ")
    }

    /// Appends a stage's wall-clock and processor seconds.
    pub fn push_stage(&mut self, stage: impl Into<String>, seconds: f64, cpu_seconds: f64) {
        self.stages.push(StageTime {
            stage: stage.into(),
            seconds,
            cpu_seconds,
        });
    }

    /// The sum of the stages' wall-clock times, in seconds.
    pub fn total_seconds(&self) -> f64 {
        self.stages.iter().map(|s| s.seconds).sum()
    }

    /// The sum of the stages' processor times, in seconds.
    pub fn total_cpu_seconds(&self) -> f64 {
        self.stages.iter().map(|s| s.cpu_seconds).sum()
    }

    /// The report as pretty-printed JSON (field names as in the structs; `genus: null` where
    /// undefined, `distance: null` where not measured).
    pub fn to_json(&self) -> String {
        // Serializing plain structs, strings and a JSON map cannot fail (non-finite floats are
        // written as null).
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}

/// A row of the printed topology block: its label and how to read the value.
type TopologyRow = (&'static str, fn(&Topology) -> String);

/// Width of the label column of the printed report.
const LABEL: usize = 34;
/// Width of a value column of the printed report.
const VALUE: usize = 12;

impl fmt::Display for QualityReport {
    /// A fixed-width table: "Triangles (Table 1)" (angles with 2 decimals, Q with 4, percentages
    /// with 2), "Topology" (the input's beside it when present), "Distance to input (bbox-100
    /// units)" (4 decimals), "Time" (per stage and total, seconds), then extras and notes.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t = &self.triangles;
        writeln!(f, "Triangles (Table 1)")?;
        let row = |f: &mut fmt::Formatter<'_>, label: &str, value: String| {
            writeln!(f, "  {label:<LABEL$}{value:>VALUE$}")
        };
        row(f, "faces measured", t.faces_measured.to_string())?;
        row(f, "θmin (deg)", format!("{:.2}", t.theta_min))?;
        row(f, "θmin,ave (deg)", format!("{:.2}", t.theta_min_ave))?;
        row(f, "θmax (deg)", format!("{:.2}", t.theta_max))?;
        row(f, "Qmin", format!("{:.4}", t.q_min))?;
        row(f, "Qave", format!("{:.4}", t.q_ave))?;
        row(
            f,
            "%θ<30 (% of triangles)",
            format!("{:.2}", t.pct_theta_below_30),
        )?;
        row(f, "P30 (% of angles)", format!("{:.2}", t.p30))?;

        writeln!(f)?;
        let input = self.input_topology.as_ref();
        if input.is_some() {
            writeln!(
                f,
                "{:<w$}{:>VALUE$}{:>VALUE$}",
                "Topology",
                "output",
                "input",
                w = LABEL + 2
            )?;
        } else {
            writeln!(f, "Topology")?;
        }
        let topo_rows: [TopologyRow; 14] = [
            ("vertices (referenced)", |t| t.vertices.to_string()),
            ("faces", |t| t.faces.to_string()),
            ("edges", |t| t.edges.to_string()),
            ("Euler characteristic", |t| {
                t.euler_characteristic.to_string()
            }),
            ("genus", |t| {
                t.genus.map_or("-".to_string(), |g| g.to_string())
            }),
            ("components", |t| t.components.to_string()),
            ("boundary edges", |t| t.boundary_edges.to_string()),
            ("boundary loops", |t| t.boundary_loops.to_string()),
            ("non-manifold edges", |t| t.non_manifold_edges.to_string()),
            ("non-manifold vertices", |t| {
                t.non_manifold_vertices.to_string()
            }),
            ("inconsistently oriented edges", |t| {
                t.inconsistent_orientation_edges.to_string()
            }),
            ("degenerate faces", |t| t.degenerate_faces.to_string()),
            ("duplicate faces", |t| t.duplicate_faces.to_string()),
            ("unreferenced vertices", |t| {
                t.unreferenced_vertices.to_string()
            }),
        ];
        for (label, get) in topo_rows {
            match input {
                Some(inp) => writeln!(
                    f,
                    "  {label:<LABEL$}{:>VALUE$}{:>VALUE$}",
                    get(&self.topology),
                    get(inp)
                )?,
                None => row(f, label, get(&self.topology))?,
            }
        }

        writeln!(f)?;
        writeln!(f, "Invariants")?;
        let si = &self.self_intersections;
        row(f, "self-intersecting face pairs", si.pairs.to_string())?;
        if si.pairs > 0 {
            for kind in PairKind::ALL {
                row(
                    f,
                    &format!("  {}", kind.describe()),
                    si.of_kind(kind).to_string(),
                )?;
            }
        }
        if self.invariant_violations.is_empty() {
            writeln!(
                f,
                "  all hold (manifold, consistently oriented, no degenerate, duplicate or intersecting faces)"
            )?;
        } else {
            for v in &self.invariant_violations {
                writeln!(f, "  VIOLATED: {v}")?;
            }
        }

        writeln!(f)?;
        writeln!(f, "Distance to input (bbox-100 units)")?;
        match &self.distance {
            Some(d) => {
                row(f, "Hausdorff", format!("{:.4}", d.hausdorff))?;
                row(f, "RMS (worse side)", format!("{:.4}", d.rms))?;
                row(f, "mean", format!("{:.4}", d.mean))?;
                row(
                    f,
                    "Hausdorff output→input",
                    format!("{:.4}", d.forward_hausdorff),
                )?;
                row(
                    f,
                    "Hausdorff input→output",
                    format!("{:.4}", d.backward_hausdorff),
                )?;
                row(f, "RMS output→input", format!("{:.4}", d.forward_rms))?;
                row(f, "RMS input→output", format!("{:.4}", d.backward_rms))?;
                row(f, "random samples per side", d.samples_per_side.to_string())?;
            }
            None => writeln!(f, "  (not measured)")?,
        }

        writeln!(f)?;
        writeln!(
            f,
            "{:<w$}{:>VALUE$}{:>VALUE$}",
            "Time (s)",
            "wall",
            "cpu",
            w = LABEL + 2
        )?;
        let times = |f: &mut fmt::Formatter<'_>, label: &str, wall: f64, cpu: f64| {
            writeln!(f, "  {label:<LABEL$}{wall:>VALUE$.3}{cpu:>VALUE$.3}")
        };
        for s in &self.stages {
            times(f, &s.stage, s.seconds, s.cpu_seconds)?;
        }
        times(f, "total", self.total_seconds(), self.total_cpu_seconds())?;

        if !self.extra.is_empty() {
            writeln!(f)?;
            writeln!(f, "Extra")?;
            for (k, v) in &self.extra {
                let v = match v {
                    serde_json::Value::String(s) => s.clone(),
                    other => other.to_string(),
                };
                row(f, k, v)?;
            }
        }
        if !self.notes.is_empty() {
            writeln!(f)?;
            writeln!(f, "Notes")?;
            for n in &self.notes {
                writeln!(f, "  - {n}")?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::topology;
    use glam::DVec3;

    #[test]
    fn display_has_every_block() {
        let m = TriMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]);
        let mut r = QualityReport::new(&m);
        r.input_topology = Some(topology(&m));
        r.push_stage("triangulate", 0.25, 0.5);
        r.notes.push("a note".into());
        r.extra.insert("sigma_p".into(), serde_json::json!(1.5));
        let s = r.to_string();
        for needle in [
            "Triangles (Table 1)",
            "45.00",
            "Topology",
            "input",
            "Distance to input (bbox-100 units)",
            "(not measured)",
            "Time (s)",
            "wall",
            "cpu",
            "total",
            "0.500",
            "sigma_p",
            "- a note",
        ] {
            assert!(s.contains(needle), "missing {needle:?} in\n{s}");
        }
        let json: serde_json::Value = serde_json::from_str(&r.to_json()).unwrap();
        assert_eq!(json["topology"]["genus"], serde_json::json!(0));
        assert_eq!(json["extra"]["sigma_p"], serde_json::json!(1.5));
        assert!(json["distance"].is_null());
    }
}
