"""Scaling of the remesher (`remesh IN OUT --points N`) with the output size (issues 18 and 57),
beside three reference remeshers run in the same sitting.

Run through eval/scale (it sets up the venv and builds remesh):

    eval/scale --input horse --outputs 8600,200000,1000000   # issue 57's sitting: all four tools
    eval/scale --outputs 8600 --repeats 1 --input horse --references meshlib   # a quick look
    eval/scale --references none      # ours alone: 10k, 30k, 100k, 200k from a 194k-vertex horse

The tools, each run as a whole process on the same input file at each output size N:
- ours: `remesh IN OUT --points N --seed S --report R -q --no-distance`;
- meshlib: MeshLib's remesh (`mrmeshpy.remesh`, default settings) at the edge length of N
  equilateral vertices over the input's area (eval/references.py);
- cgal: CGAL's isotropic remeshing with one iteration at that edge length (eval/references.py,
  the reference of issue 38);
- geogram: geogram's CVT remeshing at N points (eval/geogram_cvt.cpp, built into eval/.build/ on
  first use by compare.build_geogram_cvt).
Within each repeat the tools run one after the other (round robin), so that the load of a shared
machine falls on all of them alike. Every run is timed by GNU time (`/usr/bin/time -v`):
wall-clock seconds (median of the repeats) and the peak resident set size (largest of the
repeats). The first repeat's output of each tool is measured by one NumPy function (vertices,
Qave, θmin, θmax), the same for all four. A tool that is missing or fails gets "failed: <why>"
in the table; the other tools go on.

The default input is a large scan-like mesh made here: horse.obj with every triangle split in
four at its edge midpoints (194k vertices), written to a temporary folder and deleted at the
end. Writes eval/results/scale/scale[-LABEL].md and .json, time-per-vertex[-LABEL].png (wall
microseconds per output vertex against the output size, one line per tool), memory[-LABEL].png
(peak memory against output size, one line per tool) and stages-per-vertex[-LABEL].png (ours'
microseconds per output vertex stacked by stage, from its report). With `--references none`
time-per-vertex is ours' stacked plot and there is no stages-per-vertex, as before issue 57.
"""

import argparse
import importlib.metadata
import importlib.util
import json
import os
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

from references import equilateral_edge_length
from ruler_check import triangle_angles, triangle_qualities
from scaling import RunFailed, run_timed  # GNU time's wall seconds and peak RSS

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SHARED = ROOT.parent / "shared" / "data"
REMESH = os.environ.get("REMESH_BIN", str(ROOT / "target" / "release" / "remesh"))
OUT = HERE / "results" / "scale"

# The tools: key -> name in the tables and plots.
TOOLS = {
    "ours": "remesh (ours)",
    "meshlib": "MeshLib remesh",
    "cgal": "CGAL isotropic, 1 it.",
    "geogram": "geogram CVT",
}
# Short names, for the table's headers.
SHORT = {"ours": "ours", "meshlib": "MeshLib", "cgal": "CGAL", "geogram": "geogram"}
REFERENCES = ["meshlib", "cgal", "geogram"]
COLORS = {"ours": "tab:red", "meshlib": "tab:blue", "cgal": "tab:green", "geogram": "tab:purple"}


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--input", default="horse-subdivided",
                   help="a shared model's name, or horse-subdivided (horse split once: 194k vertices)")
    p.add_argument("--outputs", default="10000,30000,100000,200000", help="output vertex counts")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--references", default=",".join(REFERENCES),
                   help=f"reference tools run beside ours: some of {','.join(REFERENCES)}, or none")
    p.add_argument("--timeout", type=float, default=3600,
                   help="seconds one run may take; a tool that runs out is stopped, marked failed "
                        "and not run at larger sizes")
    p.add_argument("--distance", action="store_true",
                   help="ours also measures its Hausdorff distance to the input (a stage of its own)")
    p.add_argument("--label", default="", help="a suffix for the output files (scale-LABEL.md, ...)")
    p.add_argument("--replot", action="store_true", help="only redraw the plots from scale[-LABEL].json")
    args = p.parse_args()
    args.references = [] if args.references == "none" else args.references.split(",")
    unknown = [r for r in args.references if r not in REFERENCES]
    if unknown:
        p.error(f"unknown reference(s): {', '.join(unknown)} (known: {', '.join(REFERENCES)}, or none)")
    return args


