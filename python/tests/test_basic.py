"""Tests of the spectral_remesh Python module against the `remesh` command line.

Reads data/spot.obj (part of the checkout) and needs the `remesh` binary: $REMESH_BIN, or built here with `cargo build --release --workspace --bin
remesh` (with --workspace the features resolve as in CI's `cargo test --release --workspace`,
so after it the build is a no-op).
"""

import ast
import inspect
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import spectral_remesh as sr

REPO = Path(__file__).resolve().parents[2]
DATA = REPO / "data"
STUBS = REPO / "python" / "spectral_remesh.pyi"


@pytest.fixture(scope="session")
def spot_path():
    path = DATA / "spot.obj"
    if not path.is_file():
        pytest.fail(f"{path} is missing: it is part of the checkout")
    return path


@pytest.fixture(scope="session")
def spot(spot_path):
    return sr.read(spot_path)


def read_binary_ply(path):
    """The vertex positions and faces of a binary PLY as `remesh` writes it (vertex x y z
    double, nx ny nz float; face list uchar int), parsed here without the library."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert "format binary_little_endian 1.0" in header
    counts = {}
    for line in header:
        if line.startswith("element "):
            _, name, n = line.split()
            counts[name] = int(n)
    props = [line for line in header if line.startswith("property ")]
    assert props == [
        "property double x",
        "property double y",
        "property double z",
        "property float nx",
        "property float ny",
        "property float nz",
        "property list uchar int vertex_indices",
    ], props
    vertex = np.dtype([("p", "<f8", 3), ("n", "<f4", 3)])
    face = np.dtype([("k", "u1"), ("i", "<i4", 3)])
    nv, nf = counts["vertex"], counts["face"]
    v = np.frombuffer(data, vertex, nv, end)
    f = np.frombuffer(data, face, nf, end + nv * vertex.itemsize)
    assert end + nv * vertex.itemsize + nf * face.itemsize == len(data)
    assert (f["k"] == 3).all()
    return v["p"].copy(), f["i"].astype(np.int64)


def without_times(report):
    report = dict(report)
    stages = report.pop("stages")
    return report, [s["stage"] for s in stages]


def test_read_spot(spot):
    V, F = spot
    assert V.dtype == np.float64 and V.shape == (2930, 3)
    assert F.dtype == np.int64 and F.shape == (5856, 3)
    assert V.flags.c_contiguous and F.flags.c_contiguous
    assert np.isfinite(V).all()
    assert F.min() == 0 and F.max() == len(V) - 1


@pytest.mark.parametrize("seed", [1, 7])
def test_remesh_equals_cli(spot, spot_path, remesh_bin, tmp_path, seed):
    """Byte-identical arrays: the CLI's binary PLY (positions as double) against the arrays."""
    out, report_path = tmp_path / "out.ply", tmp_path / "report.json"
    subprocess.run(
        [remesh_bin, spot_path, out, "--points", "2000", "--seed", str(seed), "-q",
         "--report", report_path],
        check=True,
    )
    V, F, report = sr.remesh(*spot, points=2000, seed=seed)
    cli_V, cli_F = read_binary_ply(out)
    assert V.dtype == np.float64 and F.dtype == np.int64
    assert V.shape == cli_V.shape and F.shape == cli_F.shape
    assert V.tobytes() == cli_V.tobytes()
    assert F.tobytes() == cli_F.tobytes()
    assert abs(len(V) - 2000) <= 20
    # The report is the CLI's but for the times.
    assert without_times(report) == without_times(json.loads(report_path.read_text()))
    assert report["extra"]["seed"] == seed


def test_remesh_seed_changes_output(spot):
    a = sr.remesh(*spot, points=500, seed=1, distance=False)
    b = sr.remesh(*spot, points=500, seed=2, distance=False)
    c = sr.remesh(*spot, points=500, seed=1, distance=False)
    assert a[0].tobytes() == c[0].tobytes() and a[1].tobytes() == c[1].tobytes()
    assert a[0].shape != b[0].shape or a[0].tobytes() != b[0].tobytes()
    assert a[2]["distance"] is None


