"""Whole-process time of remesh against CGAL's isotropic remeshing with one iteration, the
reference of issue 38 (horse -> 8600: ours at most 0.5x CGAL).

    eval/.venv/bin/python3 eval/cgal_once.py [--input ../shared/data/horse.obj] [--points 8600]
                                             [--repeats 5] [--remesh target/release/remesh]

The two are alternated in one sitting (the machine is shared) and timed by GNU time as whole
processes. CGAL's process reads the OBJ, writes and reads an OFF (its Python bindings' only
reader), remeshes once at the edge length of `--points` equilateral vertices over the input's
area, and writes OFF. Ours is `remesh IN OUT --points N --no-distance --seed 1 -q`. Prints each
run and the medians and their ratio.
"""

import argparse
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path


def cgal_child(src, dst, n):
    import numpy as np
    from CGAL import CGAL_Polygon_mesh_processing as PMP
    from CGAL.CGAL_Polyhedron_3 import Polyhedron_3

    V, F = [], []
    for line in open(src):
        if line.startswith("v "):
            V.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            F.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
    V, F = np.array(V), np.array(F)
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1).sum()
    h = (2 * area / (3**0.5 * n)) ** 0.5  # 2n equilateral triangles of side h cover the area
    off = Path(dst).with_suffix(".in.off")
    with open(off, "w") as f:
        f.write(f"OFF\n{len(V)} {len(F)} 0\n")
        f.writelines(f"{v[0]} {v[1]} {v[2]}\n" for v in V)
        f.writelines(f"3 {t[0]} {t[1]} {t[2]}\n" for t in F)
    P = Polyhedron_3(str(off))
    PMP.isotropic_remeshing([f for f in P.facets()], float(h), P, 1)
    P.write_to_file(str(dst))
    print(P.size_of_vertices())


def timed(cmd):
    r = subprocess.run(["/usr/bin/time", "-f", "%e"] + cmd, capture_output=True, text=True, check=True)
    return float(r.stderr.strip().splitlines()[-1]), r.stdout.strip()


def main():
    if len(sys.argv) == 5 and sys.argv[1] == "--child":
        return cgal_child(sys.argv[2], sys.argv[3], int(sys.argv[4]))
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--input", default="../shared/data/horse.obj")
    p.add_argument("--points", type=int, default=8600)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--remesh", default="target/release/remesh")
    a = p.parse_args()
    ours, theirs = [], []
    with tempfile.TemporaryDirectory() as work:
        for i in range(a.repeats):
            t, nv = timed([sys.executable, __file__, "--child", a.input, f"{work}/cgal.off", str(a.points)])
            theirs.append(t)
            o, _ = timed([a.remesh, a.input, f"{work}/ours.obj", "--points", str(a.points),
                          "--no-distance", "--seed", "1", "-q"])
            ours.append(o)
            print(f"run {i + 1}: CGAL {t:.2f} s ({nv} vertices), remesh {o:.2f} s", flush=True)
    mo, mt = statistics.median(ours), statistics.median(theirs)
    print(f"median: remesh {mo:.2f} s, CGAL 1 iteration {mt:.2f} s, ratio {mo / mt:.2f}")


if __name__ == "__main__":
    main()