def subdivide(src: Path, dst: Path):
    """Writes src split once at its edge midpoints (each triangle into four) as OBJ."""
    import trimesh

    mesh = trimesh.load(src, force="mesh", process=False)
    v, f = trimesh.remesh.subdivide(mesh.vertices, mesh.faces)
    trimesh.Trimesh(v, f, process=False).export(dst)
    return len(v)


# ----------------------------------------------------------------------------- the tools


def unavailable_references(references):
    """The references that cannot run here, with why: a Python package not installed, or the
    geogram tool failing to build. Returns ({tool: message}, path of the geogram tool or None)."""
    missing, geogram_tool = {}, None
    for tool, package in (("meshlib", "meshlib"), ("cgal", "CGAL")):
        if tool in references and importlib.util.find_spec(package) is None:
            missing[tool] = f"the Python package {package} is not installed (eval/requirements.txt)"
    if "geogram" in references:
        try:
            from compare import build_geogram_cvt

            geogram_tool = build_geogram_cvt()
        except Exception as e:  # the build needs pip's network and a C++ compiler
            missing["geogram"] = f"building eval/geogram_cvt.cpp failed: {type(e).__name__}: {e}".splitlines()[0][:200]
    return missing, geogram_tool


def command(tool, path, n, seed, work, geogram_tool, distance):
    """The command line that runs `tool` on `path` to about n vertices, and its output file."""
    if tool == "ours":
        out = work / "ours.obj"
        cmd = [REMESH, str(path), str(out), "--points", str(n), "--seed", str(seed),
               "--report", str(work / "ours.json"), "-q"]
        return cmd + ([] if distance else ["--no-distance"]), out
    if tool in ("meshlib", "cgal"):
        out = work / f"{tool}.{'off' if tool == 'cgal' else 'obj'}"
        return [sys.executable, str(HERE / "references.py"), tool, str(path), str(out), str(n)], out
    if tool == "geogram":
        out = work / "geogram.obj"
        return [str(geogram_tool), str(path), str(out), str(n)], out
    raise ValueError(tool)


def output_measures(path):
    """The output's vertices and faces (bit-identical positions welded and unreferenced vertices
    dropped, as remesh reads a mesh), Qave, and its smallest and largest angle (degrees): one
    NumPy computation for every tool's output (eval/ruler_check.py's formulas)."""
    from compare import read_mesh

    V, F = read_mesh(path)
    if len(F) == 0:
        raise ValueError("empty output")
    angles = triangle_angles(V, F)
    return {
        "vertices": len(V),
        "faces": len(F),
        "q_ave": float(triangle_qualities(V, F).mean()),
        "theta_min": float(angles.min()),
        "theta_max": float(angles.max()),
    }


def sitting(path, n, tools, repeats, seed, work, geogram_tool, args, unavailable):
    """Runs every tool at output size n, `repeats` times, round robin within each repeat. Returns
    {tool: result} (result: timings and measures, or {"failed": why}) and ours' reports."""
    runs = {t: [] for t in tools}
    failed = {t: unavailable[t] for t in tools if t in unavailable}
    measured, reports = {}, []
    for k in range(repeats):
        for tool in tools:
            if tool in failed:
                continue
            cmd, out = command(tool, path, n, seed, work, geogram_tool, args.distance)
            try:
                wall, rss, _, cpu = run_timed(cmd, timeout=args.timeout, cpu=True)
                if k == 0:
                    measured[tool] = output_measures(out)
                if tool == "ours":
                    reports.append(json.loads((work / "ours.json").read_text()))
            except Exception as e:  # RunFailed, or the output unreadable
                failed[tool] = str(e) if isinstance(e, RunFailed) else f"{type(e).__name__}: {e}".splitlines()[0][:200]
                if isinstance(e, RunFailed) and e.timed_out:
                    unavailable[tool] = f"ran out of time ({args.timeout:g} s) at {n:,}, not run"
                print(f"  {n:,} run {k + 1}: {TOOLS[tool]} failed: {failed[tool]}", flush=True)
                continue
            finally:
                for f in work.glob(f"{tool}*"):
                    f.unlink()
            runs[tool].append((wall, rss, cpu))
            print(f"  {n:,} run {k + 1}: {TOOLS[tool]}: {wall:.2f} s, {cpu:.2f} processor s, {rss:.0f} MiB"
                  + (f", {measured[tool]['vertices']:,} vertices" if k == 0 else ""), flush=True)
    results = {}
    for tool in tools:
        if tool in failed:
            results[tool] = {"failed": failed[tool]}
            continue
        walls, rss, cpus = ([x[i] for x in runs[tool]] for i in range(3))
        r = {"wall_s": statistics.median(walls), "wall_runs": walls, "peak_rss_mib": max(rss), "rss_runs": rss,
             "cpu_s": statistics.median(cpus), "cpu_runs": cpus}
        r.update(measured[tool])
        r["us_per_vertex"] = 1e6 * r["wall_s"] / r["vertices"]
        results[tool] = r
    return results, reports