def test_remesh_options_reach_the_pipeline(spot, spot_path, remesh_bin, tmp_path):
    out = tmp_path / "out.ply"
    flags = ["--sigma-p", "4", "--sigma-n", "0.8", "--no-fit", "--smooth", "2",
             "--min-angle", "30", "--max-angle", "120", "--feature-angle", "40",
             "--iterations", "3", "--seed", "5", "--no-distance", "-q"]
    subprocess.run([remesh_bin, spot_path, out, *flags], check=True)
    V, F, report = sr.remesh(
        *spot, sigma_p=4.0, sigma_n=0.8, fit=False, smooth=2, min_angle=30, max_angle=120,
        feature_angle=40, iterations=3, seed=5, distance=False,
    )
    cli_V, cli_F = read_binary_ply(out)
    assert V.tobytes() == cli_V.tobytes() and F.tobytes() == cli_F.tobytes()
    assert report["extra"]["sigma_p"] == 4.0 and report["extra"]["sigma_n"] == 0.8
    assert "fit" not in report["extra"]


QUALITY_KEYS = {
    "triangles", "topology", "self_intersections", "invariant_violations", "distance",
    "input_topology", "topology_changes", "stages", "notes", "extra",
}
TRIANGLE_KEYS = {
    "theta_min", "theta_min_ave", "theta_max", "q_min", "q_ave", "pct_theta_below_30", "p30",
    "faces_measured",
}


def test_quality_equals_cli(spot, spot_path, remesh_bin):
    q = sr.quality(*spot)
    assert set(q) == QUALITY_KEYS
    assert set(q["triangles"]) == TRIANGLE_KEYS
    assert q["distance"] is None and q["input_topology"] is None
    assert q["topology"]["vertices"] == 2930 and q["topology"]["genus"] == 0
    cli = subprocess.run(
        [remesh_bin, "quality", spot_path, "--json"], check=True, stdout=subprocess.PIPE, text=True
    ).stdout
    assert without_times(q) == without_times(json.loads(cli))


def test_quality_with_reference_equals_cli(spot, spot_path, remesh_bin, tmp_path):
    V, F, _ = sr.remesh(*spot, points=1000, distance=False)
    out = tmp_path / "out.ply"
    subprocess.run([remesh_bin, spot_path, out, "--points", "1000", "--no-distance", "-q"], check=True)
    q = sr.quality(V, F, ref=spot)
    assert q["distance"]["hausdorff"] > 0 and q["distance"]["samples_per_side"] == 200000
    cli = subprocess.run(
        [remesh_bin, "quality", out, "--ref", spot_path, "--json"],
        check=True, stdout=subprocess.PIPE, text=True,
    ).stdout
    assert without_times(q) == without_times(json.loads(cli))


def test_non_contiguous_and_other_dtypes_are_read_alike(spot):
    V, F = spot
    wide = np.zeros((len(V), 6))
    wide[:, ::2] = V
    strided = wide[:, ::2]
    assert not strided.flags.c_contiguous
    reversed_rows = V[::-1][::-1]
    fortran = np.asfortranarray(F)
    expected, _ = without_times(sr.quality(V, F))
    for v, f in [
        (strided, F),
        (reversed_rows, fortran),
        (V, F.astype(np.int32)),
        (V, F.astype(np.uint64)),
        (V, F.astype(np.uint32)),
        (V.tolist(), F.tolist()),
    ]:
        assert without_times(sr.quality(v, f))[0] == expected
    # float32 positions are converted exactly.
    v32 = V.astype(np.float32)
    assert without_times(sr.quality(v32, F))[0] == without_times(sr.quality(v32.astype(np.float64), F))[0]


def tetrahedron():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int64)
    return V, F


