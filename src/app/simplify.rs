//! The `remesh simplify` job: a point set out of core with the randomized linear scan, written as
//! binary PLY, and the summary the command line prints.

use std::fmt;
use std::path::PathBuf;
use std::time::Instant;

use glam::DVec3;

use crate::error::{Error, Result};
use crate::points::out_of_core::{simplify_out_of_core, simplify_progressive, OutOfCoreParams};
use crate::points::source::PointSource;
use crate::points::{PlyPointWriter, PointReader};

/// How dense the simplified point set is.
#[derive(Debug, Clone, PartialEq)]
pub enum SimplifyDensity {
    /// About this many output points (sigma_p is searched on a random subset).
    Points(usize),
    /// This sigma_p, bbox-100 units.
    SigmaP(f64),
    /// Progressive sampling (Sec. 6.4): one nested level per sigma_p (bbox-100 units), coarsest
    /// first.
    Levels(Vec<f64>),
}

/// A `remesh simplify` job.
#[derive(Debug, Clone, PartialEq)]
pub struct SimplifyJob {
    /// The input point set: PLY (ascii or binary), PCD, LAS, LAZ, E57 or XYZ/CSV text, with or
    /// without normals.
    pub input: PathBuf,
    /// The output point set (binary PLY with normals; with levels, a `uchar level` property).
    pub output: PathBuf,
    /// The output's density.
    pub density: SimplifyDensity,
    /// sigma_n (`None`: infinity, positions only; a finite value needs input normals).
    pub sigma_n: Option<f64>,
    /// Sweeps of gradient-ascent resampling onto the RIMLS surface after the scan (Sec. 6.2).
    pub resample: usize,
    /// Seed of every random choice.
    pub seed: u64,
    /// For an input without normals: orient the estimated normals towards this point (model
    /// units) instead of outward by a spanning tree. `None`: the sensor the file gives when it
    /// gives one (a PLY range map's camera, a PCD's `VIEWPOINT`, an E57's single scan:
    /// [`PointSource::viewpoint`]) and the points look seen from there
    /// ([`PointSource::orientation`]), else the spanning tree.
    pub viewpoint: Option<DVec3>,
}

/// What a [`SimplifyJob`] did; `Display` is the text the command line prints.
#[derive(Debug, Clone, PartialEq)]
pub struct SimplifySummary {
    /// The job's input and output.
    pub input: PathBuf,
    /// See [`SimplifySummary::input`].
    pub output: PathBuf,
    /// Points read.
    pub input_points: u64,
    /// Points of far groups left out: they would have set the scale (a stray `0 0 0`, or a
    /// small cluster, in a scan at UTM coordinates).
    pub far_points: u64,
    /// Points merged into another at the same position.
    pub duplicate_points: u64,
    /// Points written.
    pub samples: usize,
    /// The count asked for (`--points`), if one was.
    pub target: Option<usize>,
    /// Whether the input had normals.
    pub had_normals: bool,
    /// The single-level run's figures, or the levels'.
    pub detail: SimplifyDetail,
    /// Wall-clock seconds of the whole job.
    pub total_seconds: f64,
}

/// The per-run part of a [`SimplifySummary`].
#[derive(Debug, Clone, PartialEq)]
pub enum SimplifyDetail {
    /// One level.
    Single {
        /// sigma_p used, bbox-100 units.
        sigma_p: f64,
        /// Candidates rejected by their nearest sample alone.
        rejected_by_nearest: u64,
        /// Candidates whose full measure was computed.
        measured: u64,
        /// Seconds of: read + bucket, sigma_p search, scan, normals + resample.
        seconds: [f64; 4],
    },
    /// Nested levels.
    Levels {
        /// sigma_p per level, bbox-100 units.
        sigma_p: Vec<f64>,
        /// The end index of each level in the output.
        level_ends: Vec<usize>,
        /// Seconds: read + bucket, then one per level.
        seconds: Vec<f64>,
    },
}

