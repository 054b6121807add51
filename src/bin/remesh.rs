//! `remesh`: the command line. Parses flags into a validated [`Config`], runs it with one library
//! call per subcommand, prints, and maps errors to exit codes (2 usage, 3 input, 4 output,
//! 1 internal). All work lives in the library (`spectral_remesh::run_remesh` and the other jobs).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use clap::{CommandFactory, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use spectral_remesh::internal::{
    catch_panics, check_report_path, effective_memory_limit, parse_bytes, remove_temporaries,
    run_points, run_simplify, write_report, PointsJob, SimplifyDensity, SimplifyJob, STDOUT,
};
use spectral_remesh::{run_quality, run_remesh, Error, MeshFormat, RemeshJob, RemeshOptions};

const EXAMPLES: &str = "\
Examples:
  remesh data/spot.obj spot-3k.obj --points 3000
  remesh horse.ply horse.glb --points 8600 --report horse.json
  remesh fandisk.obj fandisk.obj.ply --points 6000 --sigma-n 0.75
  remesh cow.obj - --points 3000 -q | gzip > cow-3k.obj.gz
  remesh cow.obj - --format glb --points 3000 -q > cow-3k.glb
  remesh quality out.obj --ref in.obj
  remesh points horse.obj horse-14M.ply --count 14000000
  remesh horse-14M.ply horse-300k.obj --points 300000
  remesh scan.xyz scan-20k.ply --points 20000
  remesh simplify horse-14M.ply horse-300k.ply --points 300000
  remesh simplify scan.xyz levels.ply --levels 4,2,1";

