use super::*;
use crate::points::test_support::assert_one_line_naming;
use pcd_rs::{DataKind, DynRecord, DynWriter, Schema, ValueKind, WriterInit};

/// Writes `rows` (x y z, and a fourth float field `intensity`) as a PCD of `kind`, `width` ×
/// `height`, with the sensor at `viewpoint`.
fn write(path: &Path, kind: DataKind, rows: &[[f32; 4]], width: u64, viewpoint: [f64; 3]) {
    let schema = Schema::from_iter([
        ("x", ValueKind::F32, 1),
        ("y", ValueKind::F32, 1),
        ("z", ValueKind::F32, 1),
        ("intensity", ValueKind::F32, 1),
    ]);
    let mut writer: DynWriter<_> = WriterInit {
        width,
        height: rows.len() as u64 / width,
        viewpoint: pcd_rs::ViewPoint {
            tx: viewpoint[0],
            ty: viewpoint[1],
            tz: viewpoint[2],
            ..Default::default()
        },
        data_kind: kind,
        schema: Some(schema),
        version: None,
    }
    .create(path)
    .unwrap();
    for r in rows {
        let record = DynRecord(r.iter().map(|&v| Field::F32(vec![v])).collect());
        writer.push(&record).unwrap();
    }
    writer.finish().unwrap();
}

#[test]
fn the_three_encodings_read_back_the_points_written_and_leave_out_the_pixels_without_depth() {
    let dir = tempfile::tempdir().unwrap();
    // An organized 3 × 2 frame: two pixels without depth (NaN), as a depth camera writes them.
    let nan = f32::NAN;
    let rows = [
        [0.5, -1.25, 2.0, 7.0],
        [nan, nan, nan, 0.0],
        [1.5, 0.25, 2.5, 1.0],
        [-0.75, 3.0, 1.0, 2.0],
        [nan, 1.0, nan, 3.0],
        [2.0, 2.0, 4.0, 4.0],
    ];
    let finite: Vec<DVec3> = rows
        .iter()
        .filter(|r| r[..3].iter().all(|v| v.is_finite()))
        .map(|r| DVec3::new(r[0] as f64, r[1] as f64, r[2] as f64))
        .collect();
    for kind in [
        DataKind::Ascii,
        DataKind::Binary,
        DataKind::BinaryCompressed,
    ] {
        let path = dir.path().join(format!("{kind:?}.pcd"));
        write(&path, kind, &rows, 3, [0.25, -2.0, 10.0]);
        let read = read_pcd(&path).unwrap();
        assert_eq!(read.positions, finite, "{kind:?}");
        assert!(read.normals.is_empty());
        assert_eq!(read.left_out, 2, "{kind:?}");
        assert!(!read.has_normals);
        assert_eq!(read.viewpoint, DVec3::new(0.25, -2.0, 10.0));
        assert_eq!(read_pcd_viewpoint(&path).unwrap(), read.viewpoint);
        // The same through the point reader the pipeline uses.
        let mut reader = crate::points::PointReader::open(&path).unwrap();
        assert_eq!(reader.count(), 4);
        assert_eq!(reader.viewpoint(), Some(DVec3::new(0.25, -2.0, 10.0)));
        let (mut all, mut chunk) = (Vec::new(), Vec::new());
        while reader.read_chunk(&mut chunk, 3).unwrap() > 0 {
            all.extend(chunk.iter().map(|p| p.position));
        }
        assert_eq!(all, finite);
        assert!(crate::points::stream::is_point_set(&path).unwrap());
    }
}

#[test]
fn a_file_without_x_y_z_or_not_pcd_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan.pcd");
    std::fs::write(
        &path,
        "VERSION .7\nFIELDS a b c\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\n\
         VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2 3\n",
    )
    .unwrap();
    let e = read_pcd(&path).unwrap_err().to_string();
    assert!(e.contains("scan.pcd") && e.contains("x y z"), "{e}");
    std::fs::write(&path, "ply\nformat ascii 1.0\n").unwrap();
    let e = read_pcd(&path).unwrap_err().to_string();
    assert_one_line_naming(&e, &["scan.pcd", "PCD"]);
}

