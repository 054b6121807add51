"""Thin parts and topology (issue 15's acceptance sweep): does the output keep the input's surface?

Run through eval/topology (it sets up the venv and builds remesh):

    eval/topology                     # every shared model at 2000, harness, 30000; seeds 1-5; shapes
    eval/topology --quick             # 2000 only, seeds 1-2, spot, cow, fandisk and the shapes
    eval/topology --models cow,spot.glb --counts harness --seeds 1-3 --no-shapes
    eval/topology --distance --jobs 2 # also the Hausdorff distance; two runs at a time

Every run is `remesh IN OUT --points N --seed S -q --no-distance --report R.json` (without
--no-distance when --distance is given); nothing else is measured than what the report says.

Models: the shared models in ../shared/data (horse, stanford-bunny, fandisk, spot.obj, spot.glb,
cow, beetle, bracket, flange) at 2000 points, at the eval harness count (horse 8600,
stanford-bunny 9635, fandisk 6000, spot 3000, cow 3000, beetle 8000, bracket 4000, flange 6000)
and at 30000. Generated shapes (written as OBJ into a temporary folder, checked with
`remesh quality` before use; at 2000 points only):
  plate-0.1      plate 100 x 100 x 0.1 (closed box)
  plate-1        plate 100 x 100 x 1
  cylinder       closed cylinder, radius 0.1, length 100 (16 sides)
  two-boxes      two 10 x 10 x 10 boxes 2.5 apart (two components; the gap is 11% of the
                 bounding box, wider than the sample spacing at 2000 points)
  two-boxes-100  two 100 x 100 x 100 boxes 2.5 apart (the gap is 1.2% of the bounding box,
                 below the sample spacing: the case where boxes fuse)
  two-sheets     two open 10 x 10 squares 0.05 apart, facing away from each other
                 (two components, one boundary loop each)
  cone           cone of apex angle 2.9 degrees (half-angle 1.45), height 100, base closed
Input edges are at most 1/20 of the part's length, and at most about 10 times the part's
thickness (or the edge across it); the cone's apex fan has 4 triangles of 2.3 degrees there,
its developed angle (9.1 degrees) over 4.

One row per model x count, the seeds aggregated: worst (and median) per column, and the seeds
that fail any of issue 15's checks. "topology kept" counts the seeds whose report has no
topology_changes (remesh's own comparison of components, Euler characteristic and boundary
loops with the input's). Then issue 15's acceptance per row, PASS/FAIL with the figure:
  topology   every seed keeps components, Euler characteristic and boundary loops
  clean      0 non-manifold edges and vertices, 0 crossing face pairs, 0 degenerate faces
  angles     theta_min >= 25 degrees and %theta<30 <= 0.1 at every seed
  cow 3000   theta_min >= 30 degrees (cow at its harness count only)
  count      vertex count within 1% of the asked count at every seed
A run that fails (non-zero exit, no report, timeout) is a failing seed; its error line is in
the table. Writes eval/results/topology/topology.md and topology.json (--quick:
topology-quick.md and topology-quick.json).
"""

import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SHARED = ROOT.parent / "shared" / "data"
REMESH = os.environ.get("REMESH_BIN", str(ROOT / "target" / "release" / "remesh"))
OUT = HERE / "results" / "topology"

# The shared models in issue 15's order, with the eval harness count (eval/README.md, issue 15).
MODELS = [
    ("horse.obj", 8600),
    ("stanford-bunny.obj", 9635),
    ("fandisk.obj", 6000),
    ("spot.obj", 3000),
    ("spot.glb", 3000),
    ("cow.obj", 3000),
    ("beetle.obj", 8000),
    ("bracket.obj", 4000),
    ("flange.obj", 6000),
]
QUICK_MODELS = ["spot.obj", "cow.obj", "fandisk.obj"]
SHAPE_COUNT = 2000

# Issue 15's thresholds.
THETA_MIN = 25.0
PCT_BELOW_30 = 0.1
COW_THETA_MIN = 30.0
COUNT_TOLERANCE = 1.0  # percent


# ---------------------------------------------------------------------------------------------
# Generated shapes