/// Spectral remeshing of triangle meshes (Öztireli, Alexa, Gross 2010: Spectral Sampling of
/// Manifolds): samples the input surface with the spectral measure, triangulates the samples,
/// writes the mesh and prints a quality report.
#[derive(Parser, Debug)]
#[command(name = "remesh", version, after_help = EXAMPLES)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
#[command(allow_negative_numbers = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,

    /// Input mesh: .obj, .ply, .gltf, .glb, .stl (binary or ascii) or .off; or a point set (a
    /// scan): a .ply without faces, a .pcd (the Point Cloud Library's; its VIEWPOINT is the
    /// sensor), a .las or .laz (LiDAR), an .e57 (laser scans, posed into one frame; a single
    /// scan's sensor is the viewpoint), or text .xyz .xyzn .csv .txt .pts .asc (x y z [nx ny nz]
    /// per line), with or without normals, read out of core (PCD and E57 read whole); it needs
    /// --points or --sigma-p.
    #[arg(required = true)]
    input: Option<PathBuf>,

    /// Output mesh: .obj, .ply, .gltf, .glb, .stl (binary) or .off (format by extension), or -
    /// for standard output
    /// (OBJ unless --format says otherwise; the report then goes to standard error).
    #[arg(required = true)]
    output: Option<PathBuf>,

    /// The format written to standard output (OUTPUT -): obj (the default), ply, gltf, glb, stl or
    /// off. The binary ones (ply, glb, stl) only when asked for, and never to a terminal. With a
    /// file, the format is the extension's, and --format must agree with it.
    #[arg(long, value_enum, value_name = "FORMAT")]
    format: Option<OutputFormat>,

    /// Number of output vertices (within 1%); sigma_p is searched for and printed. Default: the
    /// input's vertex count.
    #[arg(long, conflicts_with = "sigma_p", value_parser = whole::<usize>)]
    points: Option<usize>,

    /// Kernel width sigma_p in bbox-100 units (the model is scaled so its longest side is 100),
    /// instead of --points.
    #[arg(long)]
    sigma_p: Option<f64>,

    /// Output edges about L long, in the input's own units, instead of --points: for a mesh the
    /// count of equilateral triangles of that edge on the input's area, for a point set (whose
    /// area is known only once its surface is) sigma_p = L / 1.2 in bbox-100 units (its
    /// sampling's mean edge is 1.2 sigma_p; printed in the notes).
    #[arg(long, value_name = "L", conflicts_with_all = ["points", "sigma_p"])]
    edge_length: Option<f64>,

    /// Normal width sigma_n: finite values turn on feature-adaptive sampling (more samples where
    /// normals vary; 0.5 to 1 is typical). Default: infinity (isotropic).
    #[arg(long)]
    sigma_n: Option<f64>,

    /// The sizing field (meshes): the spacing follows the local feature size, h(x) = C · lfs(x)
    /// where that is below sigma_p (walls, tubes, holes and gaps narrower than the spacing), in
    /// absolute units: a part thinner than the count resolves gets the samples it needs, and the
    /// count grows (at most 4 times; the report says so, --strict refuses). 2.5 is the bound
    /// of the topological ball property. 0, the default, turns it off (one sigma_p everywhere,
    /// as in the paper).
    #[arg(long, default_value_t = 0.0, value_name = "C")]
    lfs_factor: f64,

    /// Curved parts: the spacing follows the curvature, h = sqrt(8 E sigma_p / curvature), so an
    /// output edge's chord stays within E · sigma_p of the surface, down to half of sigma_p;
    /// flat parts keep sigma_p, and the count stays --points (samples move from flat parts to
    /// curved ones: a lower Hausdorff and RMS distance). 0.003 is the measured choice for CAD
    /// parts (with --feature-angle 20). 0, the default, turns it off.
    #[arg(long, default_value_t = 0.0, value_name = "E")]
    chord_error: f64,

    /// No least-squares vertex placement: the vertices stay on the input, as in the paper. By
    /// default each vertex (not on a boundary or a crease) moves off the input along its normal
    /// so the faces straddle the surface instead of lying under it as chords (the sag's mean,
    /// about 2/3 of its peak): RMS distance about a third lower on curved parts, angles kept
    /// within --min-angle and --max-angle.
    #[arg(long)]
    no_fit: bool,

    /// Iterations of the finishing relaxation: vertices move towards where their triangles
    /// would be equilateral, on the input, with valence flips (Qave about 0.90 without, 0.94
    /// after 10). 0 turns it off (the triangulated samples as the paper leaves them).
    #[arg(
        long,
        default_value_t = spectral_remesh::internal::SMOOTH_ITERATIONS,
        value_name = "N",
        value_parser = whole::<usize>
    )]
    smooth: usize,

    /// The smallest angle the last pass of the optimization works towards, degrees: faces with a
    /// smaller angle get the best of a flip, collapse or move that raises it (where the input
    /// surface allows; the report says the angle reached).
    #[arg(long, default_value_t = 35.0, value_name = "DEG")]
    min_angle: f64,

    /// The largest angle the last pass works towards, degrees (as --min-angle).
    #[arg(long, default_value_t = 100.0, value_name = "DEG")]
    max_angle: f64,

    /// Sharp features: an input edge is a crease when the surface either side of it turns by
    /// at least DEG degrees, between its two faces and still at the sample spacing (so a scan's
    /// folds are not creases); creases are sampled evenly like the boundary and kept as output
    /// edges, every one found. Without it (the default) creases are found at 20° and kept when
    /// they are a part's: at least 90% of their length in curves of 3 sample spacings or more,
    /// or in those and curves from junction to junction when the creases lie more than a
    /// spacing apart and detection at 10° finds at most 1.3 times their length (a scan's folds
    /// come in short pieces among gentler bends and are sampled like the rest; the report says
    /// what decided). 180 turns detection off, as does --no-features.
    #[arg(long, value_name = "DEG", conflicts_with = "no_features")]
    feature_angle: Option<f64>,

    /// No sharp-feature detection: every part of the input is sampled alike.
    #[arg(long)]
    no_features: bool,

    /// How the samples are connected: `restricted`, the default (the restricted Delaunay
    /// triangulation on the input mesh: the dual of the samples' Voronoi cells grown over the
    /// input, which keeps thin parts whole; also `restricted-refined`), `restricted-clipped`
    /// (the same dual, the cells clipped exactly from the input's facets: faster, but it leaves
    /// holes at thin tips that the refined cells close), or `umbrellas` (tangent-plane Delaunay
    /// umbrellas merged by votes, as before).
    #[arg(long, default_value = "restricted", value_name = "METHOD")]
    triangulation: String,

    /// Gradient-ascent sweeps (Sec. 6.2), at most 1000.
    #[arg(long, default_value_t = 10, value_parser = whole::<usize>)]
    iterations: usize,

    /// Seed of every random choice: the same seed gives the same output, byte for byte.
    #[arg(long, default_value_t = 1, value_parser = whole::<u64>)]
    seed: u64,

    /// Write the quality report as JSON to this file (written with the mesh, both only once
    /// the run has succeeded); - prints it on standard output instead of the table.
    #[arg(long, value_name = "FILE.json")]
    report: Option<PathBuf>,

    /// Skip the distance to the input (Hausdorff, RMS) in the report.
    #[arg(long)]
    no_distance: bool,

    /// Fail (exit 1, nothing written) when the output breaks an invariant (manifold, oriented,
    /// no degenerate, duplicate or self-intersecting faces) or its topology (components, Euler
    /// characteristic, boundary loops) differs from the input's, instead of reporting it.
    #[arg(long)]
    strict: bool,

    /// The most memory the job may take (e.g. 512M, 8G, 2GiB): a job whose estimated peak is
    /// larger is refused at once (exit 2), before reading an input file too large for it.
    /// Default: the smallest of the machine's physical memory, the process's control-group
    /// memory limit and its address-space limit (ulimit -v).
    #[arg(long, value_name = "SIZE", value_parser = parse_bytes)]
    max_memory: Option<u64>,

    /// Read a .ply input as a point set, ignoring its faces (a range map, a mesh whose
    /// connectivity is not to be trusted).
    #[arg(long)]
    as_points: bool,

    /// For a point set without normals: orient the estimated normals towards this point
    /// (`x,y,z`, model units; a single scan's sensor) instead of outward by a spanning tree.
    /// Without it, the sensor the file gives is used (a PLY range map's camera `view_px view_py
    /// view_pz`, a PCD's VIEWPOINT, or the sensor of an E57 of one scan) when the points look
    /// seen from there (few lie behind others on its lines of sight).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point)]
    viewpoint: Option<[f64; 3]>,

    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Report on any mesh: Table 1 triangle measures, topology, and with --ref the distance to a
    /// reference surface.
    #[command(allow_negative_numbers = true)]
    Quality {
        /// The mesh to measure.
        mesh: PathBuf,
        /// The reference (usually the input of a remesher); sets the bbox-100 frame.
        #[arg(long = "ref")]
        reference: Option<PathBuf>,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// Also write the JSON report to this file (- : on standard output, as --json).
        #[arg(long, value_name = "FILE.json")]
        report: Option<PathBuf>,
        /// Seed of the distance sampling.
        #[arg(long, default_value_t = 1, value_parser = whole::<u64>)]
        seed: u64,
    },
    /// Simplify a point set (PLY) out of core with the randomized linear scan (Sec. 6.1):
    /// memory bounded by the output plus a fixed buffer. Writes the samples as PLY with normals.
    #[command(allow_negative_numbers = true)]
    Simplify {
        /// The input point set: .ply (ascii or binary), .pcd (ascii, binary or
        /// binary_compressed), .las, .laz, .e57 or XYZ/CSV text (.xyz .xyzn .csv .txt .pts .asc:
        /// `x y z` or `x y z nx ny nz` per line, or named columns), with or without normals.
        input: PathBuf,
        /// The output point set (.ply; not - : point sets need a file).
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
        #[arg(
            long,
            value_name = "K",
            default_value_t = 0,
            conflicts_with = "levels",
            value_parser = whole::<usize>
        )]
        resample: usize,
        /// Seed of the visit order.
        #[arg(long, default_value_t = 1, value_parser = whole::<u64>)]
        seed: u64,
        /// For an input without normals: orient the estimated normals towards this point
        /// (`x,y,z`, model units; a single scan's sensor) instead of outward by a spanning tree.
        /// Without it, the sensor the file gives is used (a PLY range map's camera `view_px
        /// view_py view_pz`, a PCD's VIEWPOINT, or the sensor of an E57 of one scan) when the
        /// points look seen from there (few lie behind others on its lines of sight).
        #[arg(long, value_name = "X,Y,Z", value_parser = parse_point)]
        viewpoint: Option<[f64; 3]>,
        /// Print nothing but errors.
        #[arg(short, long)]
        quiet: bool,
    },
    /// Draw random points with normals uniformly by area from a mesh's surface and write them as
    /// binary PLY (streamed: any count fits in memory). Makes large point-cloud inputs.
    #[command(allow_negative_numbers = true)]
    Points {
        /// The mesh to draw from (.obj, .ply, .gltf, .glb, .stl, .off).
        mesh: PathBuf,
        /// The output point set (.ply; not - : point sets need a file).
        output: PathBuf,
        /// How many points.
        #[arg(long, value_parser = whole::<u64>)]
        count: u64,
        /// Seed of the random draw.
        #[arg(long, default_value_t = 1, value_parser = whole::<u64>)]
        seed: u64,
        /// Print nothing but errors (taken as the other commands take it; this one prints
        /// nothing else).
        #[arg(short, long)]
        quiet: bool,
    },
}