/// A grid of `n` × `n` points in the plane z = `z`, spacing `h`, centred on the z axis, with
/// `offset` added.
fn grid(n: usize, z: f32, h: f32, offset: [f32; 2]) -> Vec<[f32; 4]> {
    (0..n)
        .flat_map(|j| {
            (0..n).map(move |i| {
                let c = (n as f32 - 1.0) / 2.0;
                [
                    (i as f32 - c) * h + offset[0],
                    (j as f32 - c) * h + offset[1],
                    z,
                    0.0,
                ]
            })
        })
        .collect()
}

#[test]
fn a_viewpoint_that_did_not_see_the_points_is_not_used_for_their_normals() {
    use crate::points::normals::NormalOrientation;
    use crate::points::source::PointSource;
    let dir = tempfile::tempdir().unwrap();
    // A sheet seen from its VIEWPOINT: taken as the sensor's position.
    let seen = dir.path().join("seen.pcd");
    write(
        &seen,
        DataKind::Binary,
        &grid(60, 10.0, 0.1, [0.0, 0.0]),
        3600,
        [0.0, 0.0, 0.0],
    );
    let (orientation, camera) = PointSource::File(seen).orientation(None).unwrap();
    assert_eq!(orientation, NormalOrientation::Viewpoint(DVec3::ZERO));
    assert!(camera.unwrap().used);
    // Two sheets one behind the other as seen from it (a world frame with the default
    // VIEWPOINT): the spanning tree orients the normals, and the camera is reported unused.
    let mut rows = grid(60, 10.0, 0.1, [0.0, 0.0]);
    rows.extend(grid(60, 20.0, 0.2, [0.05, 0.05]));
    let layered = dir.path().join("layered.pcd");
    write(&layered, DataKind::Binary, &rows, 7200, [0.0, 0.0, 0.0]);
    let (orientation, camera) = PointSource::File(layered).orientation(None).unwrap();
    assert_eq!(orientation, NormalOrientation::SpanningTree);
    let camera = camera.unwrap();
    assert!(!camera.used && camera.hidden > 0.1, "{camera:?}");
    // A viewpoint the user gives is used as given.
    let (orientation, camera) = PointSource::File(dir.path().join("layered.pcd"))
        .orientation(Some(DVec3::Z))
        .unwrap();
    assert_eq!(orientation, NormalOrientation::Viewpoint(DVec3::Z));
    assert!(camera.is_none());
}

/// A PCD header for `fields` (`x y z` of one 4-byte float each unless given) announcing
/// `points` points in `data`, then `payload` as it is.
fn hostile(path: &Path, counts: &str, points: u64, data: &str, payload: &[u8]) {
    let mut bytes = format!(
        "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT {counts}\nWIDTH {points}\n\
         HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {points}\nDATA {data}\n"
    )
    .into_bytes();
    bytes.extend_from_slice(payload);
    std::fs::write(path, bytes).unwrap();
}