class MeshBuilder:
    """Vertices welded by position (rounded to 1e-9), triangles as index triples."""

    def __init__(self):
        self.index = {}
        self.vertices = []
        self.faces = []

    def vertex(self, p):
        key = tuple(round(c, 9) + 0.0 for c in p)
        i = self.index.get(key)
        if i is None:
            i = len(self.vertices)
            self.index[key] = i
            self.vertices.append(key)
        return i

    def triangle(self, a, b, c):
        ia, ib, ic = self.vertex(a), self.vertex(b), self.vertex(c)
        if len({ia, ib, ic}) == 3:
            self.faces.append((ia, ib, ic))

    def grid(self, origin, u, v, nu, nv):
        """A parallelogram origin + s u + t v, s, t in [0, 1], as nu x nv quads split into
        triangles along alternating diagonals; the normal is u x v."""

        def at(i, j):
            s, t = i / nu, j / nv
            return [origin[k] + s * u[k] + t * v[k] for k in range(3)]

        for i in range(nu):
            for j in range(nv):
                p00, p10, p11, p01 = at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)
                if (i + j) % 2 == 0:
                    self.triangle(p00, p10, p11)
                    self.triangle(p00, p11, p01)
                else:
                    self.triangle(p00, p10, p01)
                    self.triangle(p10, p11, p01)

    def box(self, lo, size, n):
        """A closed axis-aligned box, outward normals, n[k] segments along axis k."""
        x0, y0, z0 = lo
        sx, sy, sz = size
        nx, ny, nz = n
        X, Y, Z = [sx, 0, 0], [0, sy, 0], [0, 0, sz]
        self.grid([x0, y0, z0], Y, X, ny, nx)  # bottom, -z
        self.grid([x0, y0, z0 + sz], X, Y, nx, ny)  # top, +z
        self.grid([x0, y0, z0], X, Z, nx, nz)  # front, -y
        self.grid([x0, y0 + sy, z0], Z, X, nz, nx)  # back, +y
        self.grid([x0, y0, z0], Z, Y, nz, ny)  # left, -x
        self.grid([x0 + sx, y0, z0], Y, Z, ny, nz)  # right, +x

    def write_obj(self, path):
        lines = [f"# {path.name}: generated by eval/topology.py"]
        lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in self.vertices]
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in self.faces]
        path.write_text("\n".join(lines) + "\n")


def segments(length, longest):
    return max(1, math.ceil(length / longest - 1e-9))


def plate(thickness):
    """100 x 100 x thickness; edges at most min(100/20, 10 thickness)."""
    m = MeshBuilder()
    n = segments(100, min(100 / 20, 10 * thickness))
    m.box([0, 0, 0], [100, 100, thickness], [n, n, 1])
    return m


def two_boxes(side):
    """Two side x side x side boxes 2.5 apart along x."""
    m = MeshBuilder()
    n = segments(side, side / 20)
    m.box([0, 0, 0], [side, side, side], [n, n, n])
    m.box([side + 2.5, 0, 0], [side, side, side], [n, n, n])
    return m


def two_sheets():
    """Two open 10 x 10 squares 0.05 apart; the lower faces -z, the upper +z."""
    m = MeshBuilder()
    n = segments(10, 10 / 20)
    m.grid([0, 0, 0], [0, 10, 0], [10, 0, 0], n, n)
    m.grid([0, 0, 0.05], [10, 0, 0], [0, 10, 0], n, n)
    return m


def ring(radius, z, sides, phase=0.0):
    return [
        [radius * math.cos(2 * math.pi * (k + phase) / sides), radius * math.sin(2 * math.pi * (k + phase) / sides), z]
        for k in range(sides)
    ]


def tube(m, radius_at, z0, z1, sides, rings):
    """The side of a surface of revolution about z from z0 to z1 (radius_at(z) > 0 there), outward
    normals, rings + 1 circles, neighbouring circles turned half a side against each other."""
    circles = []
    for j in range(rings + 1):
        z = z0 + (z1 - z0) * j / rings
        circles.append(ring(radius_at(z), z, sides, 0.5 * j))
    for j in range(rings):
        a, b = circles[j], circles[j + 1]
        for k in range(sides):
            k1 = (k + 1) % sides
            m.triangle(a[k], a[k1], b[k])
            m.triangle(a[k1], b[k1], b[k])
    return circles


