"""Reconstruction accuracy (the paper's Sec. 7.2 and Table 2).

Run through eval/reconstruction (it sets up the venv and builds spectral-experiments):

    eval/reconstruction                  # horse, stanford-bunny, fandisk; sigma_p 0.5, 0.75, 1
    eval/reconstruction --quick          # spot at sigma_p 2, one run (seconds; not committed)
    eval/reconstruction --skip-run       # tables and pictures from the last run's JSON

All the work is `spectral-experiments reconstruct-eval` (see
`spectral-experiments reconstruct-eval --help` and experiments/src/reconstruction_eval.rs): per model and sigma_p, the RIMLS surface (sigma_n 0.75) of all
input points against that of a subset chosen by the linear scan with the same kernel (ours) and
by uniform random, voxel-grid and Poisson-disk subsampling at the same count, triangulated by
marching cubes (cell sigma_p/2) and compared Metro-style (RMS and Hausdorff, bbox-100 units).
This script runs it for the main setting (dense surface points) and a variant (the mesh
vertices as input); each reports the distances with and without the restricted domain. It
writes the tables in the layout of Table 2 and renders some reconstructions.

Writes eval/results/reconstruction/: table2.md (all tables and the acceptance check),
reconstruction-*.json (the raw results) and PNG renderings. Meshes (run 0) go to
eval/results/reconstruction/tmp/VARIANT/ (not committed).
"""

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SHARED = ROOT.parent / "shared" / "data"
EXPERIMENTS = os.environ.get(
    "EXPERIMENTS_BIN", str(ROOT / "target" / "release" / "spectral-experiments"))
OUT = HERE / "results" / "reconstruction"
METHODS = ["ours", "random", "voxel", "poisson"]
LABELS = {"ours": "Ours", "random": "Random", "voxel": "Voxel", "poisson": "Poisson"}

# Variants (the input point sets): name -> (extra reconstruct-eval arguments, description).
VARIANTS = {
    "crease": (
        ["--spacing", "0.15", "--crease-angle", "60"],
        "input: area-uniform random points 0.15 apart on average (bbox-100 units); normals: "
        "the mesh's corner normals with a 60° crease angle, interpolated (sharp edges stay sharp)",
    ),
    "dense": (
        ["--spacing", "0.15"],
        "input: area-uniform random points 0.15 apart on average (bbox-100 units); normals: "
        "the vertex normals interpolated (smooth across sharp edges too)",
    ),
    "vertices": (
        [],
        "input: the mesh vertices with their vertex normals",
    ),
}
# Which reconstruction of a subset and which distance: (key path into a method's JSON, label).
# Weighted: the subset reconstructed with the weights of the points it dropped as masses (Sec. 5).
DISTANCES = {
    "weighted": (("weighted", "distance"),
                 "weighted subsets (Sec. 5 weights as masses), restricted domain (surface within "
                 "1.5 σp of a point)"),
    "weighted_no_domain": (("weighted", "distance_no_domain"),
                           "weighted subsets, no restricted domain (every zero crossing where "
                           "RIMLS is defined)"),
    "plain": (("distance",),
              "unweighted subsets (every point mass 1), restricted domain"),
    "plain_no_domain": (("distance_no_domain",),
                        "unweighted subsets, no restricted domain"),
}
# The setting of the headline table and the acceptance check.
PRIMARY = ("crease", "weighted")


def distance_of(run, which):
    """The distance record `which` (a DISTANCES key) of one method run, or None."""
    d = run
    for k in DISTANCES[which][0]:
        d = d.get(k) if d else None
    return d


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--models", default="horse,stanford-bunny,fandisk",
                   help="model names in ../shared/data (OBJ)")
    p.add_argument("--sigma-p", default="0.5,0.75,1", help="sigma_p values, bbox-100 units")
    p.add_argument("--variants", default="crease,dense,vertices",
                   help="which settings to run: " + ", ".join(VARIANTS))
    p.add_argument("--quick", action="store_true",
                   help="spot at sigma_p 2 from points 0.5 apart, one run; writes "
                        "eval/results/reconstruction/quick/")
    p.add_argument("--skip-run", action="store_true", help="reuse the JSON of the last run")
    p.add_argument("--render-model", default="horse,fandisk", help="models of the renderings")
    p.add_argument("--render-sigma", default="1", help="sigma_p of the renderings")
    return p.parse_args()