/// Issue 76 (R1, R5, R6, R11): a header whose sizes the file cannot hold is refused naming the
/// file before anything it sizes is allocated (at cc1f49d: an abort allocating 4 GB, a panic
/// inside pcd-rs, "failed to fill whole buffer").
#[test]
fn a_header_promising_more_than_the_file_holds_is_refused_before_it_is_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("hostile.pcd");
    let block = |compressed: u32, decompressed: u32, body: &[u8]| {
        let mut b = compressed.to_le_bytes().to_vec();
        b.extend_from_slice(&decompressed.to_le_bytes());
        b.extend_from_slice(body);
        b
    };
    let refused = |mentions: &[&str]| {
        let e = read_pcd(&path).unwrap_err().to_string();
        assert_one_line_naming(&e, &[&["hostile.pcd"], mentions].concat());
        // The memory estimate reads the same header and refuses the same.
        assert_eq!(pcd_payload(&path).unwrap_err().to_string(), e);
    };
    // A block claiming 4 GB decompressed for one point.
    let body = vec![7u8; 37_000];
    hostile(
        &path,
        "1 1 1",
        1,
        "binary_compressed",
        &block(37_000, u32::MAX - 15, &body),
    );
    refused(&["decompresses to 4294967280", "need 12"]);
    // The same with POINTS to match: more than LZF can expand 37 KB to.
    hostile(
        &path,
        "1 1 1",
        357_913_940,
        "binary_compressed",
        &block(37_000, u32::MAX - 15, &body),
    );
    refused(&["more than LZF can expand"]);
    // A block larger than the file, and a block promising more than it holds.
    hostile(
        &path,
        "1 1 1",
        2,
        "binary_compressed",
        &block(1000, 24, &[0; 10]),
    );
    refused(&["compressed block of 1000 bytes"]);
    hostile(
        &path,
        "1 1 1",
        1_000_000_000,
        "binary_compressed",
        &block(10, 24, &[0; 10]),
    );
    refused(&["decompresses to 24 bytes"]);
    // 10^12 points in a binary or ascii payload of a few bytes.
    hostile(&path, "1 1 1", 1_000_000_000_000, "binary", &[0; 90]);
    refused(&["1000000000000 points of 12 bytes"]);
    hostile(&path, "1 1 1", 1_000_000_000_000, "ascii", b"1 2 3\n");
    refused(&["1000000000000 ascii points"]);
    // A coordinate of two values, and a COUNT whose record overflows.
    hostile(&path, "2 1 1", 1, "ascii", b"1 2 3 4\n");
    refused(&["`x` has COUNT 2"]);
    std::fs::write(
        &path,
        "VERSION .7\nFIELDS x y z w\nSIZE 4 4 4 8\nTYPE F F F F\nCOUNT 1 1 1 4611686018427387904\n\
         WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA binary\n",
    )
    .unwrap();
    refused(&["overflows"]);
    // The honest files these were made from read.
    hostile(&path, "1 1 1", 2, "ascii", b"1 2 3\n4 5 6\n");
    assert_eq!(read_pcd(&path).unwrap().positions.len(), 2);
    // COUNT 0 is one value (PCL's convention, which pcd-rs follows).
    hostile(&path, "0 1 1", 2, "ascii", b"1 2 3\n4 5 6");
    assert_eq!(read_pcd(&path).unwrap().positions.len(), 2);
    let binary: Vec<u8> = [1f32, 2., 3., 4., 5., 6.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    hostile(&path, "1 1 1", 2, "binary", &binary);
    assert_eq!(read_pcd(&path).unwrap().positions.len(), 2);
    assert_eq!(pcd_payload(&path).unwrap().points, 2);
}

/// Writes the seeds of the `read_pcd` fuzz target (`fuzz/seeds/read_pcd`: the three
/// encodings, with and without depth) into `$FUZZ_SEEDS/read_pcd`.
#[test]
#[ignore = "writes the fuzz seeds: FUZZ_SEEDS=fuzz/seeds cargo test -- --ignored fuzz_seeds"]
fn write_pcd_fuzz_seeds() {
    let dir = Path::new(&std::env::var("FUZZ_SEEDS").expect("FUZZ_SEEDS")).join("read_pcd");
    std::fs::create_dir_all(&dir).unwrap();
    let rows = [
        [0.5, -1.25, 2.0, 7.0],
        [f32::NAN, 1.0, 2.0, 0.0],
        [1.5, 0.25, 2.5, 1.0],
    ];
    for kind in [
        DataKind::Ascii,
        DataKind::Binary,
        DataKind::BinaryCompressed,
    ] {
        write(
            &dir.join(format!("{kind:?}.pcd")),
            kind,
            &rows,
            3,
            [0.0, 0.0, 1.0],
        );
    }
}