def cap(m, circle, center, outward_up):
    """A fan closing a circle; normal +z when outward_up, else -z."""
    n = len(circle)
    for k in range(n):
        k1 = (k + 1) % n
        if outward_up:
            m.triangle(center, circle[k], circle[k1])
        else:
            m.triangle(center, circle[k1], circle[k])


def cylinder():
    """Radius 0.1, length 100, closed; 16 sides, rings at most 10 side lengths apart."""
    m = MeshBuilder()
    r, length, sides = 0.1, 100.0, 16
    rings = segments(length, min(length / 20, 10 * 2 * r * math.sin(math.pi / sides)))
    circles = tube(m, lambda z: r, 0.0, length, sides, rings)
    cap(m, circles[0], [0, 0, 0], False)
    cap(m, circles[-1], [0, 0, length], True)
    return m


def cone():
    """Apex angle 2.9 degrees (half-angle 1.45), height 100, apex at z = 100, base at z = 0 closed
    by a fan with a ring at half the radius. Rings at distance t from the apex are min(5, t / 10)
    apart (down to t = 1), 16 sides, halved to 8 and 4 on the last rings so the apex fan's
    triangles have 2.3 degree angles there (the cone's developed angle, 9.1 degrees, over 4) and
    no ring has edges more than about 10 times longer along than across."""
    m = MeshBuilder()
    height = 100.0
    slope = math.tan(math.radians(2.9 / 2))
    ts = [height]
    while ts[-1] > 1.0:
        ts.append(ts[-1] - min(5.0, ts[-1] / 10))
    sides = [16] * len(ts)
    sides[-2], sides[-1] = 8, 4
    circles = [ring(slope * t, height - t, n) for t, n in zip(ts, sides)]
    for a, b in zip(circles, circles[1:]):  # a toward the base, b toward the apex
        if len(a) == len(b):
            n = len(a)
            for k in range(n):
                k1 = (k + 1) % n
                m.triangle(a[k], a[k1], b[k])
                m.triangle(a[k1], b[k1], b[k])
        else:  # len(a) == 2 len(b)
            n = len(b)
            for j in range(n):
                j1 = (j + 1) % n
                m.triangle(a[2 * j], a[2 * j + 1], b[j])
                m.triangle(a[2 * j + 1], b[j1], b[j])
                m.triangle(a[2 * j + 1], a[(2 * j + 2) % (2 * n)], b[j1])
    cap(m, circles[-1], [0, 0, height], True)
    base = circles[0]
    inner = ring(slope * height / 2, 0.0, len(base))
    for k in range(len(base)):  # the annulus between the base circle and the inner ring, normal -z
        k1 = (k + 1) % len(base)
        m.triangle(base[k], inner[k], base[k1])
        m.triangle(base[k1], inner[k], inner[k1])
    cap(m, inner, [0, 0, 0], False)
    return m


# name -> (builder, expected (components, Euler characteristic, boundary loops), description)
SHAPES = {
    "plate-0.1": (lambda: plate(0.1), (1, 2, 0), "plate 100 x 100 x 0.1"),
    "plate-1": (lambda: plate(1.0), (1, 2, 0), "plate 100 x 100 x 1"),
    "cylinder": (cylinder, (1, 2, 0), "closed cylinder r 0.1, length 100"),
    "two-boxes": (lambda: two_boxes(10), (2, 4, 0), "two 10-cubes 2.5 apart"),
    "two-boxes-100": (lambda: two_boxes(100), (2, 4, 0), "two 100-cubes 2.5 apart (gap 1.2% of the bbox)"),
    "two-sheets": (two_sheets, (2, 2, 2), "two open 10 x 10 sheets 0.05 apart"),
    "cone": (cone, (1, 2, 0), "cone, apex angle 2.9°, height 100, base closed"),
}


