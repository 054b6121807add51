"""Scaling of the remesher (`remesh IN OUT --points N`) with the output size (issue 18).

Run through eval/scale (it sets up the venv and builds remesh):

    eval/scale                                   # 10k, 30k, 100k, 200k from a 194k-vertex horse
    eval/scale --outputs 10000,1000000 --repeats 1 --input horse   # horse -> 1M, once

The default input is a large scan-like mesh made here: horse.obj with every triangle split in
four at its edge midpoints (194k vertices), written to a temporary folder and deleted at the
end. Every run is timed by GNU time (`/usr/bin/time -v`): wall-clock seconds (median of the
repeats) and the peak resident set size (largest of the repeats); the stage wall and processor
seconds are the report's (`--report`, medians). Writes eval/results/scale/: scale.md,
scale.json, time-per-vertex.png (microseconds per output vertex by stage against the output
size) and memory.png (peak memory against output size).
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from scaling import timed  # GNU time's wall seconds and peak RSS

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SHARED = ROOT.parent / "shared" / "data"
REMESH = os.environ.get("REMESH_BIN", str(ROOT / "target" / "release" / "remesh"))
OUT = HERE / "results" / "scale"


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--input", default="horse-subdivided",
                   help="a shared model's name, or horse-subdivided (horse split once: 194k vertices)")
    p.add_argument("--outputs", default="10000,30000,100000,200000", help="output vertex counts")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--label", default="", help="a suffix for the output files (scale-LABEL.md, ...)")
    p.add_argument("--replot", action="store_true", help="only redraw the plots from scale[-LABEL].json")
    return p.parse_args()


def subdivide(src: Path, dst: Path):
    """Writes src split once at its edge midpoints (each triangle into four) as OBJ."""
    import trimesh

    mesh = trimesh.load(src, force="mesh", process=False)
    v, f = trimesh.remesh.subdivide(mesh.vertices, mesh.faces)
    trimesh.Trimesh(v, f, process=False).export(dst)
    return len(v)


def run(path: Path, n: int, repeats: int, seed: int, work: Path):
    walls, rss, reports = [], [], []
    for _ in range(repeats):
        out, rep = work / "out.obj", work / "report.json"
        wall, peak, _ = timed([REMESH, str(path), str(out), "--points", str(n), "--seed", str(seed),
                            "--report", str(rep), "-q"])
        walls.append(wall)
        rss.append(peak)
        reports.append(json.loads(rep.read_text()))
    stages = [s["stage"] for s in reports[0]["stages"]]
    med = lambda key: {st: statistics.median(next(s[key] for s in r["stages"] if s["stage"] == st)
                                             for r in reports) for st in stages}
    r0 = reports[0]
    row = {
        "target": n,
        "vertices": r0["topology"]["vertices"],
        "wall_s": statistics.median(walls),
        "wall_runs": walls,
        "peak_rss_mib": max(rss),
        "stage_wall_s": med("seconds"),
        "stage_cpu_s": med("cpu_seconds"),
        "q_ave": r0["triangles"]["q_ave"],
        "theta_min": r0["triangles"]["theta_min"],
    }
    row["us_per_vertex"] = 1e6 * row["wall_s"] / row["vertices"]
    print(f"-> {n}: {row['wall_s']:.2f} s (runs {', '.join(f'{w:.2f}' for w in walls)}), "
          f"{row['us_per_vertex']:.0f} us/vertex, peak {row['peak_rss_mib']:.0f} MiB", flush=True)
    return row


def plot(rows, out: Path, label: str, input_name: str):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    xs = np.array([r["vertices"] for r in rows], float)
    stages = [s for s in rows[0]["stage_wall_s"] if s != "check (report)"] + ["check (report)"]
    fig, ax = plt.subplots(figsize=(8, 5))
    bottom = np.zeros(len(rows))
    colors = plt.get_cmap("tab20").colors
    for i, st in enumerate(stages):
        vals = np.array([1e6 * r["stage_wall_s"].get(st, 0.0) / r["vertices"] for r in rows])
        ax.fill_between(xs, bottom, bottom + vals, label=st, color=colors[i % len(colors)])
        bottom += vals
    ax.plot(xs, [r["us_per_vertex"] for r in rows], "ko-", label="whole process (wall)")
    ax.set_xscale("log")
    ax.set_xlabel("output vertices")
    ax.set_ylabel("microseconds per output vertex (wall)")
    ax.set_title(f"remesh {input_name} --points N: cost per output vertex, stacked by stage")
    ax.legend(loc="upper left", fontsize=7, ncol=2)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / f"time-per-vertex{label}.png", dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot(xs, [r["peak_rss_mib"] for r in rows], "o-", label="peak resident memory")
    ax.set_xscale("log")
    ax.set_xlabel("output vertices")
    ax.set_ylabel("MiB")
    ax.set_title(f"remesh {input_name}: peak memory against output size")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / f"memory{label}.png", dpi=120)
    plt.close(fig)


def table(rows):
    stages = list(rows[0]["stage_wall_s"])
    head = "| output vertices | wall s (median) | runs | us/vertex | peak MiB | Qave | θmin | " + \
        " | ".join(f"{s} s (cpu/wall)" for s in stages) + " |"
    lines = [head, "|" + "---|" * (7 + len(stages))]
    for r in rows:
        cells = []
        for s in stages:
            w, c = r["stage_wall_s"].get(s, 0.0), r["stage_cpu_s"].get(s, 0.0)
            cells.append(f"{w:.2f} ({c / w:.1f})" if w > 0 else "0")
        lines.append(
            f"| {r['vertices']:,} | {r['wall_s']:.2f} | {', '.join(f'{w:.2f}' for w in r['wall_runs'])} | "
            f"{r['us_per_vertex']:.0f} | {r['peak_rss_mib']:.0f} | {r['q_ave']:.4f} | {r['theta_min']:.2f} | "
            + " | ".join(cells) + " |")
    return "\n".join(lines)


def main():
    args = parse_args()
    if not Path("/usr/bin/time").exists():
        sys.exit("scale: needs GNU time at /usr/bin/time")
    outputs = [int(s) for s in args.outputs.split(",")]
    label = f"-{args.label}" if args.label else ""
    OUT.mkdir(parents=True, exist_ok=True)
    if args.replot:
        plot(json.loads((OUT / f"scale{label}.json").read_text())["rows"], OUT, label, args.input)
        return
    work = Path(tempfile.mkdtemp(prefix="remesh-scale-"))
    try:
        if args.input == "horse-subdivided":
            path = work / "horse-subdivided.obj"
            nv = subdivide(SHARED / "horse.obj", path)
            input_desc = f"horse.obj split once at its edge midpoints ({nv:,} vertices)"
        else:
            path = SHARED / f"{args.input}.obj"
            if not path.exists():
                sys.exit(f"scale: {path}: no such model")
            input_desc = f"{path.name}"
        rows = [run(path, n, args.repeats, args.seed, work) for n in outputs]
    finally:
        shutil.rmtree(work, ignore_errors=True)
    plot(rows, OUT, label, args.input)
    us = [r["us_per_vertex"] for r in rows]
    md = [
        "# Scaling of `remesh IN OUT --points N` with the output size",
        "",
        f"Input: {input_desc}. Seed {args.seed}. Machine: {os.cpu_count()} cores. Wall clock: median of "
        f"{args.repeats} runs; peak RSS: the largest of them (`/usr/bin/time -v`). Stage seconds: the "
        "report's (medians), with processor over wall seconds in brackets (2.0 = both cores busy).",
        "",
        table(rows),
        "",
        f"Cost per output vertex from {rows[0]['vertices']:,} to {rows[-1]['vertices']:,}: "
        f"{min(us):.0f}–{max(us):.0f} µs (max/min {max(us) / min(us):.2f}).",
        "",
        f"![time per vertex](time-per-vertex{label}.png) ![memory](memory{label}.png)",
        "",
        f"Command: `eval/scale --input {args.input} --outputs {args.outputs} --repeats {args.repeats}`",
        "",
    ]
    (OUT / f"scale{label}.md").write_text("\n".join(md))
    (OUT / f"scale{label}.json").write_text(json.dumps({"input": input_desc, "rows": rows}, indent=1))
    print(f"wrote {OUT / f'scale{label}.md'}")


if __name__ == "__main__":
    main()