@pytest.mark.parametrize(
    "V, F, pattern",
    [
        (np.zeros((4, 2)), tetrahedron()[1], r"V must be an array of shape \(n, 3\), got shape \(4, 2\)"),
        (np.zeros(12), tetrahedron()[1], r"V must be an array of shape \(n, 3\), got shape \(12,\)"),
        (tetrahedron()[0], np.zeros((4, 4), dtype=np.int64), r"F must be an array of shape \(m, 3\), got shape \(4, 4\)"),
        (tetrahedron()[0], tetrahedron()[1][:, :, None], r"F must be an array of shape"),
        (tetrahedron()[0].astype(str), tetrahedron()[1], r"V must hold real numbers"),
        (tetrahedron()[0].astype(complex), tetrahedron()[1], r"V must hold real numbers"),
        (tetrahedron()[0], tetrahedron()[1].astype(np.float64), r"F must hold vertex indices \(an integer dtype\), got dtype"),
        (tetrahedron()[0], tetrahedron()[1].astype(bool), r"F must hold vertex indices"),
        (tetrahedron()[0], np.array([[0, 2, 1], [0, 1, 4]]), r"F\[1, 2\] = 4 is not a vertex index: the vertices are numbered 0 to 3"),
        # Issue 56, R13 (e): no vertices at all read "the vertices are numbered 0 to -1".
        (np.zeros((0, 3)), tetrahedron()[1], r"^F\[0, 0\] = 0 is not a vertex index: there are no vertices \(the vertex array is empty\)$"),
        (tetrahedron()[0], np.array([[0, 2, 1], [0, -1, 3]]), r"F\[1, 1\] = -1 is not a vertex index"),
        (tetrahedron()[0], np.array([[0, 2, 1], [0, 2**40, 3]], dtype=np.uint64), r"F\[1, 1\] = 1099511627776 is not a vertex index"),
        (np.array([[0, 0, np.nan], [1, 0, 0], [0, 1, 0], [0, 0, 1]]), tetrahedron()[1], r"mesh: vertex 0 \(0-based\) has a non-finite coordinate"),
        (np.array([[0, 0, 0], [1, 0, 0], [0, np.inf, 0], [0, 0, 1]]), tetrahedron()[1], r"vertex 2 \(0-based\) has a non-finite coordinate"),
        (tetrahedron()[0], np.zeros((0, 3), dtype=np.int64), r"no faces"),
        (tetrahedron()[0], np.array([[0, 0, 1]]), r"no faces \(every triangle is degenerate"),
        ([[0, 0, 0], [1, 0]], tetrahedron()[1], r"."),
    ],
)
def test_bad_arrays_raise_value_error(V, F, pattern):
    for call in (lambda: sr.quality(V, F), lambda: sr.remesh(V, F, points=100, distance=False)):
        with pytest.raises(ValueError, match=pattern):
            call()


def test_bad_reference_raises_value_error():
    V, F = tetrahedron()
    with pytest.raises(ValueError, match=r"ref must be a pair \(V0, F0\)"):
        sr.quality(V, F, ref=V)
    with pytest.raises(ValueError, match=r"ref\[1\]\[0, 0\] = 9 is not a vertex index"):
        sr.quality(V, F, ref=(V, F + 9))
    with pytest.raises(ValueError, match=r"reference: vertex 1 \(0-based\) has a non-finite"):
        sr.quality(V, F, ref=(np.where(np.arange(12).reshape(4, 3) == 3, np.nan, V), F))


@pytest.mark.parametrize(
    "options, pattern",
    [
        ({"points": -5}, r"invalid parameter points: must be an integer >= 0, got -5"),
        ({"points": 2}, r"invalid parameter points"),
        ({"points": 100, "sigma_p": 2.0}, r"give one of `points`, `sigma_p` and `edge_length`"),
        ({"sigma_p": -1.0}, r"invalid parameter sigma_p"),
        ({"sigma_p": float("nan")}, r"invalid parameter sigma_p"),
        ({"sigma_n": 0.0}, r"invalid parameter sigma_n"),
        ({"min_angle": 70}, r"invalid parameter min_angle"),
        ({"max_angle": 50}, r"invalid parameter max_angle"),
        ({"feature_angle": 200}, r"invalid parameter feature_angle"),
        ({"feature_angle": 30, "features": False}, r"give `feature_angle` or `no_features`"),
        ({"triangulation": "voronoi"}, r"invalid parameter triangulation: must be umbrellas, restricted"),
        ({"lfs_factor": -1.0}, r"invalid parameter lfs_factor"),
        ({"chord_error": float("inf")}, r"invalid parameter chord_error"),
        ({"seed": -1}, r"invalid parameter seed"),
        ({"smooth": -1}, r"invalid parameter smooth"),
        ({"max_memory": "1K"}, r"`max_memory`"),
        ({"max_memory": "lots"}, r"invalid parameter max_memory"),
        ({"max_memory": -3}, r"invalid parameter max_memory"),
    ],
)
def test_bad_options_raise_value_error(spot, options, pattern):
    with pytest.raises(ValueError, match=pattern):
        sr.remesh(*spot, distance=False, **options)


def test_unknown_option_raises_type_error(spot):
    with pytest.raises(TypeError):
        sr.remesh(*spot, point=100)


