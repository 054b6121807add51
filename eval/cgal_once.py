"""Whole-process time of remesh against CGAL's isotropic remeshing with one iteration, the
reference of issue 38 (horse -> 8600: ours at most 0.5x CGAL).

    eval/.venv/bin/python3 eval/cgal_once.py [--input ../shared/data/horse.obj] [--points 8600]
                                             [--repeats 5] [--remesh target/release/remesh]

The two are alternated in one sitting (the machine is shared) and timed by GNU time as whole
processes. CGAL's process reads the OBJ, writes and reads an OFF (its Python bindings' only
reader), remeshes once at the edge length of `--points` equilateral vertices over the input's
area, and writes OFF (eval/references.py's `cgal`). Ours is `remesh IN OUT --points N
--no-distance --seed 1 -q`. Prints each run and the medians and their ratio.
"""

import argparse
import statistics
import subprocess
import sys
import tempfile

from references import cgal_child  # the CGAL process, shared with eval/scale


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