/// The formats `--format` names.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum OutputFormat {
    Obj,
    Ply,
    Gltf,
    Glb,
    Stl,
    Off,
}

impl From<OutputFormat> for MeshFormat {
    fn from(f: OutputFormat) -> MeshFormat {
        match f {
            OutputFormat::Obj => MeshFormat::Obj,
            OutputFormat::Ply => MeshFormat::Ply,
            OutputFormat::Gltf => MeshFormat::Gltf,
            OutputFormat::Glb => MeshFormat::Glb,
            OutputFormat::Stl => MeshFormat::Stl,
            OutputFormat::Off => MeshFormat::Off,
        }
    }
}

/// A validated command: what to run and how to print it.
enum Config {
    Remesh {
        job: Box<RemeshJob>,
        quiet: bool,
        /// The JSON report on standard output instead of the table (`--report -`).
        json: bool,
    },
    Quality {
        mesh: PathBuf,
        reference: Option<PathBuf>,
        seed: u64,
        json: bool,
        report: Option<PathBuf>,
    },
    Simplify {
        job: SimplifyJob,
        quiet: bool,
    },
    Points(PointsJob),
}

/// The flags as a [`Config`].
///
/// # Errors
/// [`Error::InvalidParameter`] for flags that clap's own checks let through but that make no job.
fn config(mut cli: Cli) -> Result<Config, Error> {
    match cli.command.take() {
        Some(Command::Quality {
            mesh,
            reference,
            json,
            report,
            seed,
        }) => {
            // `--report -`: the JSON report on standard output, as --json.
            let to_stdout = report.as_deref() == Some(Path::new(STDOUT));
            Ok(Config::Quality {
                mesh,
                reference,
                seed,
                json: json || to_stdout,
                report: report.filter(|_| !to_stdout),
            })
        }
        Some(Command::Simplify {
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
        }) => {
            let density = match (points, sigma_p, levels) {
                (Some(n), _, _) => SimplifyDensity::Points(n),
                (_, Some(s), _) => SimplifyDensity::SigmaP(s),
                (_, _, Some(l)) => SimplifyDensity::Levels(l),
                _ => {
                    return Err(Error::InvalidParameter {
                        name: "points",
                        message: "give --points N, --sigma-p S or --levels S1,S2,...".into(),
                    })
                }
            };
            let job = SimplifyJob {
                input,
                output,
                density,
                sigma_n,
                resample,
                seed,
                viewpoint: viewpoint.map(glam::DVec3::from),
            };
            Ok(Config::Simplify { job, quiet })
        }
        Some(Command::Points {
            mesh,
            output,
            count,
            seed,
            quiet: _,
        }) => Ok(Config::Points(PointsJob {
            mesh,
            output,
            count,
            seed,
        })),
        None => {
            let (Some(input), Some(output)) = (cli.input.take(), cli.output.take()) else {
                return Err(Error::InvalidParameter {
                    name: "INPUT OUTPUT",
                    message: "both are required (see --help)".into(),
                });
            };
            let params = remesh_options(&cli).params()?;
            let job = RemeshJob {
                input,
                output,
                format: cli.format.map(MeshFormat::from),
                params,
                measure_distance: !cli.no_distance,
                strict: cli.strict,
                max_memory: effective_memory_limit(cli.max_memory),
                as_points: cli.as_points,
                viewpoint: cli.viewpoint.map(glam::DVec3::from),
                report: cli.report,
            };
            // `--report -`: the JSON report on standard output, in place of the table.
            let mut job = job;
            let json = job.report.as_deref() == Some(Path::new(STDOUT));
            if json {
                if job.output.as_os_str() == STDOUT {
                    return Err(Error::InvalidParameter {
                        name: "report",
                        message: "- (standard output) is where the mesh goes (OUTPUT -); give \
                                  the report a file"
                            .into(),
                    });
                }
                job.report = None;
            }
            Ok(Config::Remesh {
                job: Box::new(job),
                quiet: cli.quiet,
                json,
            })
        }
    }
}

