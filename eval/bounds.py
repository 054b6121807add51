"""The bounds of issue 17 at default settings, seeds 1-5: every angle in [35°, 100°], Qave >= 0.94,
Hausdorff <= 0.2% of the input's bounding-box diagonal, the vertex count within 1% of --points;
and (issue 55) no self-intersection by CGAL's `self_intersections` (eval/cgal_ruler.py), beside
our report's count.

Runs `remesh IN OUT --points N --seed S --report R.json` (the release binary, or $REMESH_BIN) on
the shared models at the eval harness's counts and writes a table per model (one row per seed,
the worst and median seed, and whether each bound holds at every seed) to
eval/results/bounds/bounds.md and bounds.json.

    eval/.venv/bin/python3 eval/bounds.py [--models horse,spot] [--seeds 1,2,3,4,5] [--out DIR]
"""

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import cgal_ruler
from compare import DEFAULT_MODELS, HERE, REMESH, SHARED

# The models of the eval harness and their counts, by name.
MODELS = [(Path(m).stem, n) for m, n in DEFAULT_MODELS]
THETA_MIN, THETA_MAX, Q_AVE, HAUSDORFF_PCT_DIAG, COUNT_PCT = 35.0, 100.0, 0.94, 0.2, 1.0


def diagonal_bbox100(path):
    """The input's bounding-box diagonal in bbox-100 units (longest side 100)."""
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                p = np.array([float(x) for x in line.split()[1:4]])
                lo, hi = np.minimum(lo, p), np.maximum(hi, p)
    return 100.0 * np.linalg.norm(hi - lo) / (hi - lo).max()


def run(model, n, seed, work):
    """One remesh run: the report's figures and the wall time of the whole process."""
    out, rep = work / f"{model}-{seed}.obj", work / f"{model}-{seed}.json"
    t = time.perf_counter()
    subprocess.run(
        [REMESH, str(SHARED / f"{model}.obj"), str(out), "--points", str(n), "--seed", str(seed),
         "--report", str(rep), "-q"],
        check=True,
    )
    seconds = time.perf_counter() - t
    r = json.loads(rep.read_text())
    t = r["triangles"]
    cgal = cgal_ruler.check(out)
    return {
        "pairs": r["self_intersections"]["pairs"],
        "cgal_pairs": cgal["pairs"],
        "cgal_error": cgal["error"],
        "cgal_agrees": cgal_ruler.agrees(r, cgal),
        "seed": seed,
        "theta_min": t["theta_min"],
        "theta_max": t["theta_max"],
        "q_ave": t["q_ave"],
        "hausdorff": r["distance"]["hausdorff"],
        "rms": r["distance"]["rms"],
        "vertices": r["topology"]["vertices"],
        "seconds": seconds,
    }


def verdicts(rows, n, diag):
    """Per bound: (holds at every seed, the worst value)."""
    h_bound = HAUSDORFF_PCT_DIAG / 100.0 * diag
    worst_count = max(abs(r["vertices"] - n) / n * 100.0 for r in rows)
    return {
        f"θmin ≥ {THETA_MIN:g}": (bool(min(r["theta_min"] for r in rows) >= THETA_MIN), f"{min(r['theta_min'] for r in rows):.2f}"),
        f"θmax ≤ {THETA_MAX:g}": (max(r["theta_max"] for r in rows) <= THETA_MAX, f"{max(r['theta_max'] for r in rows):.2f}"),
        f"Qave ≥ {Q_AVE:g}": (min(r["q_ave"] for r in rows) >= Q_AVE, f"{min(r['q_ave'] for r in rows):.4f}"),
        f"Hausdorff ≤ {h_bound:.3f} (0.2% diag)": (max(r["hausdorff"] for r in rows) <= h_bound, f"{max(r['hausdorff'] for r in rows):.3f}"),
        f"count within {COUNT_PCT:g}%": (worst_count <= COUNT_PCT, f"{worst_count:.2f}%"),
        "CGAL finds no self-intersection": (
            all(r["cgal_pairs"] == 0 for r in rows),
            f"{max((r['cgal_pairs'] for r in rows if r['cgal_pairs'] is not None), default='-')} pairs"
            + ("" if all(r["cgal_agrees"] for r in rows) else ", disagrees with our report")),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--models", default=None, help="comma-separated model names (default: all seven)")
    ap.add_argument("--seeds", default="1,2,3,4,5")
    ap.add_argument("--out", default=str(HERE / "results" / "bounds"))
    args = ap.parse_args()
    models = MODELS if not args.models else [m for m in MODELS if m[0] in args.models.split(",")]
    seeds = [int(s) for s in args.seeds.split(",")]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    lines = ["# Issue 17's bounds at default settings", "",
             f"`remesh IN OUT --points N --seed S` (release), seeds {args.seeds}; Hausdorff and RMS from the report "
             "(bbox-100 units, two-sided); seconds: the whole process, with the report's distance measurement.", ""]
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for model, n in models:
            diag = diagonal_bbox100(SHARED / f"{model}.obj")
            rows = [run(model, n, s, Path(tmp)) for s in seeds]
            v = verdicts(rows, n, diag)
            results[model] = {"count": n, "diagonal": float(diag), "rows": rows,
                              "bounds": {k: {"holds": bool(ok), "worst": w} for k, (ok, w) in v.items()}}
            lines += [f"## {model} at {n} (diagonal {diag:.1f})", "",
                      "| seed | θmin | θmax | Qave | Hausdorff | RMS | V | crossing pairs (ours / CGAL) | seconds |",
                      "|---|---|---|---|---|---|---|---|---|"]
            for r in rows:
                lines.append(f"| {r['seed']} | {r['theta_min']:.2f} | {r['theta_max']:.2f} | {r['q_ave']:.4f} | "
                             f"{r['hausdorff']:.3f} | {r['rms']:.4f} | {r['vertices']} | "
                             f"{r['pairs']} / {'-' if r['cgal_pairs'] is None else r['cgal_pairs']} | {r['seconds']:.2f} |")
            med = lambda k: statistics.median(r[k] for r in rows)
            lines.append(f"| median | {med('theta_min'):.2f} | {med('theta_max'):.2f} | {med('q_ave'):.4f} | "
                         f"{med('hausdorff'):.3f} | {med('rms'):.4f} | {med('vertices'):.0f} | | {med('seconds'):.2f} |")
            lines.append("")
            for k, (ok, w) in v.items():
                lines.append(f"- {k}: {'holds' if ok else 'NOT met'} (worst seed: {w})")
            lines.append("")
            print(f"{model}: " + "; ".join(f"{k} {'ok' if ok else 'NO'} ({w})" for k, (ok, w) in v.items()), flush=True)
    (out / "bounds.md").write_text("\n".join(lines))
    (out / "bounds.json").write_text(json.dumps(results, indent=1))
    all_ok = all(b["holds"] for m in results.values() for b in m["bounds"].values())
    sys.exit(0 if all_ok else 1)


if __name__ == "__main__":
    main()
