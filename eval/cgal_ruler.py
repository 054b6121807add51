"""CGAL's self-intersection test as an independent ruler beside our report (issue 55).

    eval/.venv/bin/python3 eval/cgal_ruler.py MESH [MESH ...]     # one JSON line per mesh

For each mesh (OBJ, OFF or PLY, read as stored: no welding, no vertex merging), CGAL's
`Polygon_mesh_processing.does_self_intersect` and `self_intersections` (cgal 6.0.1's Python
bindings, on a Polyhedron_3 built from the mesh's own vertices and faces; exact predicates,
Epick): `{"path", "self_intersects", "pairs", "error"}`. CGAL's definition is the standard one:
two faces intersect when they share no vertex and meet, share one vertex and meet elsewhere too,
or share an edge and overlap (and a degenerate face counts as intersecting).

`check(path, timeout)` runs it in a child process (CGAL aborts the process on some inputs) and
returns the dict, with `error` set when CGAL could not build a polyhedral surface from the file
(a non-manifold mesh) or did not answer in time. eval/corpus.py, eval/bounds.py and
eval/scans.py put it in a column beside our own count.
"""

import json
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent


def read_mesh(path):
    """Vertices (list of xyz) and triangles (lists of indices) of a mesh file, as stored."""
    path = Path(path)
    if path.suffix.lower() == ".obj":
        v, f = [], []
        with open(path) as fh:
            for line in fh:
                if line.startswith("v "):
                    v.append([float(x) for x in line.split()[1:4]])
                elif line.startswith("f "):
                    idx = [int(x.split("/")[0]) for x in line.split()[1:]]
                    idx = [i - 1 if i > 0 else len(v) + i for i in idx]
                    f.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
        return v, f
    import trimesh

    m = trimesh.load(str(path), process=False, force="mesh")
    return m.vertices.tolist(), m.faces.tolist()


def cgal_in_process(path):
    from CGAL import CGAL_Polygon_mesh_processing as PMP
    from CGAL.CGAL_Polyhedron_3 import Polyhedron_3

    v, f = read_mesh(path)
    out = {"path": str(path), "self_intersects": None, "pairs": None, "error": None}
    if not f:
        out["error"] = "no faces"
        return out
    with tempfile.TemporaryDirectory() as tmp:
        off = Path(tmp) / "m.off"
        with open(off, "w") as fh:
            fh.write(f"OFF\n{len(v)} {len(f)} 0\n")
            fh.writelines(f"{p[0]!r} {p[1]!r} {p[2]!r}\n" for p in v)
            fh.writelines(f"3 {t[0]} {t[1]} {t[2]}\n" for t in f)
        P = Polyhedron_3(str(off))
    if P.size_of_facets() != len(f):
        out["error"] = f"CGAL built {P.size_of_facets()} of {len(f)} faces (not a polyhedral surface)"
        return out
    out["self_intersects"] = bool(PMP.does_self_intersect(P))
    pairs = []
    PMP.self_intersections(P, pairs)
    out["pairs"] = len(pairs)
    return out


def check(path, timeout=120.0):
    """CGAL's answer for the mesh at `path`, from a child process (see the module)."""
    try:
        p = subprocess.run([sys.executable, str(Path(__file__).resolve()), str(path)],
                           capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"path": str(path), "self_intersects": None, "pairs": None,
                "error": f"CGAL took over {timeout:.0f} s"}
    lines = [l for l in p.stdout.splitlines() if l.startswith("{")]
    if p.returncode != 0 or not lines:
        tail = (p.stderr.strip().splitlines() or [f"exit {p.returncode}"])[-1]
        return {"path": str(path), "self_intersects": None, "pairs": None,
                "error": f"CGAL failed: {tail[:200]}"}
    return json.loads(lines[-1])


def agrees(report, cgal):
    """Whether our report (the JSON of `remesh --report` or `remesh quality --json`) and CGAL's
    answer agree: both find nothing, or both find something and the same number of pairs. CGAL
    reports a degenerate face as a pair of its own, our report as an invariant of its own (the
    count of its DegenerateFace violation), so those are added to ours. None when CGAL gave no
    answer."""
    if cgal.get("self_intersects") is None:
        return None
    degenerate = sum(v.get("count", 0) for v in report.get("invariant_violations", [])
                     if v.get("kind") == "DegenerateFace")
    ours = report["self_intersections"]["pairs"] + degenerate
    return (ours > 0) == cgal["self_intersects"] and cgal.get("pairs") in (None, ours)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for path in sys.argv[1:]:
        print(json.dumps(cgal_in_process(path)), flush=True)


if __name__ == "__main__":
    main()
