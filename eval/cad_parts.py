"""CAD parts made in code by CSG (PyPI `manifold3d`) for eval/features (issue 59), each with the
creases it is built to have known: the edges whose faces turn by `CREASE_TURN_DEG` or more. Curved
surfaces are tessellated finely enough (`SEGMENTS` around a full circle: a turn of at most 7.5°
between neighbouring facets) that none of their edges is a crease, so the expected creases are
exactly the edges where the construction puts two surfaces together.

- `hex_nut`: a hexagonal prism (across flats 17.3) with a through bore, its corners chamfered by a
  30° cone at both ends, which meets the end faces in a circle of 0.95 times the across-flats
  radius (the chamfer's crease curves are arcs made of many short edges);
- `chamfered_block`: a 40 × 30 × 15 block, 45° chamfers on its four vertical and four top
  edges, three vertical through holes and one horizontal;
- `gear`: 20 trapezoidal teeth extruded 8 high, a bore through it;
- `dihedral_part`: a block whose top is two planes meeting at a 179° dihedral (a turn of 1°, no
  crease) with a fin whose tip is a 1° dihedral (a turn of 179°, a crease of a 1° corner).

Units are model units (the parts are 20-60 long). Each part is written as OBJ by `write_parts`.
`noisy` makes a part as a CAD export with noise in its positions (`NAME~A` in eval/features).
"""

import math
from pathlib import Path

import numpy as np

CREASE_TURN_DEG = 20.0
SEGMENTS = 48


def _mesh(m):
    out = m.to_mesh()
    V = np.asarray(out.vert_properties, dtype=np.float64)[:, :3]
    F = np.asarray(out.tri_verts, dtype=np.int64)
    return V, F


def hex_nut():
    from manifold3d import Manifold

    r_corner = 10.0  # across corners 20, across flats 17.3
    height = 8.0
    prism = Manifold.cylinder(height, r_corner, r_corner, 6)
    bore = Manifold.cylinder(height + 2.0, 5.0, 5.0, SEGMENTS).translate((0, 0, -1.0))
    # The 30° chamfer: a cone meeting each end face in a circle of 0.95 times the across-flats
    # radius (as a nut's bearing face), widening inwards past the corners.
    flats = r_corner * math.cos(math.pi / 6)
    r0 = 0.95 * flats
    slope = math.tan(math.radians(30.0))
    rise = (r_corner + 1.0 - r0) * slope
    steps = 4 * SEGMENTS
    wide = r0 + rise / slope
    low = Manifold.cylinder(rise, r0, wide, steps)
    mid = Manifold.cylinder(height - 2 * rise, wide, wide, steps).translate((0, 0, rise))
    high = Manifold.cylinder(rise, wide, r0, steps).translate((0, 0, height - rise))
    return _mesh((prism ^ (low + mid + high)) - bore)


def chamfered_block():
    from manifold3d import Manifold

    a, b, c, ch = 40.0, 30.0, 15.0, 3.0
    block = Manifold.cube((a, b, c))
    cutters = []
    big = 2 * ch / math.sqrt(2)
    # Vertical edges: a square prism turned 45° about z, centred on each vertical edge.
    for x, y in [(0, 0), (a, 0), (0, b), (a, b)]:
        cutters.append(
            Manifold.cube((big, big, c + 2), center=True).rotate((0, 0, 45)).translate((x, y, c / 2))
        )
    # Top edges: along x at y = 0 and y = b, along y at x = 0 and x = a.
    for y in (0.0, b):
        cutters.append(Manifold.cube((a + 2, big, big), center=True).rotate((45, 0, 0)).translate((a / 2, y, c)))
    for x in (0.0, a):
        cutters.append(Manifold.cube((big, b + 2, big), center=True).rotate((0, 45, 0)).translate((x, b / 2, c)))
    holes = [
        Manifold.cylinder(c + 2, 3.0, 3.0, SEGMENTS).translate((x, y, -1))
        for x, y in [(10, 10), (20, 20), (30, 10)]
    ]
    # One horizontal hole along x, below the vertical ones' level of the top chamfers.
    holes.append(Manifold.cylinder(a + 2, 2.0, 2.0, SEGMENTS).rotate((0, 90, 0)).translate((-1, 26.5, 6.0)))
    part = block
    for k in cutters + holes:
        part = part - k
    return _mesh(part)


