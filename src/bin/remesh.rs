//! `remesh`: the command line. Parses flags into a validated job, calls the library, prints the
//! report, and maps errors to exit codes (2 usage, 3 input, 4 output, 1 internal).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use spectral_remesh::app::{run_quality, run_remesh, RemeshJob};
use spectral_remesh::pipeline::{Density, RemeshParams};
use spectral_remesh::Error;

const EXAMPLES: &str = "\
Examples:
  remesh data/spot.obj spot-3k.obj --points 3000
  remesh horse.ply horse.glb --points 8600 --report horse.json
  remesh fandisk.obj fandisk.obj.ply --points 6000 --sigma-n 0.75
  remesh quality out.obj --ref in.obj
  remesh points horse.obj horse-14M.ply --count 14000000
  remesh simplify horse-14M.ply horse-300k.ply --points 300000
  remesh simplify scan.xyz levels.ply --levels 4,2,1";

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