def test_read_errors(tmp_path):
    missing = tmp_path / "missing.obj"
    with pytest.raises(FileNotFoundError, match="missing.obj"):
        sr.read(missing)
    with pytest.raises(OSError):
        sr.read(str(missing))
    text = tmp_path / "mesh.txt"
    text.write_text("1 2 3\n")
    with pytest.raises(ValueError, match=r"mesh.txt: unsupported format"):
        sr.read(text)
    bad = tmp_path / "bad.ply"
    bad.write_bytes(b"not a ply file\n")
    with pytest.raises(ValueError, match=r"bad.ply: not a PLY file"):
        sr.read(bad)
    folder = tmp_path / "folder.obj"
    folder.mkdir()
    with pytest.raises(OSError, match="folder.obj"):
        sr.read(folder)


@pytest.mark.parametrize("ext", [".ply", ".obj", ".off", ".glb", ".stl"])
def test_write_then_read(spot, tmp_path, ext):
    """write goes through the library's writers: .ply, .obj and .off keep every float64; glb and
    stl store float32."""
    V, F = spot
    path = tmp_path / ("spot" + ext)
    sr.write(path, V, F)
    V2, F2 = sr.read(path)
    assert F2.shape == F.shape
    if ext in (".ply", ".obj", ".off"):
        assert np.array_equal(V2, V) and np.array_equal(F2, F)
    else:
        # float32 corners; an STL is a triangle soup, welded again on reading, so its vertices
        # come back in another order: the triangles' corners are compared, in order.
        def corners(V, F):
            c = V[F].reshape(len(F), 9)
            return c[np.lexsort(c.T[::-1])]

        assert np.abs(corners(V2, F2) - corners(V, F)).max() < 1e-5 * np.abs(V).max()


def test_write_errors(spot, tmp_path):
    V, F = spot
    bad = V.copy()
    bad[9, 2] = np.inf
    with pytest.raises(ValueError, match=r"V\[9\]"):
        sr.write(tmp_path / "a.ply", bad, F)
    with pytest.raises(ValueError, match="unsupported format"):
        sr.write(tmp_path / "a.xyz", V, F)
    with pytest.raises(ValueError, match="vertex index"):
        sr.write(tmp_path / "a.ply", V, F + len(V))
    with pytest.raises(OSError, match="no-such-folder"):
        sr.write(tmp_path / "no-such-folder" / "a.ply", V, F)
    # Nothing half-written is left behind.
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_progress_names_each_stage_and_its_exception_comes_back(spot):
    stages = []
    sr.remesh(*spot, points=500, distance=False, progress=stages.append)
    assert stages[0] == "read"
    for stage in ("linear scan", "gradient ascent", "triangulate", "write"):
        assert stage in stages, stages

    class Stop(Exception):
        pass

    calls = []

    def stop_at_scan(stage):
        calls.append(stage)
        if stage == "linear scan":
            raise Stop("enough")

    with pytest.raises(Stop, match="enough"):
        sr.remesh(*spot, points=500, distance=False, progress=stop_at_scan)
    assert calls[-1] == "linear scan"
    with pytest.raises(TypeError, match="callable"):
        sr.remesh(*spot, points=500, progress=3)