def run(variant, models, sigmas, out, meshes, quick=False):
    extra, _ = VARIANTS[variant]
    if quick:
        extra = ["--spacing", "0.5", "--crease-angle", "60", "--repeats", "1"]
    json_path = out / f"reconstruction-{variant}.json"
    cmd = [EXPERIMENTS, "reconstruct-eval", *[str(SHARED / f"{m}.obj") for m in models],
           "--sigma-p", sigmas, "--json", str(json_path), *extra]
    if meshes is not None:
        meshes.mkdir(parents=True, exist_ok=True)
        cmd += ["--meshes", str(meshes)]
    print("reconstruction:", " ".join(cmd), file=sys.stderr)
    t = time.perf_counter()
    r = subprocess.run(cmd)
    if r.returncode != 0:
        sys.exit(f"reconstruction: spectral-experiments failed ({r.returncode})")
    seconds = time.perf_counter() - t
    data = json.loads(json_path.read_text())
    # Wall-clock time of the whole run, kept beside the results.
    (out / f"reconstruction-{variant}.seconds").write_text(f"{seconds:.1f}\n")
    return data


def fmt(x, best):
    s = f"{x:.4f}"
    return f"**{s}**" if best else s


def aggregate(sigma, which):
    """Per method: mean RMS and Hausdorff over the repeats, their ranges, the mean count and
    whether every count search reached its tolerance."""
    out = {}
    for m in METHODS:
        runs = [r for r in sigma["methods"] if r["method"] == m]
        if not runs:
            continue
        d = [distance_of(r, which) for r in runs]
        inf = float("inf")
        rms = [x["rms"] if x else inf for x in d]
        haus = [x["hausdorff"] if x else inf for x in d]
        out[m] = {
            "rms": float(np.mean(rms)), "rms_range": (min(rms), max(rms)),
            "hausdorff": float(np.mean(haus)), "hausdorff_range": (min(haus), max(haus)),
            "points": float(np.mean([r["points"] for r in runs])),
            "reached": all(r["reached"] for r in runs),
            "runs": len(runs),
            "per_run": {"rms": rms, "hausdorff": haus},
        }
    return out


def table(data, which):
    """Markdown in the layout of Table 2: rows model x metric, columns sigma_p x method; the
    mean over the repeats."""
    sigmas = [s["sigma_p"] for s in data[0]["sigmas"]]
    head = "| Model | Error | " + " | ".join(
        f"{LABELS[m]} σp={s:g}" for s in sigmas for m in METHODS) + " |"
    sep = "|" + "---|" * (2 + len(sigmas) * len(METHODS))
    lines = [head, sep]
    for model in data:
        aggs = [aggregate(s, which) for s in model["sigmas"]]
        for metric, key in (("RMS", "rms"), ("HAUS", "hausdorff")):
            cells = []
            for agg in aggs:
                low = min(a[key] for a in agg.values())
                cells += [fmt(agg[m][key], agg[m][key] == low) if m in agg else "–" for m in METHODS]
            name = model["model"] if metric == "RMS" else ""
            lines.append(f"| {name} | {metric} | " + " | ".join(cells) + " |")
        counts = []
        for agg in aggs:
            counts += [f"{agg[m]['points']:.0f}" + ("" if agg[m]["reached"] else "*") if m in agg else "–"
                       for m in METHODS]
        lines.append("|  | points | " + " | ".join(counts) + " |")
    return "\n".join(lines)