/// Runs a [`SimplifyJob`]: simplifies the input out of core and writes the output atomically.
///
/// # Errors
/// [`Error::InvalidParameter`] for `--points 0`, a finite sigma_n on an input without normals,
/// or an output that is the input; reading and writing errors naming the file.
pub fn run_simplify(job: &SimplifyJob) -> Result<SimplifySummary> {
    super::points::require_ply_output(&job.output)?;
    super::files::refuse_input_as_output(&job.input, &job.output)?;
    if job.density == SimplifyDensity::Points(0) {
        return Err(Error::InvalidParameter {
            name: "points",
            message: "must be at least 1".into(),
        });
    }
    if job.resample > super::options::MAX_SWEEPS {
        return Err(Error::InvalidParameter {
            name: "resample",
            message: format!(
                "must be at most {}, got {}",
                super::options::MAX_SWEEPS,
                job.resample
            ),
        });
    }
    let t = Instant::now();
    if job.sigma_n.is_some_and(f64::is_finite) && !PointReader::open(&job.input)?.has_normals() {
        return Err(Error::InvalidParameter {
            name: "sigma_n",
            message: format!("{} has no normals; sigma_n needs them", job.input.display()),
        });
    }
    let (orientation, _) = PointSource::File(job.input.clone()).orientation(job.viewpoint)?;
    let params = OutOfCoreParams {
        resample: job.resample,
        orientation,
        target: match job.density {
            SimplifyDensity::Points(n) => Some(n),
            _ => None,
        },
        sigma_p: match job.density {
            SimplifyDensity::SigmaP(s) => s,
            _ => 1.0,
        },
        sigma_n: job.sigma_n.unwrap_or(f64::INFINITY),
        seed: job.seed,
        ..Default::default()
    };
    let (input_points, (far_points, duplicate_points), samples, had_normals, detail) = match &job
        .density
    {
        SimplifyDensity::Levels(levels) => {
            let r = simplify_progressive(&job.input, levels, &params)?;
            let mut w = PlyPointWriter::create_with_levels(&job.output, r.samples.len() as u64)?;
            w.write_levels(&r.samples, &r.levels)?;
            w.finish()?;
            let detail = SimplifyDetail::Levels {
                sigma_p: r.sigma_p.clone(),
                level_ends: r.level_ends.clone(),
                seconds: r.seconds.clone(),
            };
            (
                r.input_points,
                (r.far_points, r.duplicate_points),
                r.samples.len(),
                r.had_normals,
                detail,
            )
        }
        _ => {
            let r = simplify_out_of_core(&job.input, &params)?;
            let mut w = PlyPointWriter::create(&job.output, r.samples.len() as u64)?;
            w.write(&r.samples)?;
            w.finish()?;
            let detail = SimplifyDetail::Single {
                sigma_p: r.sigma_p,
                rejected_by_nearest: r.rejected_by_nearest as u64,
                measured: r.measured as u64,
                seconds: [r.seconds[0], r.seconds[1], r.seconds[2], r.seconds[3]],
            };
            (
                r.input_points,
                (r.far_points, r.duplicate_points),
                r.samples.len(),
                r.had_normals,
                detail,
            )
        }
    };
    Ok(SimplifySummary {
        input: job.input.clone(),
        output: job.output.clone(),
        input_points,
        far_points,
        duplicate_points,
        samples,
        target: match job.density {
            SimplifyDensity::Points(n) => Some(n),
            _ => None,
        },
        had_normals,
        detail,
        total_seconds: t.elapsed().as_secs_f64(),
    })
}

impl fmt::Display for SimplifySummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let no_normals = if self.had_normals {
            ""
        } else {
            "; the input has no normals: positions only, normals estimated on the output"
        };
        let (input, output) = (self.input.display(), self.output.display());
        let far = left_out(self.far_points, self.duplicate_points);
        match &self.detail {
            SimplifyDetail::Levels {
                sigma_p,
                level_ends,
                seconds,
            } => {
                writeln!(
                    f,
                    "{input} -> {output}: {} points{far} -> {} samples in {} nested levels{no_normals}",
                    self.input_points,
                    self.samples,
                    level_ends.len(),
                )?;
                for (l, (&end, s)) in level_ends.iter().zip(sigma_p).enumerate() {
                    let start = if l == 0 { 0 } else { level_ends[l - 1] };
                    writeln!(
                        f,
                        "  level {}: sigma_p {s:.4}, |P{}| = {end} (+{}), {:.2} s",
                        l + 1,
                        l + 1,
                        end - start,
                        seconds[l + 1]
                    )?;
                }
                writeln!(
                    f,
                    "seconds: read+bucket {:.2}, total {:.2}",
                    seconds[0], self.total_seconds
                )
            }
            SimplifyDetail::Single {
                sigma_p,
                rejected_by_nearest,
                measured,
                seconds,
            } => {
                writeln!(
                    f,
                    "{input} -> {output}: {} points{far} -> {} samples, sigma_p {sigma_p:.4} (bbox-100 units){no_normals}; {rejected_by_nearest} rejected by the nearest sample, {measured} measured",
                    self.input_points, self.samples,
                )?;
                if let Some(n) = self.target {
                    let off = self.samples as f64 / n as f64 - 1.0;
                    // (1e-9: 51 for 50 is within 2%, whatever the division rounds to.)
                    if off.abs() > COUNT_TOLERANCE + 1e-9 {
                        writeln!(
                            f,
                            "note: {} samples for --points {n} ({:+.1}%, outside the {:.0}% the count \
                             search aims at{})",
                            self.samples,
                            100.0 * off,
                            100.0 * COUNT_TOLERANCE,
                            if self.samples < n && (self.input_points as usize) < n {
                                format!(": the input has {} distinct points", self.input_points)
                            } else {
                                String::new()
                            }
                        )?;
                    }
                }
                writeln!(
                    f,
                    "seconds: read+bucket {:.2}, sigma_p search {:.2}, scan {:.2}, normals+resample {:.2}, total {:.2}",
                    seconds[0], seconds[1], seconds[2], seconds[3], self.total_seconds
                )
            }
        }
    }
}

/// The share by which a `--points` count may miss before the summary says so (the README's
/// promise for `simplify`).
const COUNT_TOLERANCE: f64 = 0.02;

/// What the reading left out, for the summary line: " (…)" or nothing.
fn left_out(far: u64, duplicates: u64) -> String {
    let mut parts = Vec::new();
    if duplicates > 0 {
        parts.push(format!(
            "{} merged",
            super::notes::plural(duplicates, "coincident point", "coincident points")
        ));
    }
    if far > 0 {
        parts.push(format!(
            "{} left out: they would have set the scale",
            super::notes::plural(far, "point of far groups", "points of far groups")
        ));
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!(" ({})", parts.join("; "))
    }
}
