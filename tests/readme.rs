//! The figures README.md quotes are what their sources say today (issue 56: they had drifted
//! from what the main command prints and from the table they cite). `eval/readme_figures.py`
//! regenerates them; these tests fail when they drift again.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The label of a report line ("  Qave      0.9411" -> "Qave"), if it is one.
fn label(line: &str) -> Option<&str> {
    let rest = line.strip_prefix("  ")?;
    if rest.starts_with(' ') {
        return None;
    }
    let end = rest.find("  ")?;
    rest[end..].trim_start().chars().next()?;
    Some(&rest[..end])
}

const FIX: &str = "run `python3 eval/readme_figures.py` (REMESH_BIN=target/release/remesh)";

#[test]
fn the_readme_quotes_what_the_main_command_prints() {
    let readme = read(&root().join("README.md"));
    let start = readme
        .find("```text\ndata/spot.obj -> ")
        .expect("README has the report block");
    let block = &readme[start + 8..];
    let block = &block[..block.find("```").expect("the block ends")];
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_remesh"))
        .current_dir(root())
        .args(["data/spot.obj"])
        .arg(dir.path().join("spot-3k.obj"))
        .args(["--points", "3000"])
        .output()
        .expect("run remesh");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let printed = String::from_utf8_lossy(&o.stdout);
    let mut checked = 0;
    for line in block.lines() {
        let Some(name) = label(line) else { continue };
        let theirs = printed
            .lines()
            .find(|l| label(l) == Some(name))
            .unwrap_or_else(|| panic!("the README quotes '{name}', which the report lacks"));
        assert_eq!(line, theirs, "README's '{name}' line drifted: {FIX}");
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} lines checked");
}

/// `values` as the README prints a range over the seeds ("lo–hi", or one value).
fn span(values: &[f64], fmt: impl Fn(f64) -> String) -> String {
    let lo = fmt(values.iter().copied().fold(f64::INFINITY, f64::min));
    let hi = fmt(values.iter().copied().fold(f64::NEG_INFINITY, f64::max));
    if lo == hi {
        lo
    } else {
        format!("{lo}–{hi}")
    }
}

/// `x` to `digits` significant digits.
fn significant(x: f64, digits: i32) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let decimals = (digits - 1 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

#[test]
fn the_readme_table_is_the_range_of_the_bounds_it_cites() {
    let readme = read(&root().join("README.md"));
    let bounds = read(&root().join("eval/results/bounds/bounds.md"));
    let mut rows = 0;
    for section in bounds.split("\n## ").skip(1) {
        let mut words = section.split_whitespace();
        let model = words.next().unwrap();
        let count: usize = words.nth(1).unwrap().parse().unwrap();
        let seeds: Vec<Vec<f64>> = section
            .lines()
            .filter(|l| {
                l.starts_with("| ") && l[2..].chars().next().is_some_and(|c| c.is_ascii_digit())
            })
            .map(|l| {
                l.trim_matches('|')
                    .split('|')
                    .skip(1)
                    .take(5)
                    .map(|c| c.trim().parse().unwrap())
                    .collect()
            })
            .collect();
        assert_eq!(seeds.len(), 5, "{model}: seeds 1-5");
        let col = |k: usize| seeds.iter().map(|r| r[k]).collect::<Vec<f64>>();
        let expected = [
            span(&col(0), |v| format!("{v:.1}")),
            span(&col(1), |v| format!("{v:.1}")),
            span(&col(2), |v| format!("{v:.3}")),
            span(&col(3), |v| format!("{v:.2}")),
            span(&col(4), |v| significant(v, 2)),
        ];
        let name = if model == "stanford-bunny" {
            "bunny"
        } else {
            model
        };
        let thousands = if count >= 1000 {
            format!("{},{:03}", count / 1000, count % 1000)
        } else {
            count.to_string()
        };
        let key = format!("|{name} {thousands}|");
        let row = readme
            .lines()
            .find(|l| l.starts_with(&key))
            .unwrap_or_else(|| panic!("README has no row {key}"));
        let cells: Vec<&str> = row.trim_matches('|').split('|').collect();
        assert_eq!(cells[1..6], expected, "README's {key} row drifted: {FIX}");
        rows += 1;
    }
    assert_eq!(rows, 7, "the seven shared models");
}

/// Every option each command's `--help` gives is named in the README (issue 56: `quality
/// --seed`, four of `simplify`'s and `-V` were missing), and the help names every format the
/// command reads and the limit `--iterations` has.
#[test]
fn the_readme_names_every_option_the_help_gives() {
    let readme = read(&root().join("README.md"));
    let help = |sub: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_remesh"))
            .args(sub)
            .arg("--help")
            .output()
            .expect("run remesh");
        assert!(o.status.success());
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    // Where the README names a command's options: the main command's in its table (and the
    // commands block for -V), a subcommand's on its line of the commands block (with the
    // lines that continue it).
    let block = &readme[readme
        .find("remesh <INPUT> <OUTPUT> [OPTIONS]")
        .expect("commands")..];
    let block = &block[..block.find("```").expect("the block ends")];
    let usage = |sub: &str| -> String {
        let mut out = String::new();
        let mut on = false;
        for line in block.lines() {
            if line.starts_with("remesh ") {
                on = line.starts_with(&format!("remesh {sub} "));
            }
            if on {
                out += line;
                out += "\n";
            }
        }
        out
    };
    for sub in ["", "quality", "simplify", "points"] {
        let args: &[&str] = if sub.is_empty() { &[] } else { &[sub] };
        let text = help(args);
        let place = if sub.is_empty() {
            readme
                .lines()
                .filter(|l| l.starts_with("| `"))
                .collect::<Vec<_>>()
                .join("\n")
                + block
        } else {
            usage(sub)
        };
        for line in text.lines() {
            let line = line.trim_start();
            if !line.starts_with('-') {
                continue;
            }
            // The option's spellings on this line (`-q, --quiet`): one of them named will do.
            let forms: Vec<&str> = line
                .split(|c: char| c == ',' || c.is_whitespace())
                .take_while(|w| w.is_empty() || w.starts_with('-'))
                .filter(|w| !w.is_empty())
                .collect();
            if forms.iter().any(|f| matches!(*f, "-h" | "--help")) {
                continue;
            }
            let named = forms.iter().any(|option| {
                [" ", "`", "[", "(", ","]
                    .iter()
                    .any(|before| place.contains(&format!("{before}{option}")))
            });
            assert!(
                named,
                "`remesh {sub} --help` gives {forms:?}; the README does not name it there"
            );
        }
    }
    let simplify = help(&["simplify"]);
    let point_formats = [
        ".ply", ".pcd", ".las", ".laz", ".e57", ".xyz", ".xyzn", ".csv", ".txt", ".pts", ".asc",
    ];
    for ext in point_formats {
        assert!(simplify.contains(ext), "simplify --help omits {ext}");
    }
    let points = help(&["points"]);
    for ext in [".obj", ".ply", ".gltf", ".glb", ".stl", ".off"] {
        assert!(points.contains(ext), "points --help omits {ext}");
    }
    let main = help(&[]);
    for ext in point_formats {
        assert!(
            main.contains(ext),
            "--help omits the point set format {ext}"
        );
    }
    let iterations = main
        .lines()
        .find(|l| l.contains("--iterations"))
        .expect("--iterations in --help");
    assert!(iterations.contains("at most 1000"), "{iterations}");
}