def ours_row(n, result, reports):
    """Ours at one size in the form of the table by stage (as before issue 57): the timings and
    the report's stage seconds (medians), vertices, Qave and θmin."""
    stages = [s["stage"] for s in reports[0]["stages"]]
    med = lambda key: {st: statistics.median(next(s[key] for s in r["stages"] if s["stage"] == st)
                                             for r in reports) for st in stages}
    r0 = reports[0]
    row = {
        "target": n,
        "vertices": r0["topology"]["vertices"],
        "wall_s": result["wall_s"],
        "wall_runs": result["wall_runs"],
        "peak_rss_mib": result["peak_rss_mib"],
        "stage_wall_s": med("seconds"),
        "stage_cpu_s": med("cpu_seconds"),
        "q_ave": r0["triangles"]["q_ave"],
        "theta_min": r0["triangles"]["theta_min"],
    }
    row["us_per_vertex"] = 1e6 * row["wall_s"] / row["vertices"]
    return row


# ----------------------------------------------------------------------------- plots


def plain_log_labels(axis, fmt, limits):
    """Plain numbers on a log axis (1,000,000 and 300, not 10^6 and 3x10^2): every power of ten,
    and between them 2, 3, 4 and 5 times one over at most a decade, 2 and 5 times one over at
    most three, none over more."""
    from matplotlib.ticker import FuncFormatter

    decades = np.log10(limits[1] / limits[0])
    digits = "2345" if decades <= 1 else "25" if decades <= 3 else ""
    axis.set_major_formatter(FuncFormatter(lambda v, _: fmt.format(v)))
    axis.set_minor_formatter(FuncFormatter(lambda v, _: fmt.format(v) if f"{v:.0e}"[0] in digits else ""))