/// The pipeline options of `remesh INPUT OUTPUT` (checked by [`RemeshOptions::params`]).
fn remesh_options(cli: &Cli) -> RemeshOptions {
    RemeshOptions {
        points: cli.points,
        sigma_p: cli.sigma_p,
        edge_length: cli.edge_length,
        sigma_n: cli.sigma_n,
        lfs_factor: cli.lfs_factor,
        chord_error: cli.chord_error,
        no_fit: cli.no_fit,
        smooth: cli.smooth,
        min_angle: cli.min_angle,
        max_angle: cli.max_angle,
        feature_angle: cli.feature_angle,
        no_features: cli.no_features,
        triangulation: cli.triangulation.clone(),
        iterations: cli.iterations,
        seed: cli.seed,
    }
}

/// Runs a [`Config`]: one library call, then what it prints and the JSON report.
fn execute(config: Config) -> Result<(), Error> {
    match config {
        Config::Remesh { job, quiet, json } => {
            let bar = progress(quiet);
            let result = run_remesh(&job, &|stage: &str| bar.set_message(stage.to_string()));
            bar.finish_and_clear();
            let r = result?;
            if json {
                emit(&format!("{}\n", r.to_json()));
            } else if !quiet {
                // With the mesh on standard output, the report goes to standard error.
                let to_stdout = job.output.as_os_str() == STDOUT;
                let text = format!(
                    "{} -> {}\n{r}",
                    job.input.display(),
                    if to_stdout {
                        "standard output".into()
                    } else {
                        job.output.display().to_string()
                    }
                );
                if to_stdout {
                    eprint!("{text}");
                } else {
                    emit(&text);
                }
            }
            Ok(())
        }
        Config::Quality {
            mesh,
            reference,
            seed,
            json,
            report,
        } => {
            if let Some(p) = &report {
                let mut others = vec![(mesh.as_path(), "the mesh to report on")];
                if let Some(r) = &reference {
                    others.push((r.as_path(), "the reference mesh"));
                }
                check_report_path(p, &others)?;
            }
            let r = run_quality(&mesh, reference.as_deref(), seed)?;
            emit(&if json {
                format!("{}\n", r.to_json())
            } else {
                r.to_string()
            });
            report.map_or(Ok(()), |p| write_report(&p, &r))
        }
        Config::Simplify { job, quiet } => {
            let summary = run_simplify(&job)?;
            if !quiet {
                emit(&summary.to_string());
            }
            Ok(())
        }
        Config::Points(job) => run_points(&job),
    }
}

