//! `spectral-experiments`: the paper's experiments on the command line. `blue-noise` is the plane
//! experiment (Sec. 7.1, Fig. 11), `reconstruct-eval` the reconstruction experiment (Sec. 7.2,
//! Table 2). Parses flags, calls the experiments crate, writes the reports, and maps errors to
//! the exit codes of `remesh` (2 usage, 3 input, 4 output, 1 internal).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use spectral_experiments::reconstruction_eval::{
    evaluate_model, PointSource, ReconstructionEvalParams,
};
use spectral_experiments::subsample::Subsampler;
use spectral_remesh::internal::NormalField;
use spectral_remesh::Error;

const EXAMPLES: &str = "\
Examples:
  spectral-experiments blue-noise --method ours --output ours.json
  spectral-experiments reconstruct-eval horse.obj fandisk.obj --spacing 0.15 --json table2.json";

/// The experiments of Spectral Sampling of Manifolds (Öztireli, Alexa, Gross 2010): blue noise
/// in the plane (Sec. 7.1) and reconstruction accuracy (Sec. 7.2), on the spectral-remesh
/// library.
#[derive(Parser, Debug)]
#[command(name = "spectral-experiments", version, after_help = EXAMPLES)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Blue noise on the periodic unit square (Sec. 7.1, Fig. 11): several point sets by one
    /// method, their normalized Poisson-disk radius (Lagae and Dutré 2008), mean periodogram,
    /// and radially averaged power and anisotropy (Ulichney 1987). Prints a summary; --output
    /// writes everything needed to plot as JSON.
    BlueNoise {
        /// ours (random start, 10 sweeps of gradient ascent, the paper's), ours-scan (a dense
        /// random set, the linear scan, then gradient ascent), lloyd (100 iterations, periodic
        /// Voronoi), dart (dart throwing to n points at rho 0.75), random.
        #[arg(long, default_value = "ours", value_parser = ["ours", "ours-scan", "lloyd", "dart", "random"])]
        method: String,
        /// Points per set.
        #[arg(long, default_value_t = 4096)]
        n: usize,
        /// Point sets.
        #[arg(long, default_value_t = 10)]
        sets: usize,
        /// Seed: set k uses ChaCha8 stream k of it.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Gradient-ascent sweeps (ours, ours-scan).
        #[arg(long, default_value_t = 10)]
        iterations: usize,
        /// Gradient-ascent step of eq. 11 in kernel units (ours, ours-scan).
        #[arg(long, default_value_t = 0.55)]
        step: f64,
        /// Largest move per sweep in units of sigma (ours, ours-scan).
        #[arg(long, default_value_t = 0.25)]
        max_move: f64,
        /// Not in the paper: points whose measure s is below S_REF take steps S_REF / s times
        /// longer (at most 1000x, still bounded by --max-move) (ours, ours-scan).
        #[arg(long, value_name = "S_REF")]
        small_s_boost: Option<f64>,
        /// Lloyd iterations.
        #[arg(long, default_value_t = 100)]
        lloyd_iterations: usize,
        /// Dart throwing's minimum distance over d_max.
        #[arg(long, default_value_t = 0.75)]
        dart_rho: f64,
        /// Periodogram half-width in integer frequencies (default round(2 sqrt(n))).
        #[arg(long)]
        half_width: Option<usize>,
        /// Write the report as JSON to this file.
        #[arg(long, value_name = "FILE.json")]
        output: Option<PathBuf>,
        /// Print nothing but errors.
        #[arg(short, long)]
        quiet: bool,
    },
    /// The reconstruction experiment of Sec. 7.2 (Table 2): per model and sigma_p, the RIMLS
    /// surface of all points against that of a subset chosen by the linear scan (same kernel)
    /// and by the baselines at the same count; RMS and Hausdorff distances in bbox-100 units.
    ReconstructEval {
        /// Meshes (.obj, .ply, .gltf, .glb): normalized to bbox 100 and oriented outward.
        #[arg(required = true)]
        models: Vec<PathBuf>,
        /// Kernel widths sigma_p, bbox-100 units, for sampling and reconstruction alike.
        #[arg(long, value_delimiter = ',', default_value = "0.5,0.75,1")]
        sigma_p: Vec<f64>,
        /// Normal width sigma_n.
        #[arg(long, default_value_t = 0.75)]
        sigma_n: f64,
        /// Input points: area-uniform random points this far apart on average (bbox-100 units),
        /// with interpolated vertex normals. Default: the mesh's vertices.
        #[arg(long)]
        spacing: Option<f64>,
        /// With --spacing: the points' normals keep the mesh's edges sharper than this many
        /// degrees sharp (corner normals with a crease angle) instead of averaging across them.
        #[arg(long, value_name = "DEG", requires = "spacing")]
        crease_angle: Option<f64>,
        /// Skip the second reconstruction of every subset, with the weights of the points it
        /// dropped as masses (Sec. 5 of the paper).
        #[arg(long)]
        no_weights: bool,
        /// Subsamplers (ours is required: it sets the count).
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "ours,random,voxel,poisson"
        )]
        methods: Vec<String>,
        /// Marching-cubes cell in units of sigma_p.
        #[arg(long, default_value_t = 0.5)]
        cell: f64,
        /// Restricted domain of the reconstructions, in units of sigma_p: surface farther than
        /// this from every point is dropped (0: none). The distances without it are reported
        /// too.
        #[arg(long, default_value_t = 1.5)]
        domain: f64,
        /// Random samples per side of each distance (on top of the vertices).
        #[arg(long, default_value_t = 200_000)]
        samples: usize,
        /// Seed of the points, the visit orders and the distance sampling.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Runs of every subsampler with different seeds, against the same all-points surface.
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Write the results as JSON to this file.
        #[arg(long, value_name = "FILE.json")]
        json: Option<PathBuf>,
        /// Write every reconstruction into this folder (binary PLY, bbox-100 units).
        #[arg(long, value_name = "DIR")]
        meshes: Option<PathBuf>,
        /// Print nothing but errors.
        #[arg(short, long)]
        quiet: bool,
    },
}

