"""The reference remeshers that eval/scale and eval/cgal_once.py time beside remesh, each run as a
whole process that reads an OBJ, remeshes it to about N vertices and writes the result:

    eval/.venv/bin/python3 eval/references.py meshlib IN.obj OUT.obj N   # MeshLib's remesh
    eval/.venv/bin/python3 eval/references.py cgal IN.obj OUT.off N      # CGAL, 1 iteration

Both remesh at the edge length h of N equilateral vertices over the input's area (2N equilateral
triangles of side h cover it) and print the output's vertex count.

- meshlib: `mrmeshpy.loadMesh`, `mrmeshpy.remesh` with `RemeshSettings()` at its defaults but
  `targetEdgeLen = h`, `mrmeshpy.saveMesh` (OBJ). The area is MeshLib's (`Mesh.area()`).
- cgal: CGAL's isotropic remeshing with one iteration on a `Polyhedron_3` (the reference of issue
  38). The OBJ is read here (`v` and `f` lines, triangles only), written as OFF (the Python
  bindings' only reader) and read back by CGAL; the output is written as OFF.

geogram's CVT remeshing is a C++ tool of its own (eval/geogram_cvt.cpp, built by
compare.build_geogram_cvt) and so is not here.
"""

import sys
from pathlib import Path


def equilateral_edge_length(area, n):
    """The side of the equilateral triangles that cover `area` with n vertices (2n triangles)."""
    return (2 * area / (3**0.5 * n)) ** 0.5


def meshlib_child(src, dst, n):
    from meshlib import mrmeshpy as mm

    mesh = mm.loadMesh(str(src))
    settings = mm.RemeshSettings()
    settings.targetEdgeLen = equilateral_edge_length(mesh.area(), n)
    if not mm.remesh(mesh, settings):
        sys.exit("meshlib: remesh returned false")
    mm.saveMesh(mesh, str(dst))
    print(mesh.topology.numValidVerts())


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
    h = equilateral_edge_length(area, n)
    off = Path(dst).with_suffix(".in.off")
    with open(off, "w") as f:
        f.write(f"OFF\n{len(V)} {len(F)} 0\n")
        f.writelines(f"{v[0]} {v[1]} {v[2]}\n" for v in V)
        f.writelines(f"3 {t[0]} {t[1]} {t[2]}\n" for t in F)
    P = Polyhedron_3(str(off))
    if P.size_of_facets() == 0:
        sys.exit("cgal: Polyhedron_3 could not read the input (non-manifold?)")
    PMP.isotropic_remeshing([f for f in P.facets()], float(h), P, 1)
    P.write_to_file(str(dst))
    print(P.size_of_vertices())


CHILDREN = {"meshlib": meshlib_child, "cgal": cgal_child}


def main():
    if len(sys.argv) != 5 or sys.argv[1] not in CHILDREN:
        sys.exit(f"usage: references.py {{{'|'.join(CHILDREN)}}} IN OUT N")
    CHILDREN[sys.argv[1]](sys.argv[2], sys.argv[3], int(sys.argv[4]))


if __name__ == "__main__":
    main()