def plot_stages(rows, path: Path, input_name: str):
    """Ours' microseconds per output vertex stacked by stage (the report's wall seconds), with the
    whole process's wall time over them."""
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
    plain_log_labels(ax.xaxis, "{:,.0f}", ax.get_xlim())
    ax.set_xlabel("output vertices")
    ax.set_ylabel("microseconds per output vertex (wall)")
    ax.set_title(f"remesh {input_name} --points N: cost per output vertex, stacked by stage")
    ax.legend(loc="upper left", fontsize=7, ncol=2)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_tools(sizes, key, ylabel, title, path: Path):
    """One line per tool: `key` of its result (each point at the tool's own output vertex count)
    against output vertices, log-log; failed sizes left out."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    for tool in TOOLS:
        points = [(s["tools"][tool]["vertices"], s["tools"][tool][key]) for s in sizes
                  if tool in s["tools"] and "failed" not in s["tools"][tool]]
        if points:
            xs, ys = zip(*points)
            ax.plot(xs, ys, "o-", label=TOOLS[tool], color=COLORS[tool])
    ax.set_xscale("log")
    ax.set_yscale("log")
    plain_log_labels(ax.xaxis, "{:,.0f}", ax.get_xlim())
    plain_log_labels(ax.yaxis, "{:g}", ax.get_ylim())
    ax.set_xlabel("output vertices")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend()
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot(data, out: Path, label: str, input_name: str):
    if not data.get("references"):  # ours alone: the plots as before issue 57
        plot_stages(data["rows"], out / f"time-per-vertex{label}.png", input_name)
    else:
        if data["rows"]:
            plot_stages(data["rows"], out / f"stages-per-vertex{label}.png", input_name)
        plot_tools(data["sizes"], "us_per_vertex", "microseconds per output vertex (wall, whole process)",
                   f"{input_name} -> N vertices: time per output vertex", out / f"time-per-vertex{label}.png")
    plot_tools(data["sizes"], "peak_rss_mib", "peak resident memory (MiB)",
               f"{input_name} -> N vertices: peak memory", out / f"memory{label}.png")


# ----------------------------------------------------------------------------- tables


def stage_table(rows):
    """Ours by stage, one row per size (the table before issue 57)."""
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


def ratio(sizes_row, reference, key="wall_s"):
    """Ours' median wall seconds (`key` "cpu_s": processor seconds) over the reference's at one
    size, or None (a run failed, or a sitting from before processor seconds were kept)."""
    ours, ref = sizes_row["tools"].get("ours", {}), sizes_row["tools"].get(reference, {})
    if key in ours and key in ref:
        return ours[key] / ref[key]
    return None


def comparison_table(sizes, tools):
    """One row per size: each tool's median wall and processor seconds, peak MiB, vertices, Qave
    and θmin, then ours' time over CGAL's and over MeshLib's, and ours' processor time over
    CGAL's."""
    head = ["asked"]
    for t in tools:
        head += [f"{SHORT[t]} s", f"{SHORT[t]} cpu s", f"{SHORT[t]} MiB", f"{SHORT[t]} V", f"{SHORT[t]} Qave",
                 f"{SHORT[t]} θmin"]
    ratios = [r for r in ("cgal", "meshlib") if r in tools]
    head += [f"ours / {SHORT[r]}" for r in ratios]
    head += ["ours cpu / CGAL cpu"] if "cgal" in tools else []
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for s in sizes:
        cells = [f"{s['target']:,}"]
        for t in tools:
            r = s["tools"][t]
            if "failed" in r:
                cells += [f"failed: {r['failed']}", "–", "–", "–", "–", "–"]
            else:
                cpu = f"{r['cpu_s']:.2f}" if "cpu_s" in r else "–"
                cells += [f"{r['wall_s']:.2f}", cpu, f"{r['peak_rss_mib']:.0f}", f"{r['vertices']:,}",
                          f"{r['q_ave']:.4f}", f"{r['theta_min']:.2f}"]
        for ref in ratios:
            x = ratio(s, ref)
            cells.append("–" if x is None else f"{x:.2f}")
        if "cgal" in tools:
            x = ratio(s, "cgal", "cpu_s")
            cells.append("–" if x is None else f"{x:.2f}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def runs_table(sizes, tools):
    """One row per size and tool: every run's wall and processor seconds and peak MiB, time per
    vertex, faces and θmax."""
    lines = ["| asked | tool | wall s (runs) | processor s (runs) | peak MiB (runs) | µs/vertex | vertices | faces "
             "| θmax |",
             "|---|---|---|---|---|---|---|---|---|"]
    for s in sizes:
        for t in tools:
            r = s["tools"][t]
            if "failed" in r:
                lines.append(f"| {s['target']:,} | {TOOLS[t]} | failed: {r['failed']} | | | | | | |")
                continue
            lines.append(
                f"| {s['target']:,} | {TOOLS[t]} | {', '.join(f'{w:.2f}' for w in r['wall_runs'])} | "
                f"{', '.join(f'{c:.2f}' for c in r.get('cpu_runs', [])) or '–'} | "
                f"{', '.join(f'{m:.0f}' for m in r['rss_runs'])} | {r['us_per_vertex']:.0f} | {r['vertices']:,} | "
                f"{r['faces']:,} | {r['theta_max']:.2f} |")
    return "\n".join(lines)


def targets_lines(sizes):
    """Issue 57's timing targets at each size: ours at most CGAL 1-iteration's time and at most
    twice MeshLib's."""
    lines = []
    for s in sizes:
        parts = []
        for ref, bound in (("cgal", 1.0), ("meshlib", 2.0)):
            if ref not in s["tools"]:
                continue
            x = ratio(s, ref)
            if x is None:
                parts.append(f"against {TOOLS[ref]}: no figure (a run failed)")
            else:
                verdict = "met" if x <= bound else "not met"
                parts.append(f"ours / {SHORT[ref]} {x:.2f} (target ≤ {bound:g}: {verdict})")
        if parts:
            lines.append(f"- {s['target']:,}: " + "; ".join(parts))
    return lines


def targets_77(sizes):
    """Issue 77's targets at each size: ours' processor seconds at most twice CGAL 1-iteration's,
    its wall seconds at most CGAL's; at 1,000,000, at most 60 s and 1 GiB."""
    lines = []
    for s in sizes:
        ours = s["tools"].get("ours", {})
        if "cpu_s" not in ours:
            continue
        parts = []
        x = ratio(s, "cgal", "cpu_s")
        if x is not None:
            parts.append(f"processor ours / CGAL {x:.2f} (target ≤ 2: {'met' if x <= 2 else 'not met'})")
        x = ratio(s, "cgal")
        if x is not None:
            parts.append(f"wall ours / CGAL {x:.2f} (target ≤ 1: {'met' if x <= 1 else 'not met'})")
        if s["target"] == 1_000_000:
            w, m = ours["wall_s"], ours["peak_rss_mib"]
            parts.append(f"{w:.1f} s (target ≤ 60: {'met' if w <= 60 else 'not met'}), "
                         f"{m:.0f} MiB (target ≤ 1024: {'met' if m <= 1024 else 'not met'})")
        if parts:
            lines.append(f"- {s['target']:,}: " + "; ".join(parts))
    return lines


def versions():
    """The reference tools' versions as installed."""
    from compare import GEOGRAM_VERSION

    out = []
    for name, package in (("MeshLib", "meshlib"), ("CGAL", "cgal")):
        try:
            out.append(f"{name} {importlib.metadata.version(package)}")
        except importlib.metadata.PackageNotFoundError:
            out.append(f"{name} not installed")
    return ", ".join(out) + f", geogram {GEOGRAM_VERSION} (the PyPI wheel's static library)"


def markdown(data, args, label):
    rows, sizes, tools = data["rows"], data["sizes"], ["ours"] + data["references"]
    head = [
        "# Scaling of `remesh IN OUT --points N` with the output size" + (", beside the references" if data["references"] else ""),
        "",
        f"Input: {data['input']}. Seed {args.seed}. Machine: {os.cpu_count()} cores. Every run is a whole "
        f"process timed by GNU time (`/usr/bin/time -v`): wall clock, median of {args.repeats} runs; peak RSS, "
        "the largest of them.",
        "",
    ]
    if not data["references"]:
        us = [r["us_per_vertex"] for r in rows]
        body = [
            f"Ours: `remesh IN OUT --points N --seed {args.seed} --report R -q"
            f"{'' if args.distance else ' --no-distance'}`. Stage seconds: the report's (medians), with "
            "processor over wall seconds in brackets (2.0 = both cores busy).",
            "",
            stage_table(rows),
            "",
            f"Cost per output vertex from {rows[0]['vertices']:,} to {rows[-1]['vertices']:,}: "
            f"{min(us):.0f}–{max(us):.0f} µs (max/min {max(us) / min(us):.2f}).",
            "",
            f"![time per vertex](time-per-vertex{label}.png) ![memory](memory{label}.png)",
            "",
        ]
    else:
        h = ", ".join(f"{s['target']:,}: {s['edge_length']:.6g}" for s in sizes)
        body = [
            "The tools, in this order within each repeat (round robin):",
            f"- remesh (ours): `remesh IN OUT --points N --seed {args.seed} --report R -q"
            f"{'' if args.distance else ' --no-distance'}`;",
            "- MeshLib remesh: `mrmeshpy.remesh` with default `RemeshSettings` but `targetEdgeLen` = h, loading and "
            "saving OBJ (eval/references.py);" if "meshlib" in tools else None,
            "- CGAL isotropic, 1 it.: `isotropic_remeshing` with one iteration at h on a `Polyhedron_3`, the OBJ read "
            "in Python and handed over as OFF, written as OFF (eval/references.py, issue 38's reference);"
            if "cgal" in tools else None,
            "- geogram CVT: `remesh_smooth` at N points, 5 Lloyd and 30 Newton iterations (eval/geogram_cvt.cpp)."
            if "geogram" in tools else None,
            "",
            f"h is the edge length of N equilateral vertices over the input's area (by asked size: {h}); the "
            "references' vertex counts differ from N as their remeshing makes them. V, Qave, θmin and θmax: the "
            "first run's output of each tool measured by one NumPy function (eval/scale.py's `output_measures`). "
            f"Versions: {versions()}. ours / CGAL and ours / MeshLib: ours' median wall seconds over theirs.",
            "",
            comparison_table(sizes, tools),
            "",
            "Issue 57's targets (ours at most CGAL 1-iteration's time, at most twice MeshLib's):",
            "",
            *targets_lines(sizes),
            "",
            *(["Issue 77's targets (processor seconds at most twice CGAL 1-iteration's, wall at most its; "
               "1,000,000 in 60 s and 1 GiB):", "", *targets_77(sizes), ""] if targets_77(sizes) else []),
            "![time per vertex](time-per-vertex{0}.png) ![memory](memory{0}.png)".format(label),
            "",
            "## Every run",
            "",
            runs_table(sizes, tools),
            "",
        ]
        body = [b for b in body if b is not None]
        if rows:
            body += [
                "## Ours by stage",
                "",
                "The report's stage seconds (medians), with processor over wall seconds in brackets (2.0 = both "
                "cores busy); Qave and θmin are the report's.",
                "",
                stage_table(rows),
                "",
                f"![ours by stage](stages-per-vertex{label}.png)",
                "",
            ]
    command_line = (f"eval/scale --input {args.input} --outputs {args.outputs} --repeats {args.repeats} "
                    f"--references {','.join(data['references']) or 'none'}"
                    + (f" --seed {args.seed}" if args.seed != 1 else "")
                    + (" --distance" if args.distance else "") + (f" --label {args.label}" if args.label else ""))
    return "\n".join(head + body + [f"Command: `{command_line}`", ""])


# ----------------------------------------------------------------------------- main


def main():
    args = parse_args()
    if not Path("/usr/bin/time").exists():
        sys.exit("scale: needs GNU time at /usr/bin/time")
    outputs = [int(s) for s in args.outputs.split(",")]
    label = f"-{args.label}" if args.label else ""
    OUT.mkdir(parents=True, exist_ok=True)
    if args.replot:
        data = json.loads((OUT / f"scale{label}.json").read_text())
        data.setdefault("references", [])
        data.setdefault("sizes", [{"tools": {"ours": r}} for r in data["rows"]])  # before issue 57
        plot(data, OUT, label, args.input)
        return
    tools = ["ours"] + args.references
    unavailable, geogram_tool = unavailable_references(args.references)
    for tool, why in unavailable.items():
        print(f"scale: {TOOLS[tool]}: {why}", flush=True)
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
        from compare import area, read_mesh

        input_area = area(*read_mesh(path))
        runs = work / "runs"
        runs.mkdir()
        rows, sizes = [], []
        for n in outputs:
            print(f"-> {n:,}", flush=True)
            results, reports = sitting(path, n, tools, args.repeats, args.seed, runs, geogram_tool, args, unavailable)
            size = {"target": n, "edge_length": equilateral_edge_length(input_area, n), "tools": results}
            for ref in ("cgal", "meshlib"):
                if ref in tools:
                    size[f"ours_over_{ref}"] = ratio(size, ref)
            sizes.append(size)
            if reports and "failed" not in results["ours"]:
                rows.append(ours_row(n, results["ours"], reports))
            summary = ", ".join(f"{TOOLS[t]} " + ("failed" if "failed" in r else f"{r['wall_s']:.2f} s")
                                for t, r in results.items())
            print(f"-> {n:,}: {summary}", flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    data = {"input": input_desc, "seed": args.seed, "repeats": args.repeats, "references": args.references,
            "distance": args.distance, "rows": rows, "sizes": sizes}
    if not args.references and not rows:
        sys.exit("scale: ours failed at every size: " + "; ".join(s["tools"]["ours"]["failed"] for s in sizes))
    (OUT / f"scale{label}.json").write_text(json.dumps(data, indent=1))
    plot(data, OUT, label, args.input)
    (OUT / f"scale{label}.md").write_text(markdown(data, args, label))
    print(f"wrote {OUT / f'scale{label}.md'}")


if __name__ == "__main__":
    main()