def make_shapes(names, folder):
    """Writes the shapes as OBJ and checks them with `remesh quality --json`; returns
    {name: (path, input summary)}. Exits when a shape is not the clean mesh it should be."""
    made = {}
    for name in names:
        build, (components, chi, loops), _ = SHAPES[name]
        m = build()
        path = folder / f"{name}.obj"
        m.write_obj(path)
        r = subprocess.run([REMESH, "quality", str(path), "--json"], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"topology: remesh quality {path} failed:\n{r.stderr}")
        q = json.loads(r.stdout)
        t = q["topology"]
        problems = []
        if (t["components"], t["euler_characteristic"], t["boundary_loops"]) != (components, chi, loops):
            problems.append(
                f"components/chi/loops {t['components']}/{t['euler_characteristic']}/{t['boundary_loops']},"
                f" expected {components}/{chi}/{loops}"
            )
        for key in ("non_manifold_edges", "non_manifold_vertices", "degenerate_faces", "duplicate_faces",
                    "unreferenced_vertices", "inconsistent_orientation_edges"):
            if t.get(key):
                problems.append(f"{key} {t[key]}")
        pairs = (q.get("self_intersections") or {}).get("pairs")
        if pairs:
            problems.append(f"{pairs} crossing face pairs")
        if problems:
            sys.exit(f"topology: the generated {name} is not clean: {'; '.join(problems)}")
        longest = longest_edge(m)
        made[name] = (path, {
            "vertices": t["vertices"],
            "faces": t["faces"],
            "components": t["components"],
            "euler_characteristic": t["euler_characteristic"],
            "boundary_loops": t["boundary_loops"],
            "theta_min": q["triangles"]["theta_min"],
            "longest_edge": longest,
        })
    return made


def longest_edge(m):
    best = 0.0
    for f in m.faces:
        for a, b in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
            best = max(best, math.dist(m.vertices[a], m.vertices[b]))
    return best


# ---------------------------------------------------------------------------------------------
# Runs


def run_one(job, work, distance, timeout, extra=()):
    """One remesh run; returns a flat record of what issue 15 checks (or the error line)."""
    label, path, count, seed = job
    stem = f"{label.replace('.', '_')}-{count}-s{seed}"
    out = work / f"{stem}.obj"
    report = work / f"{stem}.json"
    cmd = [REMESH, str(path), str(out), "--points", str(count), "--seed", str(seed), "-q", "--report", str(report)]
    if not distance:
        cmd.insert(-2, "--no-distance")
    cmd[3:3] = list(extra)
    rec = {"model": label, "count": count, "seed": seed, "command": " ".join(["remesh"] + cmd[1:])}
    start = time.monotonic()
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        rec["error"] = f"timed out after {timeout} s"
        return rec
    rec["seconds"] = round(time.monotonic() - start, 2)
    if r.returncode != 0 or not report.exists():
        lines = [l for l in (r.stderr or r.stdout).splitlines() if l.strip()]
        rec["error"] = f"exit {r.returncode}: " + (lines[-1].strip() if lines else "no output")
        return rec
    try:
        rep = json.loads(report.read_text())
    except (OSError, ValueError) as e:
        rec["error"] = f"unreadable report: {e}"
        return rec
    finally:
        for p in (out, report):
            p.unlink(missing_ok=True)
    t, i, tri = rep["topology"], rep.get("input_topology") or {}, rep["triangles"]
    rec.update({
        "vertices": t["vertices"],
        "off_target_pct": 100.0 * (t["vertices"] - count) / count,
        "topology_changes": rep.get("topology_changes") or [],
        "components": t["components"],
        "euler_characteristic": t["euler_characteristic"],
        "boundary_loops": t["boundary_loops"],
        "input": [i.get("components"), i.get("euler_characteristic"), i.get("boundary_loops")],
        "non_manifold_edges": t["non_manifold_edges"],
        "non_manifold_vertices": t["non_manifold_vertices"],
        "degenerate_faces": t["degenerate_faces"],
        "duplicate_faces": t.get("duplicate_faces", 0),
        "crossing_pairs": (rep.get("self_intersections") or {}).get("pairs"),
        "theta_min": tri["theta_min"],
        "pct_theta_below_30": tri["pct_theta_below_30"],
        "q_min": tri["q_min"],
        "q_ave": tri["q_ave"],
        "invariant_violations": [v.get("kind") for v in rep.get("invariant_violations") or []],
    })
    d = rep.get("distance")
    if d:
        rec["hausdorff"] = d.get("hausdorff")
    return rec