/// Writes a JSON report atomically (a temporary file beside it, then a rename).
fn write_report(path: &Path, json: &str) -> Result<(), Error> {
    spectral_remesh::internal::write_atomically(path, |w| w.write_all(json.as_bytes()))
}

/// Writes to standard output. A reader that went away (`... | head`) is not an error: the
/// report file is already written, so the rest of the summary is dropped quietly.
fn emit(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes()).and_then(|_| out.flush());
}

fn run(cli: Cli) -> Result<(), Error> {
    match &cli.command {
        Command::BlueNoise {
            method,
            n,
            sets,
            seed,
            iterations,
            step,
            max_move,
            small_s_boost,
            lloyd_iterations,
            dart_rho,
            half_width,
            output,
            quiet,
        } => {
            use spectral_experiments::plane::{run_blue_noise, BlueNoiseParams, Method};
            let method = Method::parse(method).ok_or_else(|| Error::InvalidParameter {
                name: "--method",
                message: format!("unknown method {method}"),
            })?;
            let mut params = BlueNoiseParams::new(method);
            params.n = *n;
            params.sets = *sets;
            params.seed = *seed;
            params.ascent.iterations = *iterations;
            params.ascent.step = *step;
            params.ascent.max_move = *max_move;
            params.ascent.small_s_boost = *small_s_boost;
            params.lloyd_iterations = *lloyd_iterations;
            params.dart_rho = *dart_rho;
            params.half_width = *half_width;
            let t = std::time::Instant::now();
            let r = run_blue_noise(&params)?;
            if let Some(p) = output {
                write_report(p, &r.to_json())?;
            }
            if !quiet {
                let s = &r.summary;
                let gen: f64 = r.generate_seconds.iter().sum();
                let mut text = format!(
                    "{}: {} sets of {} points (seed {})\n\
                     rho mean {:.4} min {:.4} max {:.4}\n\
                     low-frequency power (< 0.5 sqrt(n)) max {:.4}; peak {:.3} at {:.3} sqrt(n)\n\
                     anisotropy beyond the peak {:.2} to {:.2} dB (noise floor {:.2} dB)\n\
                     seconds: generate {:.2} ({:.3} per set), analysis {:.2}, total {:.2}\n",
                    r.method,
                    r.sets,
                    r.n,
                    r.seed,
                    r.rho_mean,
                    r.rho_min,
                    r.rho_max,
                    s.low_frequency_max,
                    s.peak_power,
                    s.peak_frequency,
                    s.anisotropy_beyond_peak_db.0,
                    s.anisotropy_beyond_peak_db.1,
                    s.noise_floor_db,
                    gen,
                    gen / r.sets as f64,
                    r.analysis_seconds,
                    t.elapsed().as_secs_f64()
                );
                for note in &r.notes {
                    text += &format!("note: {note}\n");
                }
                emit(&text);
            }
            Ok(())
        }
        Command::ReconstructEval {
            models,
            sigma_p,
            sigma_n,
            spacing,
            crease_angle,
            no_weights,
            methods,
            cell,
            domain,
            samples,
            seed,
            repeats,
            json,
            meshes,
            quiet,
        } => {
            let mut parsed = Vec::new();
            for m in methods {
                parsed.push(
                    Subsampler::from_name(m).ok_or_else(|| Error::InvalidParameter {
                        name: "--methods",
                        message: format!("unknown method {m:?} (ours, random, voxel, poisson)"),
                    })?,
                );
            }
            let params = ReconstructionEvalParams {
                sigma_p: sigma_p.clone(),
                sigma_n: *sigma_n,
                source: match spacing {
                    Some(s) => PointSource::Surface {
                        spacing: *s,
                        normals: match crease_angle {
                            Some(a) => NormalField::Crease { angle_deg: *a },
                            None => NormalField::Smooth,
                        },
                    },
                    None => PointSource::Vertices,
                },
                methods: parsed,
                cell_per_sigma: *cell,
                domain: *domain,
                distance_samples: *samples,
                seed: *seed,
                repeats: *repeats,
                weighted: !*no_weights,
                mesh_dir: meshes.clone(),
                ..Default::default()
            };
            if let Some(dir) = meshes {
                std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
            }
            let progress = |line: &str| {
                if !*quiet {
                    eprintln!("{line}");
                }
            };
            let mut results = Vec::new();
            for m in models {
                results.push(evaluate_model(m, &params, &progress)?);
            }
            if let Some(p) = json {
                let text = serde_json::to_string_pretty(&results).map_err(|e| Error::Internal {
                    stage: "report",
                    message: e.to_string(),
                })?;
                write_report(p, &text)?;
            }
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("spectral-experiments: error: {e}");
            ExitCode::from(e.exit_code() as u8)
        }
    }
}
