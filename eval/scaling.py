"""Out-of-core scaling of `remesh simplify` (the paper's Fig. 16 and Table 1's Lucy).

Run through eval/scaling (it sets up the venv and builds remesh):

    eval/scaling                               # 1M, 4M, 14M, 28M -> 300k; 14M -> 30k..1M
    eval/scaling --sizes 1,4 --outputs 30000 --repeats 1      # a quick look

Input point sets are drawn from a mesh (default horse) with `remesh points` into a temporary
folder (28M points are 672 MB) and deleted at the end. Every run is timed by GNU time
(`/usr/bin/time -v`): wall-clock seconds (median of the repeats) and the peak resident set
size (largest of the repeats). Writes eval/results/scaling/: scaling.md, scaling.json,
time-vs-input.png, time-vs-output.png and memory-vs-input.png.
"""

import argparse
import json
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SHARED = ROOT.parent / "shared" / "data"
REMESH = os.environ.get("REMESH_BIN", str(ROOT / "target" / "release" / "remesh"))
OUT = HERE / "results" / "scaling"


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--model", default=str(SHARED / "horse.obj"), help="mesh the inputs are drawn from")
    p.add_argument("--sizes", default="1,4,14,28", help="input sizes in millions of points")
    p.add_argument("--target", type=int, default=300_000, help="output size for the input-size series")
    p.add_argument("--outputs", default="30000,100000,300000,1000000",
                   help="output sizes for the output-size series")
    p.add_argument("--output-input", type=float, default=14, help="input size (millions) of the output-size series")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--workdir", default=None, help="where the inputs go (default: a temporary folder)")
    return p.parse_args()


class RunFailed(Exception):
    """A timed command that exited non-zero or ran out of time (`timed_out`): the message is one
    line, `stderr` all that the command wrote there."""

    def __init__(self, line, stderr="", timed_out=False):
        super().__init__(line)
        self.stderr = stderr
        self.timed_out = timed_out


def run_timed(cmd, timeout=None, cpu=False):
    """Runs cmd under GNU time -v (its figures written to a file of their own, apart from the
    command's stderr); returns (wall seconds, peak RSS in MiB, stdout), and with `cpu` the
    processor seconds (user + system, every thread) after them. Raises RunFailed when the
    command exits non-zero (with the last line of its stderr) or is still running after `timeout`
    seconds (then its whole process group is killed)."""
    with tempfile.NamedTemporaryFile("r", prefix="gnu-time-", suffix=".txt") as figures:
        p = subprocess.Popen(["/usr/bin/time", "-v", "-o", figures.name] + cmd, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, start_new_session=True)
        try:
            stdout, stderr = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.communicate()
            raise RunFailed(f"still running after {timeout:g} s, stopped", timed_out=True)
        report = figures.read()
    if p.returncode != 0:
        # The command's last words, else GNU time's ("Command terminated by signal 11").
        lines = [l.strip() for l in stderr.splitlines() if l.strip()] or [report.split("\n")[0].strip()]
        raise RunFailed((lines[-1] or f"exit status {p.returncode}")[:200], stderr)
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", report).group(1)
    seconds = 0.0
    for part in wall.split(":"):
        seconds = seconds * 60 + float(part)
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", report).group(1))
    if cpu:
        processor = sum(float(re.search(rf"{kind} time \(seconds\): (\S+)", report).group(1))
                        for kind in ("User", "System"))
        return seconds, rss_kb / 1024, stdout, processor
    return seconds, rss_kb / 1024, stdout


def timed(cmd):
    """run_timed(cmd), exiting the script with the command's error when it fails."""
    try:
        return run_timed(cmd)
    except RunFailed as e:
        sys.exit(f"{Path(sys.argv[0]).stem}: {' '.join(cmd)} failed: {e}\n{e.stderr}")


def stages(stdout):
    """The stage seconds `remesh simplify` prints."""
    m = re.search(r"read\+bucket ([\d.]+), sigma_p search ([\d.]+), scan ([\d.]+)", stdout)
    n = re.search(r"-> (\d+) samples", stdout)
    return {
        "read_bucket": float(m.group(1)),
        "search": float(m.group(2)),
        "scan": float(m.group(3)),
        "samples": int(n.group(1)),
    }


def run_series(inputs, work, repeats):
    """inputs: list of (input millions, output target). Returns one row per pair."""
    rows = []
    for millions, target in inputs:
        path = work / f"in-{millions:g}M.ply"
        walls, rss, stage_runs = [], [], []
        for k in range(repeats):
            out = work / "out.ply"
            wall, peak, stdout = timed([REMESH, "simplify", str(path), str(out), "--points", str(target)])
            walls.append(wall)
            rss.append(peak)
            stage_runs.append(stages(stdout))
        med = {key: statistics.median(s[key] for s in stage_runs) for key in stage_runs[0]}
        row = {
            "input_points": int(millions * 1e6),
            "target": target,
            "samples": stage_runs[0]["samples"],
            "wall_s": statistics.median(walls),
            "wall_runs": walls,
            "peak_rss_mib": max(rss),
            "read_bucket_s": med["read_bucket"],
            "search_s": med["search"],
            "scan_s": med["scan"],
        }
        row["input_points_per_s"] = row["input_points"] / row["wall_s"]
        print(
            f"{millions:g}M -> {row['samples']} (target {target}): {row['wall_s']:.2f} s "
            f"(runs {', '.join(f'{w:.2f}' for w in walls)}), peak {row['peak_rss_mib']:.0f} MiB",
            flush=True,
        )
        rows.append(row)
    return rows


