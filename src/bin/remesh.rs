//! `remesh`: the command line. Parses flags into a validated job, calls the library, prints the
//! report, and maps errors to exit codes (2 usage, 3 input, 4 output, 1 internal).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use spectral_remesh::app::{run_quality, run_remesh, RemeshJob};
use spectral_remesh::pipeline::{Density, RemeshParams};
use spectral_remesh::points::generate::NormalField;
use spectral_remesh::points::subsample::Subsampler;
use spectral_remesh::reconstruction_eval::{evaluate_model, PointSource, ReconstructionEvalParams};
use spectral_remesh::Error;

const EXAMPLES: &str = "\
Examples:
  remesh data/spot.obj spot-3k.obj --points 3000
  remesh horse.ply horse.glb --points 8600 --report horse.json
  remesh fandisk.obj fandisk.obj.ply --points 6000 --sigma-n 0.75
  remesh quality out.obj --ref in.obj
  remesh points horse.obj horse-14M.ply --count 14000000
  remesh simplify horse-14M.ply horse-300k.ply --points 300000
  remesh simplify scan.xyz levels.ply --levels 4,2,1
  remesh blue-noise --method ours --output ours.json
  remesh reconstruct-eval horse.obj fandisk.obj --spacing 0.15 --json table2.json";

/// Spectral remeshing of triangle meshes (Öztireli, Alexa, Gross 2010: Spectral Sampling of
/// Manifolds): samples the input surface with the spectral measure, triangulates the samples,
/// writes the mesh and prints a quality report.
#[derive(Parser, Debug)]
#[command(name = "remesh", version, after_help = EXAMPLES)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,

    /// Input mesh: .obj, .ply, .gltf or .glb.
    #[arg(required = true)]
    input: Option<PathBuf>,

    /// Output mesh: .obj, .ply or .glb (format by extension).
    #[arg(required = true)]
    output: Option<PathBuf>,

    /// Number of output vertices (within 1%); sigma_p is searched for and printed. Default: the
    /// input's vertex count.
    #[arg(long, conflicts_with = "sigma_p")]
    points: Option<usize>,

    /// Kernel width sigma_p in bbox-100 units (the model is scaled so its longest side is 100),
    /// instead of --points.
    #[arg(long)]
    sigma_p: Option<f64>,

    /// Normal width sigma_n: finite values turn on feature-adaptive sampling (more samples where
    /// normals vary; 0.5 to 1 is typical). Default: infinity (isotropic).
    #[arg(long)]
    sigma_n: Option<f64>,

    /// Gradient-ascent sweeps (Sec. 6.2).
    #[arg(long, default_value_t = 10)]
    iterations: usize,

    /// Seed of every random choice: the same seed gives the same output, byte for byte.
    #[arg(long, default_value_t = 1)]
    seed: u64,

    /// Write the quality report as JSON to this file.
    #[arg(long, value_name = "FILE.json")]
    report: Option<PathBuf>,

    /// Skip the distance to the input (Hausdorff, RMS) in the report.
    #[arg(long)]
    no_distance: bool,

    /// Fail (exit 1, nothing written) when the output breaks an invariant (manifold, oriented,
    /// no degenerate, duplicate or self-intersecting faces) instead of reporting it.
    #[arg(long)]
    strict: bool,

    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Report on any mesh: Table 1 triangle measures, topology, and with --ref the distance to a
    /// reference surface.
    Quality {
        /// The mesh to measure.
        mesh: PathBuf,
        /// The reference (usually the input of a remesher); sets the bbox-100 frame.
        #[arg(long = "ref")]
        reference: Option<PathBuf>,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// Also write the JSON report to this file.
        #[arg(long, value_name = "FILE.json")]
        report: Option<PathBuf>,
        /// Seed of the distance sampling.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Simplify a point set (PLY) out of core with the randomized linear scan (Sec. 6.1):
    /// memory bounded by the output plus a fixed buffer. Writes the samples as PLY with normals.
    Simplify {
        /// The input point set: .ply (ascii or binary) or XYZ/CSV text (.xyz .csv .txt .pts:
        /// `x y z` or `x y z nx ny nz` per line, or named columns), with or without normals.
        input: PathBuf,
        /// The output point set (.ply).
        output: PathBuf,
        /// About this many output points (sigma_p is searched on a random subset).
        #[arg(long, conflicts_with_all = ["sigma_p", "levels"])]
        points: Option<usize>,
        /// Kernel width sigma_p in bbox-100 units, instead of --points.
        #[arg(long, conflicts_with = "levels")]
        sigma_p: Option<f64>,
        /// Progressive sampling (Sec. 6.4): sigma_p values in bbox-100 units (`4,2,1`), one nested
        /// level each, coarsest first: P1 ⊂ P2 ⊂ …. The output is ordered by level and has a
        /// `uchar level` property (1 = coarsest), so the first |P_l| points are P_l.
        #[arg(long, value_delimiter = ',', value_name = "S1,S2,...")]
        levels: Option<Vec<f64>>,
        /// Normal width sigma_n (default: infinity, positions only).
        #[arg(long)]
        sigma_n: Option<f64>,
        /// After the scan, K sweeps of gradient-ascent resampling (Sec. 6.2; 10 is typical), each
        /// move projected onto the RIMLS surface of the input (same sigma_p, sigma_n).
        #[arg(long, value_name = "K", default_value_t = 0, conflicts_with = "levels")]
        resample: usize,
        /// Seed of the visit order.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// For an input without normals: orient the estimated normals towards this point
        /// (`x,y,z`, model units; a single scan's sensor) instead of outward by a spanning tree.
        #[arg(long, value_name = "X,Y,Z", value_parser = parse_point)]
        viewpoint: Option<[f64; 3]>,
        /// Print nothing but errors.
        #[arg(short, long)]
        quiet: bool,
    },
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
    /// Draw random points with normals uniformly by area from a mesh's surface and write them as
    /// binary PLY (streamed: any count fits in memory). Makes large point-cloud inputs.
    Points {
        /// The mesh to draw from (.obj, .ply, .gltf, .glb).
        mesh: PathBuf,
        /// The output point set (.ply).
        output: PathBuf,
        /// How many points.
        #[arg(long)]
        count: u64,
        /// Seed of the random draw.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

/// Writes a JSON report atomically (a temporary file beside it, then a rename).
fn write_report(path: &PathBuf, json: &str) -> Result<(), Error> {
    spectral_remesh::io::write_atomically(path, |w| w.write_all(json.as_bytes()))
}

/// Writes to standard output. A reader that went away (`remesh ... | head`) is not an error:
/// the output file is already written, so the rest of the report is dropped quietly.
fn emit(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes()).and_then(|_| out.flush());
}

fn run(cli: Cli) -> Result<(), Error> {
    if let Some(Command::BlueNoise {
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
    }) = &cli.command
    {
        use spectral_remesh::plane::{run_blue_noise, BlueNoiseParams, Method};
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
        return Ok(());
    }
    if let Some(Command::Simplify {
        input,
        output,
        points,
        sigma_p,
        levels,
        sigma_n,
        resample,
        seed,
        viewpoint,
        quiet,
    }) = &cli.command
    {
        let density = match (points, sigma_p, levels) {
            (Some(n), _, _) => PointDensity::Points(*n),
            (_, Some(s), _) => PointDensity::SigmaP(*s),
            (_, _, Some(l)) => PointDensity::Levels(l.clone()),
            _ => {
                return Err(Error::InvalidParameter {
                    name: "--points",
                    message: "give --points N, --sigma-p S or --levels S1,S2,...".into(),
                })
            }
        };
        return run_simplify(
            input, output, density, *sigma_n, *resample, *seed, *viewpoint, *quiet,
        );
    }
    if let Some(Command::ReconstructEval {
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
    }) = &cli.command
    {
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
        return Ok(());
    }
    if let Some(Command::Points {
        mesh,
        output,
        count,
        seed,
    }) = &cli.command
    {
        let (m, _) = spectral_remesh::io::read_mesh(mesh)?;
        return spectral_remesh::points::generate::write_surface_points(&m, *count, *seed, output);
    }
    if let Some(Command::Quality {
        mesh,
        reference,
        json,
        report,
        seed,
    }) = cli.command
    {
        let r = run_quality(&mesh, reference.as_deref(), seed)?;
        if json {
            emit(&format!("{}\n", r.to_json()));
        } else {
            emit(&r.to_string());
        }
        if let Some(p) = report {
            write_report(&p, &r.to_json())?;
        }
        return Ok(());
    }
    let (Some(input), Some(output)) = (cli.input, cli.output) else {
        return Err(Error::InvalidParameter {
            name: "INPUT OUTPUT",
            message: "both are required (see --help)".into(),
        });
    };
    let density = match (cli.points, cli.sigma_p) {
        (Some(n), None) => Density::Points(n),
        (None, Some(s)) => Density::SigmaP(s),
        _ => Density::InputVertices,
    };
    if cli.points == Some(0) {
        return Err(Error::InvalidParameter {
            name: "--points",
            message: "must be at least 4".into(),
        });
    }
    if std::env::var_os("REMESH_INJECT_PANIC").is_some() {
        // For the test of the panic path (tests/bad_input.rs): a bug's way out, on demand.
        panic!("injected by REMESH_INJECT_PANIC");
    }
    let mut params = RemeshParams {
        density,
        seed: cli.seed,
        ..Default::default()
    };
    params.gradient_ascent.iterations = cli.iterations;
    if let Some(s) = cli.sigma_n {
        params.sigma_n = s;
    }
    let job = RemeshJob {
        input,
        output,
        params,
        measure_distance: !cli.no_distance,
        strict: cli.strict,
    };
    let bar = if cli.quiet {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("{spinner} {msg} {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        b.enable_steady_tick(Duration::from_millis(120));
        b
    };
    let result = run_remesh(&job, &|stage: &str| bar.set_message(stage.to_string()));
    bar.finish_and_clear();
    let report = result?;
    if !cli.quiet {
        emit(&format!(
            "{} -> {}\n{report}",
            job.input.display(),
            job.output.display()
        ));
    }
    if let Some(p) = cli.report {
        write_report(&p, &report.to_json())?;
    }
    Ok(())
}

fn parse_point(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("expected x,y,z: {e}"))?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([*x, *y, *z]),
        _ => Err("expected three finite numbers x,y,z".into()),
    }
}