# ---------------------------------------------------------------------------------------------
# Checks and the table


def checks_of(rec, cow_harness):
    """Issue 15's checks on one run: {check: bool} (a failed run fails every check)."""
    if "error" in rec:
        names = ["topology", "clean", "angles", "count"] + (["cow 3000"] if cow_harness else [])
        return {n: False for n in names}
    c = {
        "topology": not rec["topology_changes"],
        "clean": rec["non_manifold_edges"] == 0 and rec["non_manifold_vertices"] == 0
        and (rec["crossing_pairs"] or 0) == 0 and rec["degenerate_faces"] == 0,
        "angles": rec["theta_min"] >= THETA_MIN and rec["pct_theta_below_30"] <= PCT_BELOW_30,
        "count": abs(rec["off_target_pct"]) <= COUNT_TOLERANCE,
    }
    if cow_harness:
        c["cow 3000"] = rec["theta_min"] >= COW_THETA_MIN
    return c


def change_text(ch):
    short = {"Components": "C", "EulerCharacteristic": "χ", "BoundaryLoops": "loops"}
    return f"{short.get(ch.get('kind'), ch.get('kind'))} {ch.get('input')}→{ch.get('output')}"


def g(x, digits=1):
    return "–" if x is None else f"{x:.{digits}f}"


def aggregate(label, count, kind, recs, cow_harness):
    ok = [r for r in recs if "error" not in r]
    row = {"model": label, "count": count, "kind": kind, "seeds": [r["seed"] for r in recs],
           "errors": {r["seed"]: r["error"] for r in recs if "error" in r}}
    per_seed = {r["seed"]: checks_of(r, cow_harness) for r in recs}
    row["failing_seeds"] = sorted(s for s, c in per_seed.items() if not all(c.values()))
    names = list(next(iter(per_seed.values())).keys())
    row["checks"] = {n: all(c[n] for c in per_seed.values()) for n in names}
    if ok:
        def col(key):
            return [r[key] for r in ok if r.get(key) is not None]

        off = col("off_target_pct")
        row.update({
            "input": ok[0]["input"],
            "off_target_worst_pct": max(off, key=abs),
            "off_target_median_pct": statistics.median(off),
            "topology_kept": sum(1 for r in ok if not r["topology_changes"]),
            "changes": {r["seed"]: [change_text(c) for c in r["topology_changes"]] for r in ok if r["topology_changes"]},
            "non_manifold_worst": max(r["non_manifold_edges"] + r["non_manifold_vertices"] for r in ok),
            "non_manifold_edges_worst": max(col("non_manifold_edges")),
            "non_manifold_vertices_worst": max(col("non_manifold_vertices")),
            "crossing_worst": max(col("crossing_pairs"), default=None),
            "crossing_median": statistics.median(col("crossing_pairs")) if col("crossing_pairs") else None,
            "degenerate_worst": max(col("degenerate_faces")),
            "theta_min_worst": min(col("theta_min")),
            "theta_min_median": statistics.median(col("theta_min")),
            "pct_below_30_worst": max(col("pct_theta_below_30")),
            "pct_below_30_median": statistics.median(col("pct_theta_below_30")),
            "q_ave_median": statistics.median(col("q_ave")),
            "q_ave_worst": min(col("q_ave")),
        })
        if col("hausdorff"):
            row["hausdorff_worst"] = max(col("hausdorff"))
            row["hausdorff_median"] = statistics.median(col("hausdorff"))
    return row


def changes_cell(row):
    if not row.get("changes"):
        return ""
    seen = {}
    for seed, chs in sorted(row["changes"].items()):
        key = ", ".join(chs)
        seen.setdefault(key, []).append(seed)
    return "; ".join(f"{k} (s{','.join(str(s) for s in v)})" for k, v in seen.items())