def context_table(data):
    """Per model and sigma_p: input points, the linear scan's share, the all-points surface
    against the input mesh, holes, times."""
    lines = [
        "| Model | σp | input points | ours keeps | all-points surface: faces | all-points surface to the input mesh: RMS / HAUS (no domain: RMS / HAUS) | boundary edges (run 0) ours / random / voxel / poisson | seconds: all-points surface |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for model in data:
        for s in model["sigmas"]:
            by = {m["method"]: m for m in s["methods"] if m["repeat"] == 0}
            d = s["all_points_to_input"] or {}
            e = s["all_points_to_input_no_domain"] or {}
            holes = " / ".join(str(by[m]["mesh"]["boundary_edges"]) if m in by else "–" for m in METHODS)
            lines.append(
                f"| {model['model']} | {s['sigma_p']:g} | {model['input_points']} | "
                f"{by['ours']['points']} ({100 * by['ours']['points'] / model['input_points']:.1f}%) | "
                f"{s['all_points']['faces']} | {d.get('rms', float('nan')):.4f} / "
                f"{d.get('hausdorff', float('nan')):.4f} ({e.get('rms', float('nan')):.4f} / "
                f"{e.get('hausdorff', float('nan')):.4f}) | {holes} | {s['all_points_seconds']:.1f} |")
    return "\n".join(lines)


def acceptance(data, which):
    """Cell by cell, on the means over the repeats: is ours lowest in RMS and in Hausdorff (a
    tie when equal to 4 decimals, as when every method keeps almost every point), and by how much
    otherwise; and in how many single runs ours had the lowest RMS."""
    lines = []
    wins = {"rms": 0, "hausdorff": 0}
    ties = {"rms": 0, "hausdorff": 0}
    cells = 0
    for model in data:
        for s in model["sigmas"]:
            cells += 1
            agg = aggregate(s, which)
            ours = agg["ours"]
            share = ours["points"] / model["input_points"]
            notes = []
            for key, label in (("rms", "RMS"), ("hausdorff", "Hausdorff")):
                others = {m: a[key] for m, a in agg.items() if m != "ours"}
                best_m = min(others, key=others.get)
                o, b = ours[key], others[best_m]
                if round(o, 4) == round(b, 4):
                    ties[key] += 1
                    notes.append(f"{label} tied with {best_m} ({o:.4f})")
                elif o < b:
                    wins[key] += 1
                    notes.append(f"{label} lowest ({o:.4f}; next {best_m} {b:.4f}, {100 * (b / o - 1):+.0f}%)")
                else:
                    notes.append(f"{label} NOT lowest: ours {o:.4f} vs {best_m} {b:.4f} "
                                 f"(ours {100 * (o / b - 1):+.0f}%)")
            runs = ours["runs"]
            run_wins = sum(
                all(ours["per_run"]["rms"][r] <= a["per_run"]["rms"][r] for m, a in agg.items() if m != "ours")
                for r in range(runs))
            notes.append(f"ours lowest RMS in {run_wins} of {runs} runs; ours RMS over runs "
                         f"{ours['rms_range'][0]:.4f}–{ours['rms_range'][1]:.4f}")
            if share > 0.9:
                notes.append(f"degenerate: ours keeps {100 * share:.0f}% of the input")
            lines.append(f"- {model['model']} σp={s['sigma_p']:g}: " + "; ".join(notes))
    summary = (f"Ours has the strictly lowest mean RMS in {wins['rms']} of {cells} cells (tied in "
               f"{ties['rms']}) and the strictly lowest mean Hausdorff in {wins['hausdorff']} of "
               f"{cells} (tied in {ties['hausdorff']}).")
    counts = {"cells": cells, "wins": wins, "ties": ties}
    return summary, "\n".join(lines), counts


def render(meshes, model, sigma, out_png, suffix=""):
    """The all-points reconstruction and each subsampler's (`suffix` "-weighted": reconstructed
    with the Sec. 5 weights), same camera: full view above, a close-up below; the close-up shaded
    by the distance to the all-points surface."""
    import pyvista as pv
    from scipy.spatial import cKDTree

    pv.OFF_SCREEN = True
    names = ["all"] + METHODS
    files = {n: meshes / f"{model}-s{sigma}-{n}{'' if n == 'all' else suffix}.ply" for n in names}
    if not all(f.exists() for f in files.values()):
        print(f"reconstruction: no meshes for {model} at sigma_p {sigma}; no rendering", file=sys.stderr)
        return False
    ms = {n: pv.read(str(f)) for n, f in files.items()}
    # Distance of each vertex to the all-points surface, from a dense sampling of it (a
    # picture's scale; the table's numbers are exact point-to-triangle distances).
    ref = ms["all"]
    pts = np.asarray(ref.points)
    tri = np.asarray(ref.faces).reshape(-1, 4)[:, 1:]
    rng = np.random.default_rng(1)
    w = rng.dirichlet(np.ones(3), size=(len(tri) * 4,))
    f = np.repeat(np.arange(len(tri)), 4)
    dense = (pts[tri[f, 0]] * w[:, :1] + pts[tri[f, 1]] * w[:, 1:2] + pts[tri[f, 2]] * w[:, 2:])
    tree = cKDTree(np.vstack([pts, dense]))
    bounds = np.array(ref.bounds).reshape(3, 2)
    centre = bounds.mean(axis=1)
    extent = (bounds[:, 1] - bounds[:, 0]).max()
    if model == "horse":
        # The close-up: the highest part, the head and ears.
        top = pts[pts[:, 2] > np.percentile(pts[:, 2], 97)]
        focus = top.mean(axis=0)
    else:
        # The close-up: where the subsets' surfaces together lie farthest from the all-points one
        # (the all-points vertex with the largest sum over the methods of its distance to them).
        total = np.zeros(len(pts))
        for n in METHODS:
            m = ms[n]
            mp = np.asarray(m.points)
            mt = np.asarray(m.faces).reshape(-1, 4)[:, 1:]
            mw = rng.dirichlet(np.ones(3), size=(len(mt) * 4,))
            mf = np.repeat(np.arange(len(mt)), 4)
            md = (mp[mt[mf, 0]] * mw[:, :1] + mp[mt[mf, 1]] * mw[:, 1:2] + mp[mt[mf, 2]] * mw[:, 2:])
            total += cKDTree(np.vstack([mp, md])).query(pts)[0]
        focus = pts[int(np.argmax(total))]
        # Look at it along the surface normal there, tilted a little.
        normals = np.asarray(ref.compute_normals(point_normals=True, cell_normals=False)["Normals"])
        view_dir = normals[int(np.argmax(total))] + np.array([0.3, 0.3, 0.3])
        view_dir /= np.linalg.norm(view_dir)
    p = pv.Plotter(off_screen=True, shape=(2, len(names)), window_size=(380 * len(names), 760), border=False)
    for k, n in enumerate(names):
        m = ms[n]
        d, _ = tree.query(np.asarray(m.points))
        m["distance"] = d
        for row in range(2):
            p.subplot(row, k)
            if row == 0:
                p.add_mesh(m, color="lightgray", smooth_shading=True)
                p.camera.focal_point = centre
                p.camera.position = centre + np.array([extent * 1.9, 0.0, 0.35 * extent])
                p.camera.up = (0, 0, 1)
                label = "all points" if n == "all" else LABELS[n]
                p.add_text(label, font_size=12)
            else:
                p.add_mesh(m, scalars="distance", cmap="viridis", clim=(0, float(sigma) * 0.25),
                           smooth_shading=True, show_scalar_bar=(k == len(names) - 1),
                           scalar_bar_args={"title": "distance to all-points surface", "n_labels": 3})
                p.camera.focal_point = focus
                if model == "horse":
                    p.camera.position = focus + np.array([extent * 0.35, extent * 0.1, extent * 0.12])
                    p.camera.up = (0, 0, 1)
                else:
                    p.camera.position = focus + view_dir * extent * 0.25
                    up = np.cross(view_dir, [1.0, 0.0, 0.0])
                    p.camera.up = tuple(up / np.linalg.norm(up)) if np.linalg.norm(up) > 1e-3 else (0, 0, 1)
    p.screenshot(str(out_png))
    p.close()
    return True


def main():
    args = parse_args()
    if args.quick:
        out = OUT / "quick"
        models, sigmas, variants = ["spot"], "2", ["crease"]
        args.render_model, args.render_sigma = "spot", "2"
        VARIANTS["crease"] = (VARIANTS["crease"][0], "input: area-uniform random points 0.5 apart "
                              "on average (bbox-100 units), 60° crease normals (--quick)")
    else:
        out = OUT
        models, sigmas = args.models.split(","), args.sigma_p
        variants = args.variants.split(",")
    out.mkdir(parents=True, exist_ok=True)
    results = {}
    for v in variants:
        if v not in VARIANTS:
            sys.exit(f"reconstruction: unknown variant {v}")
        path = out / f"reconstruction-{v}.json"
        if args.skip_run and path.exists():
            results[v] = json.loads(path.read_text())
        else:
            results[v] = run(v, models, sigmas, out, out / "tmp" / v, args.quick)

    md = ["# Reconstruction accuracy (Sec. 7.2, Table 2)", "",
          "Generated by `eval/reconstruction` from `spectral-experiments reconstruct-eval`. Per model and σp (bbox-100 "
          "units, the same kernel for sampling and reconstruction, σn = 0.75): the RIMLS surface of a "
          "subset against that of all input points, both triangulated by marching cubes (cell σp/2) "
          "and compared Metro-style (RMS = the worse side's root mean square distance, HAUS = the "
          "symmetric Hausdorff distance; 200,000 random samples per side plus the vertices; bbox-100 "
          "units). Ours = the randomized linear scan alone (Algorithm 1, no resampling) with the same "
          "σp, σn; the others are chosen at its count (* = count search missed its 0.5% tolerance). "
          "Lowest per group in bold.", "",
          "Every subset is reconstructed twice: *unweighted* (every point has mass 1 in RIMLS) and "
          "*weighted*: each kept point carries the weight of the input points it stands for, as "
          "Sec. 5 of the paper prescribes for dropping a point from a kernel sum (each dropped "
          "point's φ(x_j) is projected onto the span of the kept points near it, a = K⁻¹k, and "
          "its weight moves to them: w_i += a_i). The same rule weights every subsampler's "
          "points. The all-points surface has unit masses.", ""]
    summaries = []
    sections = []
    for v in variants:
        data = results[v]
        seconds_file = out / f"reconstruction-{v}.seconds"
        seconds = seconds_file.read_text().strip() if seconds_file.exists() else "?"
        repeats = max(m["repeat"] for m in data[0]["sigmas"][0]["methods"]) + 1
        sections += [f"## `{v}`: {VARIANTS[v][1]}", "",
                     f"Run time: {seconds} s wall (2 cores, shared machine). Means over {repeats} runs "
                     "of every subsampler (different seeds) against one all-points surface.", ""]
        for which, (_, label) in DISTANCES.items():
            if not any(distance_of(r, which) for s_ in data[0]["sigmas"] for r in s_["methods"]):
                continue
            summary, detail, counts = acceptance(data, which)
            summaries.append((v, which, counts))
            sections += [f"### {label}", "", table(data, which), "", summary, "", detail, ""]
        sections += ["### Context", "", context_table(data), ""]
    md += ["## Summary: cells (model × σp) where ours has the lowest mean", "",
           "| input | reconstruction of the subsets | RMS lowest | HAUS lowest |", "|---|---|---|---|"]
    for v, which, c in summaries:
        mark = " (headline)" if (v, which) == PRIMARY else ""
        tie = lambda k: f" (+{c['ties'][k]} tied)" if c["ties"][k] else ""
        md.append(f"| `{v}` | {DISTANCES[which][1]}{mark} | {c['wins']['rms']} of {c['cells']}{tie('rms')} "
                  f"| {c['wins']['hausdorff']} of {c['cells']}{tie('hausdorff')} |")
    md += ["", "Why two input normal fields and two reconstructions of the subsets: with the vertex "
           "normals interpolated (`dense`) the dense points of fandisk have normals averaged across "
           "its sharp edges, so the all-points surface rounds them and the feature-adaptive "
           "sampling (σn = 0.75) has no sharp feature left to keep; with corner normals "
           "(`crease`) the edges stay sharp in the input and in its reconstruction. With unit "
           "masses, a subset's RIMLS average over-counts the places where it kept more points "
           "than elsewhere (for the linear scan: where normals turn, such as a small fin "
           "artifact on the horse's tail, where it leaves a blob); the Sec. 5 weights undo that. "
           "The `dense`, unweighted rows are the earlier protocol. Hausdorff distances are set "
           "by single places (ear tips, the tail's root, small fragments of the all-points "
           "surface itself), so a difference of a few percent there is within the spread "
           "between runs.", ""]
    if PRIMARY[0] in results:
        summary, detail, _ = acceptance(results[PRIMARY[0]], PRIMARY[1])
        md += [f"## Headline: `{PRIMARY[0]}`, {DISTANCES[PRIMARY[1]][1]}", "",
               table(results[PRIMARY[0]], PRIMARY[1]), "", summary, "", detail, ""]
    md += sections
    render_variant = PRIMARY[0] if PRIMARY[0] in variants else variants[0]
    for render_model in args.render_model.split(","):
        for suffix, label in (("-weighted", "weighted subsets"), ("", "unweighted subsets")):
            png = out / f"{render_model}-s{args.render_sigma}-{render_variant}{suffix}.png"
            if render(out / "tmp" / render_variant, render_model, args.render_sigma, png, suffix):
                md += [f"## Renderings: {render_model} at σp = {args.render_sigma} (`{render_variant}`, "
                       f"{label}, run 0)", "",
                       f"![reconstructions]({png.name})", "",
                       "Top: the whole model; bottom: a close-up (horse: the head; otherwise where the "
                       "subsets' surfaces together lie farthest from the all-points one), coloured by the "
                       "distance to the all-points surface (0 to σp/4 = "
                       f"{float(args.render_sigma) / 4:g} bbox-100 units; nearest of a dense sampling, "
                       "for the picture only).", ""]
    (out / "table2.md").write_text("\n".join(md))
    print(f"reconstruction: wrote {out / 'table2.md'}", file=sys.stderr)


if __name__ == "__main__":
    main()