/// The output density of `remesh simplify`.
enum PointDensity {
    Points(usize),
    SigmaP(f64),
    Levels(Vec<f64>),
}

#[allow(clippy::too_many_arguments)]
fn run_simplify(
    input: &std::path::Path,
    output: &std::path::Path,
    density: PointDensity,
    sigma_n: Option<f64>,
    resample: usize,
    seed: u64,
    viewpoint: Option<[f64; 3]>,
    quiet: bool,
) -> Result<(), Error> {
    use spectral_remesh::points::normals::Orientation;
    use spectral_remesh::points::out_of_core::{
        simplify_out_of_core, simplify_progressive, OutOfCoreParams,
    };
    use spectral_remesh::points::PlyPointWriter;
    if matches!(density, PointDensity::Points(0)) {
        return Err(Error::InvalidParameter {
            name: "--points",
            message: "must be at least 1".into(),
        });
    }
    let orientation = match viewpoint {
        Some([x, y, z]) => Orientation::Viewpoint(glam::DVec3::new(x, y, z)),
        None => Orientation::SpanningTree,
    };
    let params = OutOfCoreParams {
        resample,
        orientation,
        target: match density {
            PointDensity::Points(n) => Some(n),
            _ => None,
        },
        sigma_p: match density {
            PointDensity::SigmaP(s) => s,
            _ => 1.0,
        },
        sigma_n: sigma_n.unwrap_or(f64::INFINITY),
        seed,
        ..Default::default()
    };
    let t = std::time::Instant::now();
    if sigma_n.is_some_and(f64::is_finite) {
        let reader = spectral_remesh::points::PointReader::open(input)?;
        if !reader.has_normals() {
            return Err(Error::InvalidParameter {
                name: "--sigma-n",
                message: format!("{} has no normals; sigma_n needs them", input.display()),
            });
        }
    }
    let no_normals_note =
        "; the input has no normals: positions only, normals estimated on the output";
    if let PointDensity::Levels(levels) = &density {
        let r = simplify_progressive(input, levels, &params)?;
        let mut w = PlyPointWriter::create_with_levels(output, r.samples.len() as u64)?;
        w.write_levels(&r.samples, &r.levels)?;
        w.finish()?;
        if !quiet {
            let mut text = format!(
                "{} -> {}: {} points -> {} samples in {} nested levels{}\n",
                input.display(),
                output.display(),
                r.input_points,
                r.samples.len(),
                r.level_ends.len(),
                if r.had_normals { "" } else { no_normals_note }
            );
            for (l, (&end, s)) in r.level_ends.iter().zip(&r.sigma_p).enumerate() {
                let start = if l == 0 { 0 } else { r.level_ends[l - 1] };
                text += &format!(
                    "  level {}: sigma_p {s:.4}, |P{}| = {end} (+{}), {:.2} s\n",
                    l + 1,
                    l + 1,
                    end - start,
                    r.seconds[l + 1]
                );
            }
            text += &format!(
                "seconds: read+bucket {:.2}, total {:.2}\n",
                r.seconds[0],
                t.elapsed().as_secs_f64()
            );
            emit(&text);
        }
        return Ok(());
    }
    let r = simplify_out_of_core(input, &params)?;
    let mut w = PlyPointWriter::create(output, r.samples.len() as u64)?;
    w.write(&r.samples)?;
    w.finish()?;
    if !quiet {
        emit(&format!(
            "{} -> {}: {} points -> {} samples, sigma_p {:.4} (bbox-100 units){}; {} rejected by the nearest sample, {} measured\n\
             seconds: read+bucket {:.2}, sigma_p search {:.2}, scan {:.2}, normals+resample {:.2}, total {:.2}\n",
            input.display(),
            output.display(),
            r.input_points,
            r.samples.len(),
            r.sigma_p,
            if r.had_normals { "" } else { no_normals_note },
            r.rejected_by_nearest,
            r.measured,
            r.seconds[0],
            r.seconds[1],
            r.seconds[2],
            r.seconds[3],
            t.elapsed().as_secs_f64()
        ));
    }
    Ok(())
}

/// Where the last panic happened and what it said, kept by the panic hook for `main`.
static PANIC: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

fn main() -> ExitCode {
    let cli = Cli::parse();
    // A panic is a bug: it still ends in one line and the internal-failure exit code, with
    // where it happened, instead of the default multi-line message.
    std::panic::set_hook(Box::new(|info| {
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown cause".into());
        let place = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        if let Ok(mut p) = PANIC.lock() {
            *p = Some(format!("{message}{place}"));
        }
    }));
    match std::panic::catch_unwind(|| run(cli)) {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(e)) => {
            eprintln!("remesh: error: {e}");
            ExitCode::from(e.exit_code() as u8)
        }
        Err(_) => {
            let what = PANIC
                .lock()
                .ok()
                .and_then(|p| p.clone())
                .unwrap_or_else(|| "unknown cause".into());
            let e = Error::Internal {
                stage: "panic",
                message: format!("{} (a bug: please report it)", what.replace('\n', " ")),
            };
            eprintln!("remesh: error: {e}");
            ExitCode::from(e.exit_code() as u8)
        }
    }
}