def table(rows, distance):
    head = ["model", "N", "input C/χ/b", "off target % worst (med)", "topology kept", "changes",
            "non-manifold e+v", "crossing pairs worst (med)", "degenerate", "θmin worst (med)",
            "%θ<30 worst (med)", "Qave med (worst)"]
    if distance:
        head.append("Hausdorff worst (med)")
    head.append("failing seeds")
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        n = len(row["seeds"])
        fail = ", ".join(str(s) for s in row["failing_seeds"]) or "none"
        errors = "; ".join(f"s{s}: {e}" for s, e in sorted(row["errors"].items())).replace("|", "\\|")
        if "theta_min_worst" not in row:
            cells = [row["model"], str(row["count"])] + ["–"] * (len(head) - 3) + [f"{fail} ({errors})"]
            lines.append("| " + " | ".join(cells) + " |")
            continue
        inp = "/".join("?" if v is None else str(v) for v in row["input"])
        cells = [
            row["model"], str(row["count"]), inp,
            f"{row['off_target_worst_pct']:+.2f} ({row['off_target_median_pct']:+.2f})",
            f"{row['topology_kept']}/{n}",
            changes_cell(row),
            f"{row['non_manifold_edges_worst']}+{row['non_manifold_vertices_worst']}",
            f"{g(row['crossing_worst'], 0)} ({g(row['crossing_median'], 0)})",
            str(row["degenerate_worst"]),
            f"{row['theta_min_worst']:.1f} ({row['theta_min_median']:.1f})",
            f"{row['pct_below_30_worst']:.3f} ({row['pct_below_30_median']:.3f})",
            f"{row['q_ave_median']:.3f} ({row['q_ave_worst']:.3f})",
        ]
        if distance:
            cells.append(f"{g(row.get('hausdorff_worst'), 3)} ({g(row.get('hausdorff_median'), 3)})")
        cells.append(fail + (f" (errors: {errors})" if errors else ""))
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def acceptance(rows):
    head = ["model", "N", "topology equal", "0 non-manifold, crossings, degenerate",
            f"θmin ≥ {THETA_MIN:g}, %θ<30 ≤ {PCT_BELOW_30:g}", f"cow 3000 θmin ≥ {COW_THETA_MIN:g}",
            "vertices within 1%", "all"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    passed = 0
    for row in rows:
        c = row["checks"]
        n = len(row["seeds"])
        nerr = len(row["errors"])
        err = f", {nerr} failed run{'s' if nerr > 1 else ''}" if nerr else ""

        def verdict(name, figure):
            if name not in c:
                return "–"
            return f"{'PASS' if c[name] else 'FAIL'} ({figure}{err})"

        if "theta_min_worst" in row:
            topo = f"{row['topology_kept']}/{n} seeds"
            clean = (f"nm {row['non_manifold_worst']}, crossings {g(row['crossing_worst'], 0)}, "
                     f"degenerate {row['degenerate_worst']}")
            angles = f"θmin {row['theta_min_worst']:.1f}, %θ<30 {row['pct_below_30_worst']:.3f}"
            cow = f"θmin {row['theta_min_worst']:.1f}"
            count = f"{row['off_target_worst_pct']:+.2f}%"
        else:
            topo = clean = angles = cow = count = "no report"
        all_ok = all(c.values())
        passed += all_ok
        lines.append("| " + " | ".join([
            row["model"], str(row["count"]), verdict("topology", topo), verdict("clean", clean),
            verdict("angles", angles), verdict("cow 3000", cow), verdict("count", count),
            "PASS" if all_ok else "FAIL",
        ]) + " |")
    return lines, passed


# ---------------------------------------------------------------------------------------------


def parse_seeds(text):
    seeds = []
    for part in text.split(","):
        part = part.strip()
        if "-" in part:
            a, b = part.split("-", 1)
            seeds += list(range(int(a), int(b) + 1))
        elif part:
            seeds.append(int(part))
    return sorted(dict.fromkeys(seeds))


def model_file(name):
    name = name.strip()
    return name if Path(name).suffix else name + ".obj"


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--models", default=None,
                   help="comma-separated shared models (horse, spot.glb, ...; no extension means .obj)"
                        " or paths to meshes (count 'harness' is then 2000 unless NAME:COUNT); default: all nine")
    p.add_argument("--counts", default="2000,harness,30000",
                   help="comma-separated point counts; 'harness' is the model's eval harness count")
    p.add_argument("--seeds", default="1-5", help="seeds, e.g. 1-5 or 1,3,4")
    p.add_argument("--shapes", action=argparse.BooleanOptionalAction, default=True,
                   help="also the generated shapes at 2000 points (default: yes)")
    p.add_argument("--shape-list", default=",".join(SHAPES), help="which generated shapes")
    p.add_argument("--distance", action="store_true", help="also measure the Hausdorff distance (slower)")
    p.add_argument("--jobs", type=int, default=1, choices=[1, 2], help="runs at a time (default 1)")
    p.add_argument("--timeout", type=float, default=3600, help="seconds one run may take")
    p.add_argument("--remesh-args", default="",
                   help="more options for every run, e.g. '--triangulation restricted'")
    p.add_argument("--quick", action="store_true",
                   help="a fast look: 2000 only, seeds 1-2, spot, cow, fandisk and the shapes;"
                        " writes topology-quick.md/json")
    p.add_argument("--keep-shapes", default=None, help="write the generated shapes to this folder and keep them")
    p.add_argument("--out", default=None, help="output name stem in eval/results/topology/ (default: topology"
                                                " or topology-quick)")
    args = p.parse_args()
    if args.quick:
        args.counts = "2000"
        args.seeds = "1-2"
        if args.models is None:
            args.models = ",".join(QUICK_MODELS)
    return args