def gear():
    from manifold3d import CrossSection, Manifold

    teeth, r_root, r_tip, height = 20, 18.0, 22.0, 8.0
    pts = []
    for k in range(teeth):
        a0 = 2 * math.pi * k / teeth
        w = 2 * math.pi / teeth
        # Root arc, flank up, tip land, flank down (a trapezoid per tooth).
        for frac, r in [(0.0, r_root), (0.25, r_root), (0.4, r_tip), (0.6, r_tip), (0.75, r_root)]:
            a = a0 + frac * w
            pts.append((r * math.cos(a), r * math.sin(a)))
    profile = CrossSection([pts])
    body = Manifold.extrude(profile, height)
    bore = Manifold.cylinder(height + 2, 6.0, 6.0, SEGMENTS).translate((0, 0, -1))
    return _mesh(body - bore)


def dihedral_part():
    from manifold3d import CrossSection, Manifold

    length, width, height = 30.0, 20.0, 10.0
    # The block's profile in the x-z plane: the top turns by 1° at x = 15 (a 179° dihedral).
    ridge = height + (length / 2) * math.tan(math.radians(0.5))
    profile = CrossSection([[(0, 0), (length, 0), (length, height), (length / 2, ridge), (0, height)]])
    block = Manifold.extrude(profile, width).rotate((90, 0, 0)).translate((0, width, 0))
    # The fin: a wedge out of the block's end face x = length, its tip a 1° dihedral.
    reach = 20.0
    fin_profile = CrossSection(
        [[(length - 1.0, 2.0), (length + reach, 2.0), (length - 1.0, 2.0 + (reach + 1.0) * math.tan(math.radians(1.0)))]]
    )
    fin = Manifold.extrude(fin_profile, width - 4.0).rotate((90, 0, 0)).translate((0, width - 2.0, 0))
    return _mesh(block + fin)


PARTS = {
    "hex_nut": hex_nut,
    "chamfered_block": chamfered_block,
    "gear": gear,
    "dihedral_part": dihedral_part,
}


def crease_edges(V, F, turn_deg=CREASE_TURN_DEG):
    """The edges (pairs of vertex indices, the smaller first) whose two faces' normals turn by
    `turn_deg` or more, and boundary or non-manifold edges (none on these closed parts)."""
    T = V[F]
    n = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    face = np.tile(np.arange(len(F)), 3)
    key = np.sort(e, axis=1)
    order = np.lexsort((key[:, 1], key[:, 0]))
    key, face = key[order], face[order]
    out = []
    i = 0
    cos_bound = math.cos(math.radians(turn_deg))
    while i < len(key):
        j = i
        while j < len(key) and (key[j] == key[i]).all():
            j += 1
        if j - i != 2 or float(n[face[i]] @ n[face[i + 1]]) <= cos_bound:
            out.append(tuple(key[i]))
        i = j
    return np.array(out, dtype=np.int64).reshape(-1, 2)


NOISE_SEED = 1


def noisy(name, amplitude):
    """Part `name` as a CAD export with noise in its positions: every vertex moved by a Gaussian
    offset of standard deviation `amplitude` times the bounding box's diagonal (seed
    `NOISE_SEED`). Returns (noisy V, F, clean V): the expected creases are the clean part's
    (`crease_edges` on the clean positions), the connectivity being the same."""
    V, F = PARTS[name]()
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    rng = np.random.default_rng(NOISE_SEED)
    return V + rng.normal(0.0, amplitude * diag, V.shape), F, V


def parse_noisy(spec):
    """`NAME~A` (e.g. `hex_nut~1e-4`) as (NAME, A), else None."""
    name, sep, amplitude = spec.partition("~")
    if not sep or name not in PARTS:
        return None
    return name, float(amplitude)


def write_parts(folder):
    """Writes every part as OBJ in `folder`: {name: path}."""
    from compare import write_obj

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths = {}
    for name, make in PARTS.items():
        V, F = make()
        path = folder / f"{name}.obj"
        write_obj(path, V, F)
        paths[name] = path
    return paths