def plot(by_input, by_output, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def stacked(ax, rows, x, xlabel, title):
        xs = [r[x] / 1e6 for r in rows]
        parts = [("read_bucket_s", "read + bucket"), ("search_s", "sigma_p search"), ("scan_s", "linear scan")]
        bottom = [0.0] * len(rows)
        width = [0.6 * (xs[i] if len(xs) < 2 else min(abs(xs[i] - xs[j]) for j in range(len(xs)) if j != i)) for i in range(len(xs))]
        for key, label in parts:
            vals = [r[key] for r in rows]
            ax.bar(xs, vals, width=width, bottom=bottom, label=label, alpha=0.8)
            bottom = [b + v for b, v in zip(bottom, vals)]
        ax.plot(xs, [r["wall_s"] for r in rows], "ko-", label="wall clock (median)")
        for xv, r in zip(xs, rows):
            ax.annotate(f"{r['wall_s']:.1f} s", (xv, r["wall_s"]), textcoords="offset points", xytext=(0, 6), ha="center")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("seconds")
        ax.set_title(title)
        ax.legend(loc="upper left")
        ax.grid(alpha=0.3)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    stacked(ax, by_input, "input_points", "input points (millions)",
            f"remesh simplify --points {by_input[0]['target']}: time against input size")
    fig.tight_layout()
    fig.savefig(out / "time-vs-input.png", dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    stacked(ax, by_output, "samples", "output samples (millions)",
            f"{by_output[0]['input_points'] / 1e6:g}M input points: time against output size")
    fig.tight_layout()
    fig.savefig(out / "time-vs-output.png", dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    xs = [r["input_points"] / 1e6 for r in by_input]
    ax.plot(xs, [r["peak_rss_mib"] for r in by_input], "o-", label="peak resident memory")
    ax.axhline(1024, color="r", ls="--", label="1 GiB")
    ax.set_ylim(0, 1100)
    ax.set_xlabel("input points (millions)")
    ax.set_ylabel("MiB")
    ax.set_title(f"peak memory against input size (output {by_input[0]['target']})")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "memory-vs-input.png", dpi=120)
    plt.close(fig)


def table(rows):
    lines = [
        "| input points | samples | wall s (median) | runs | input points/s | peak RSS MiB | read+bucket s | search s | scan s |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['input_points']:,} | {r['samples']:,} | {r['wall_s']:.2f} | "
            f"{', '.join(f'{w:.2f}' for w in r['wall_runs'])} | {r['input_points_per_s'] / 1e6:.2f}M | "
            f"{r['peak_rss_mib']:.0f} | {r['read_bucket_s']:.2f} | {r['search_s']:.2f} | {r['scan_s']:.2f} |"
        )
    return "\n".join(lines)


def main():
    args = parse_args()
    if not Path("/usr/bin/time").exists():
        sys.exit("scaling: needs GNU time at /usr/bin/time")
    sizes = [float(s) for s in args.sizes.split(",")]
    outputs = [int(s) for s in args.outputs.split(",")]
    OUT.mkdir(parents=True, exist_ok=True)
    work = Path(args.workdir) if args.workdir else Path(tempfile.mkdtemp(prefix="remesh-scaling-"))
    work.mkdir(parents=True, exist_ok=True)
    try:
        for millions in sorted(set(sizes + [args.output_input])):
            path = work / f"in-{millions:g}M.ply"
            if not path.exists():
                print(f"drawing {millions:g}M points from {args.model}", flush=True)
                subprocess.run([REMESH, "points", args.model, str(path), "--count", str(int(millions * 1e6)),
                                "--seed", "1"], check=True)
        by_input = run_series([(m, args.target) for m in sizes], work, args.repeats)
        by_output = run_series([(args.output_input, n) for n in outputs], work, args.repeats)
    finally:
        if not args.workdir:
            shutil.rmtree(work, ignore_errors=True)
    cpu = os.cpu_count()
    md = [
        "# Out-of-core scaling of `remesh simplify`",
        "",
        f"Inputs: points drawn uniformly by area from `{Path(args.model).name}` with normals (binary PLY, "
        f"`remesh points`). Machine: {cpu} cores. Wall clock: median of {args.repeats} runs; peak RSS: the "
        "largest of them (`/usr/bin/time -v`). Stage seconds are what `remesh simplify` prints (medians).",
        "",
        f"## Time and memory against input size (--points {args.target})",
        "",
        table(by_input),
        "",
        "![time against input size](time-vs-input.png)",
        "![memory against input size](memory-vs-input.png)",
        "",
        f"## Time against output size ({args.output_input:g}M input points)",
        "",
        table(by_output),
        "",
        "![time against output size](time-vs-output.png)",
        "",
    ]
    (OUT / "scaling.md").write_text("\n".join(md))
    (OUT / "scaling.json").write_text(json.dumps({"by_input": by_input, "by_output": by_output}, indent=1))
    plot(by_input, by_output, OUT)
    print(f"wrote {OUT}/scaling.md, scaling.json and 3 PNGs")


if __name__ == "__main__":
    main()