def main():
    args = parse_args()
    if not Path(REMESH).exists():
        sys.exit(f"topology: no remesh binary at {REMESH} (run through eval/topology, or set REMESH_BIN)")
    seeds = parse_seeds(args.seeds)
    harness = dict(MODELS)
    names = [model_file(m) for m in args.models.split(",")] if args.models else [m for m, _ in MODELS]
    models = []
    for name in names:
        spec_count = None
        if ":" in name and not Path(name).exists():
            name, spec_count = name.rsplit(":", 1)
            name = model_file(name)
        path = SHARED / name if (SHARED / name).exists() else Path(name)
        if not path.exists():
            sys.exit(f"topology: no model {name} (looked in {SHARED} and as a path)")
        label = path.name if path.parent == SHARED else str(path)
        models.append((label, path, int(spec_count) if spec_count else harness.get(path.name, SHAPE_COUNT)))

    counts_spec = [c.strip() for c in args.counts.split(",") if c.strip()]
    jobs, kinds = [], {}
    for label, path, h in models:
        counts = []
        for c in counts_spec:
            n = h if c == "harness" else int(c)
            if n not in counts:
                counts.append(n)
            kinds[(label, n)] = "harness" if c == "harness" else kinds.get((label, n), "fixed")
        for n in counts:
            for s in seeds:
                jobs.append((label, path, n, s))

    stem = args.out or ("topology-quick" if args.quick else "topology")
    OUT.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix="remesh-topology-"))
    try:
        shapes_info = {}
        if args.shapes:
            shape_names = [s.strip() for s in args.shape_list.split(",") if s.strip()]
            for s in shape_names:
                if s not in SHAPES:
                    sys.exit(f"topology: no shape {s} (known: {', '.join(SHAPES)})")
            folder = Path(args.keep_shapes) if args.keep_shapes else tmp / "shapes"
            folder.mkdir(parents=True, exist_ok=True)
            made = make_shapes(shape_names, folder)
            for s in shape_names:
                path, info = made[s]
                shapes_info[s] = info
                print(f"shape {s}: {info['vertices']} vertices, {info['faces']} faces, C/χ/b "
                      f"{info['components']}/{info['euler_characteristic']}/{info['boundary_loops']}, "
                      f"θmin {info['theta_min']:.1f}, longest edge {info['longest_edge']:.3g}", flush=True)
                kinds[(s, SHAPE_COUNT)] = "shape"
                for seed in seeds:
                    jobs.append((s, path, SHAPE_COUNT, seed))
        work = tmp / "runs"
        work.mkdir()
        print(f"topology: {len(jobs)} runs of {REMESH}, {args.jobs} at a time", flush=True)
        done = [0]

        def go(job):
            rec = run_one(job, work, args.distance, args.timeout, args.remesh_args.split())
            done[0] += 1
            if "error" in rec:
                what = "ERROR " + rec["error"]
            else:
                what = (f"{rec['vertices']} v, C/χ/b {rec['components']}/{rec['euler_characteristic']}/"
                        f"{rec['boundary_loops']}, crossings {rec['crossing_pairs']}, θmin {rec['theta_min']:.1f}"
                        f"{', changes ' + ', '.join(change_text(c) for c in rec['topology_changes']) if rec['topology_changes'] else ''}"
                        f", {rec['seconds']} s")
            print(f"[{done[0]}/{len(jobs)}] {job[0]} {job[2]} s{job[3]}: {what}", flush=True)
            return rec

        with ThreadPoolExecutor(max_workers=args.jobs) as pool:
            records = list(pool.map(go, jobs))  # in the order of jobs, whatever finishes first
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    groups = {}
    for rec in records:
        groups.setdefault((rec["model"], rec["count"]), []).append(rec)
    rows = []
    for (label, count), recs in groups.items():
        cow_harness = label == "cow.obj" and kinds.get((label, count)) == "harness"
        rows.append(aggregate(label, count, kinds.get((label, count)), recs, cow_harness))

    version = subprocess.run([REMESH, "--version"], capture_output=True, text=True).stdout.strip()
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    acc, passed = acceptance(rows)
    title = "Thin parts and topology (issue 15)" + (" — quick run" if args.quick else "")
    argv = " ".join(sys.argv[1:])
    md = [
        f"# {title}",
        "",
        f"`{('eval/topology ' + argv).strip()}`: {version}, commit {commit}{' (with local changes)' if dirty else ''},"
        f" seeds {args.seeds}, counts {args.counts}{', shapes at 2000' if args.shapes else ''};"
        f" {len(records)} runs of `remesh IN OUT --points N --seed S -q{'' if args.distance else ' --no-distance'} --report R.json`.",
        "",
        "One row per model × count, the seeds aggregated: worst and, in brackets, median. *input C/χ/b*: the"
        " input's components, Euler characteristic and boundary loops as remesh reads it. *topology kept*: seeds"
        " whose report lists no topology_changes (remesh's comparison of components, χ and boundary loops with the"
        " input's; C components, χ Euler characteristic, loops boundary loops, input→output, with the seeds)."
        " *non-manifold e+v*: worst non-manifold edges + worst non-manifold vertices. *crossing pairs*: the"
        " report's exact self-intersection count. θmin in degrees, %θ<30 in percent of faces."
        " *failing seeds*: seeds that fail any check below.",
        "",
    ] + table(rows, args.distance) + [
        "",
        f"## Issue 15's acceptance per row: {passed} of {len(rows)} rows pass every check",
        "",
        "A check passes when it holds at every seed; the figure is the worst seed's."
        " (*cow 3000* applies to cow at its harness count only.)",
        "",
    ] + acc
    if shapes_info:
        md += ["", "## Generated shapes (inputs, checked clean with `remesh quality`)", "",
               "| shape | what | vertices | faces | C/χ/b | θmin | longest edge |", "|---|---|---|---|---|---|---|"]
        for s, info in shapes_info.items():
            md.append(f"| {s} | {SHAPES[s][2]} | {info['vertices']} | {info['faces']} | {info['components']}/"
                      f"{info['euler_characteristic']}/{info['boundary_loops']} | {info['theta_min']:.1f} | "
                      f"{info['longest_edge']:.3g} |")
    text = "\n".join(md) + "\n"
    print()
    print(text)
    (OUT / f"{stem}.md").write_text(text)
    (OUT / f"{stem}.json").write_text(json.dumps({
        "command": f"eval/topology {argv}".strip(),
        "remesh": version, "commit": commit, "seeds": seeds, "counts": args.counts,
        "shapes": shapes_info, "rows": rows, "runs": records,
    }, indent=1, ensure_ascii=False))
    print(f"wrote {OUT}/{stem}.md and {stem}.json")


if __name__ == "__main__":
    main()