def test_ctrl_c_stops_a_job_at_its_next_stage(spot):
    """Issue 36, item 7: Ctrl-C (SIGINT) during `remesh` raises KeyboardInterrupt when the job
    reaches its next stage, not when it ends: the stages it went through stop short of the
    write. From early in the linear scan (the gradient ascent, the triangulation, the
    optimization and the untangling still to come), another thread sends SIGINT every 20 ms
    until the job returns; the handler raises KeyboardInterrupt once (a single signal timed
    from the start of the job came after the last stage now and then on a loaded machine)."""
    import os
    import signal
    import threading

    stages = []
    done = threading.Event()
    raised = []

    def handler(signum, frame):
        if not raised:
            raised.append(signum)
            raise KeyboardInterrupt

    def send():
        while not done.wait(0.02):
            os.kill(os.getpid(), signal.SIGINT)

    sender = threading.Thread(target=send)

    def progress(stage):
        stages.append(stage)
        if stage == "linear scan" and not sender.is_alive():
            sender.start()

    previous = signal.signal(signal.SIGINT, handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            sr.remesh(*spot, points=40000, distance=False, progress=progress)
    finally:
        done.set()
        if sender.is_alive():
            sender.join()
        signal.signal(signal.SIGINT, previous)
    assert "linear scan" in stages and "write" not in stages, stages


def test_sweep_counts_have_upper_bounds(spot):
    """Issue 36, item 5: iterations=10**9 killed the interpreter (an allocation by the count);
    it is a ValueError at once, as is smooth=10**9."""
    with pytest.raises(ValueError, match="iterations"):
        sr.remesh(*spot, points=500, iterations=10**9)
    with pytest.raises(ValueError, match="smooth"):
        sr.remesh(*spot, points=500, smooth=10**9)


def test_gil_is_released(spot, gil_released):
    """Another Python thread runs while remesh works (about 0.6 s here)."""
    gil_released(lambda: sr.remesh(*spot, points=5000, distance=False))


def stub_functions():
    """The stubs' module docstring, each function's documented definition (the last of its
    name: for overloaded functions the general overload), and every definition by name."""
    tree = ast.parse(STUBS.read_text())
    every = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            every.setdefault(node.name, []).append(node)
    return ast.get_docstring(tree), {name: nodes[-1] for name, nodes in every.items()}, every


def stub_parameters(node):
    args = node.args
    stub = [(a.arg, "POSITIONAL_ONLY") for a in args.posonlyargs]
    stub += [(a.arg, "POSITIONAL_OR_KEYWORD") for a in args.args]
    stub += [(a.arg, "KEYWORD_ONLY") for a in args.kwonlyargs]
    return stub


def test_stubs_match_the_module():
    """The stubs' docstrings and signatures are the module's own (pyo3 takes both from the
    Rust source), so the two cannot drift apart. Overloads (`sample`, `resample`: the return
    shape follows `normals` and `return_report`) take the same parameters; the last, general
    one carries the docstring and the defaults."""
    module_doc, functions, every = stub_functions()
    assert inspect.cleandoc(sr.__doc__) == module_doc
    public = {name for name in dir(sr) if not name.startswith("_") and callable(getattr(sr, name))}
    public.discard("spectral_remesh")
    assert public == set(functions)
    assert {name for name, nodes in every.items() if len(nodes) > 1} == {"sample", "resample"}
    for name, nodes in every.items():
        runtime = getattr(sr, name)
        parameters = [(p.name, p.kind.name) for p in inspect.signature(runtime).parameters.values()]
        for node in nodes:
            assert stub_parameters(node) == parameters, name
            overloaded = any(getattr(d, "id", None) == "overload" for d in node.decorator_list)
            assert overloaded == (len(nodes) > 1), name
            if node is not nodes[-1]:
                assert ast.get_docstring(node) is None, name
    for name, node in functions.items():
        runtime = getattr(sr, name)
        assert inspect.getdoc(runtime) == ast.get_docstring(node), name
        signature = inspect.signature(runtime)
        args = node.args
        stub_defaults = [ast.literal_eval(d) for d in args.defaults]
        stub_defaults += [ast.literal_eval(d) for d in args.kw_defaults if d is not None]
        runtime_defaults = [
            p.default for p in signature.parameters.values() if p.default is not p.empty
        ]
        assert runtime_defaults == stub_defaults, name


def test_installed_package_has_stubs():
    package = Path(sr.__file__).parent
    assert (package / "py.typed").is_file()
    assert (package / "__init__.pyi").read_text() == STUBS.read_text()


def test_edge_length_gives_edges_about_that_long(spot):
    # Issue 76: edge_length (model units) instead of points, as `--edge-length`.
    V, F = spot
    V2, F2, report = sr.remesh(V, F, edge_length=0.1, distance=False)
    e = np.concatenate([V2[F2[:, k]] - V2[F2[:, (k + 1) % 3]] for k in range(3)])
    mean = np.linalg.norm(e, axis=1).mean()
    assert abs(mean - 0.1) < 0.01, mean
    assert any("--edge-length 0.1: about" in n for n in report["notes"])
    with pytest.raises(ValueError, match="edge_length"):
        sr.remesh(V, F, edge_length=0.1, points=100)


def test_edge_length_on_a_point_set_gives_edges_about_that_long():
    # A point set's area is known only once its surface is: sigma_p = L / 1.2 (bbox-100).
    rng = np.random.default_rng(1)
    P = rng.normal(size=(20000, 3))
    N = P / np.linalg.norm(P, axis=1)[:, None]
    V2, F2, report = sr.remesh(2.0 * N, normals=N, edge_length=0.25, distance=False)
    e = np.concatenate([V2[F2[:, k]] - V2[F2[:, (k + 1) % 3]] for k in range(3)])
    mean = np.linalg.norm(e, axis=1).mean()
    assert abs(mean - 0.25) < 0.025, mean
    assert any("--edge-length 0.25: sigma_p" in n for n in report["notes"])