/// A spinner with the current stage on standard error, or a hidden one.
fn progress(quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    b.set_style(
        ProgressStyle::with_template("{spinner} {msg} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    b.enable_steady_tick(Duration::from_millis(120));
    b
}

/// Writes to standard output. A reader that went away (`remesh ... | head`) is not an error:
/// the output file is already written, so the rest of the report is dropped quietly.
fn emit(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes()).and_then(|_| out.flush());
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

/// A whole number of type `T` (a count, a seed), with a message that says so for a negative
/// or fractional one.
fn whole<T: std::str::FromStr>(s: &str) -> Result<T, String> {
    s.trim()
        .parse::<T>()
        .map_err(|_| format!("must be a whole number >= 0, got {s}"))
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                e.exit();
            }
            // One line, as every other error: clap's message up to its tips and usage.
            let text = e.to_string();
            let message: Vec<&str> = text
                .lines()
                .take_while(|l| !l.trim().is_empty())
                .map(str::trim)
                .collect();
            let message = message.join(" ");
            let message = message.strip_prefix("error: ").unwrap_or(&message);
            eprintln!("remesh: error: {message} (see --help)");
            return ExitCode::from(2);
        }
    };
    // Interrupted (SIGINT, SIGTERM, SIGHUP): the temporary files and bucket folders of the run
    // are removed and the target stays as it was. Exit 130, as a shell reports an interrupt.
    let _ = ctrlc::set_handler(|| {
        remove_temporaries();
        eprintln!("remesh: interrupted; temporary files removed, nothing written");
        std::process::exit(130);
    });
    match catch_panics(|| config(cli).and_then(execute)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line whatever a file name holds: control characters (a newline) escaped.
            let mut message = String::new();
            for c in command_line_text(&e).chars() {
                if c.is_control() {
                    message.extend(c.escape_default());
                } else {
                    message.push(c);
                }
            }
            eprintln!("remesh: error: {message}");
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

/// An error as the command line says it: the library names parameters as they are spelled in
/// Rust and Python (`sigma_p`), the command line by their flags (`--sigma-p`): the parameter of an
/// [`Error::InvalidParameter`], and each parameter its message names in backticks, becomes the
/// flag of that name when the command line has one.
fn command_line_text(e: &Error) -> String {
    let cli = Cli::command();
    let flags: Vec<String> = cli
        .get_arguments()
        .chain(cli.get_subcommands().flat_map(|s| s.get_arguments()))
        .filter_map(|a| a.get_long().map(str::to_string))
        .collect();
    let flag = |name: &str| {
        let long = name.replace('_', "-");
        let plain = name.chars().all(|c| c.is_ascii_lowercase() || c == '_');
        (plain && flags.contains(&long)).then(|| format!("--{long}"))
    };
    let text = match e {
        Error::InvalidParameter { name, message } => {
            let name = flag(name).unwrap_or_else(|| name.to_string());
            format!("invalid parameter {name}: {message}")
        }
        _ => e.to_string(),
    };
    let mut out = String::new();
    let mut rest = text.as_str();
    while let Some(i) = rest.find('`') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        match after
            .find('`')
            .and_then(|j| flag(&after[..j]).map(|f| (j, f)))
        {
            Some((j, f)) => {
                out.push_str(&f);
                rest = &after[j + 1..];
            }
            None => {
                out.push('`');
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The library's [`RemeshOptions::default`] (which the Python bindings use) is the command
    /// line's defaults, and every flag reaches its field.
    #[test]
    fn option_defaults_are_the_command_lines() {
        let cli = Cli::parse_from(["remesh", "in.obj", "out.obj"]);
        assert_eq!(remesh_options(&cli), RemeshOptions::default());
        let cli = Cli::parse_from([
            "remesh",
            "in.obj",
            "out.obj",
            "--points",
            "123",
            "--sigma-n",
            "0.5",
            "--lfs-factor",
            "0.75",
            "--chord-error",
            "0.003",
            "--no-fit",
            "--smooth",
            "3",
            "--min-angle",
            "30",
            "--max-angle",
            "120",
            "--feature-angle",
            "25",
            "--triangulation",
            "umbrellas",
            "--iterations",
            "4",
            "--seed",
            "9",
        ]);
        let given = RemeshOptions {
            points: Some(123),
            sigma_p: None,
            edge_length: None,
            sigma_n: Some(0.5),
            lfs_factor: 0.75,
            chord_error: 0.003,
            no_fit: true,
            smooth: 3,
            min_angle: 30.0,
            max_angle: 120.0,
            feature_angle: Some(25.0),
            no_features: false,
            triangulation: "umbrellas".into(),
            iterations: 4,
            seed: 9,
        };
        assert_eq!(remesh_options(&cli), given);
        let cli = Cli::parse_from([
            "remesh",
            "in.obj",
            "out.obj",
            "--sigma-p",
            "2",
            "--no-features",
        ]);
        let o = remesh_options(&cli);
        assert_eq!((o.sigma_p, o.no_features), (Some(2.0), true));
    }

    /// Parameters named as in Rust and Python reach the user as flags, in the error's name and
    /// in backticks in its message; other names and backticked words stay.
    #[test]
    fn errors_name_flags_on_the_command_line() {
        let e = Error::InvalidParameter {
            name: "sigma_p",
            message: "give `points` or `sigma_p`, not both; `no_features`, `vertex`".into(),
        };
        assert_eq!(
            command_line_text(&e),
            "invalid parameter --sigma-p: give --points or --sigma-p, not both; --no-features, \
             `vertex`"
        );
        let e = Error::InvalidParameter {
            name: "OUTPUT",
            message: "x".into(),
        };
        assert_eq!(command_line_text(&e), "invalid parameter OUTPUT: x");
        // `count` is a flag of a subcommand (remesh points --count).
        let e = Error::InvalidParameter {
            name: "count",
            message: "x".into(),
        };
        assert_eq!(command_line_text(&e), "invalid parameter --count: x");
    }
}
