use super::*;
use crate::points::normals::NormalOrientation;
use crate::points::source::PointSource;
use crate::points::test_support::assert_one_line_naming;
use e57::{E57Writer, Extension, Quaternion, RecordDataType, RecordValue, Transform, Translation};

/// One scan to write: its pose and its points, each `[x y z]` (cartesian) or `[range azimuth
/// elevation]` (spherical) with its invalid state (0 valid, 1 a direction, 2 no return), and
/// with a normal when the scan has normals.
struct Scan {
    rotation: [f64; 4],
    translation: [f64; 3],
    spherical: bool,
    points: Vec<([f64; 3], i64)>,
    normals: Option<Vec<[f32; 3]>>,
}

/// Writes `scans` as an E57 file with the crate's writer.
fn write(path: &Path, scans: &[Scan]) {
    let mut writer = E57Writer::from_file(path, "file-guid").unwrap();
    if scans.iter().any(|s| s.normals.is_some()) {
        writer
            .register_extension(Extension::new("nor", NORMALS_EXTENSION))
            .unwrap();
    }
    for (k, scan) in scans.iter().enumerate() {
        let mut prototype = if scan.spherical {
            vec![
                Record::SPHERICAL_RANGE_F64,
                Record::SPHERICAL_AZIMUTH_F64,
                Record::SPHERICAL_ELEVATION_F64,
                Record::SPHERICAL_INVALID_STATE,
            ]
        } else {
            vec![
                Record::CARTESIAN_X_F64,
                Record::CARTESIAN_Y_F64,
                Record::CARTESIAN_Z_F64,
                Record::CARTESIAN_INVALID_STATE,
            ]
        };
        if scan.normals.is_some() {
            for axis in ["X", "Y", "Z"] {
                prototype.push(Record {
                    name: RecordName::Unknown {
                        namespace: "nor".into(),
                        name: format!("normal{axis}"),
                    },
                    data_type: RecordDataType::F32,
                });
            }
        }
        let mut cloud = writer
            .add_pointcloud(&format!("scan-guid-{k}"), prototype)
            .unwrap();
        let [w, x, y, z] = scan.rotation;
        let [tx, ty, tz] = scan.translation;
        cloud.set_transform(Some(Transform {
            rotation: Quaternion { w, x, y, z },
            translation: Translation {
                x: tx,
                y: ty,
                z: tz,
            },
        }));
        for (i, &(p, state)) in scan.points.iter().enumerate() {
            let mut values: Vec<RecordValue> = p.iter().map(|&v| RecordValue::Double(v)).collect();
            values.push(RecordValue::Integer(state));
            if let Some(normals) = &scan.normals {
                values.extend(normals[i].iter().map(|&v| RecordValue::Single(v)));
            }
            cloud.add_point(values).unwrap();
        }
        cloud.finalize().unwrap();
    }
    writer.finalize().unwrap();
}

fn assert_close(a: DVec3, b: DVec3) {
    assert!(
        (a - b).length() <= 1e-9 * b.length().max(1.0),
        "{a} against {b}"
    );
}

/// Two scans: one rotated 120° about (1, 1, 1) (the quaternion (½, ½, ½, ½), which takes
/// `x y z` to `z x y`) and moved, one only moved, at a survey's coordinates; each with points of
/// no return (state 2) and a direction without range (state 1).
fn two_scans() -> (Vec<Scan>, Vec<DVec3>) {
    let first: Vec<([f64; 3], i64)> = (0..40)
        .map(|i| {
            let t = i as f64;
            let state = match i % 7 {
                3 => 2,
                5 => 1,
                _ => 0,
            };
            ([1.0 + 0.25 * t, -2.0 + (0.3 * t).sin(), 0.125 * t], state)
        })
        .collect();
    let second: Vec<([f64; 3], i64)> = (0..25)
        .map(|i| {
            let t = i as f64;
            (
                [-3.0 + 0.5 * t, 4.0, 1.5 - 0.0625 * t],
                if i == 10 { 2 } else { 0 },
            )
        })
        .collect();
    let t1 = DVec3::new(500_010.0, 4_200_020.0, 95.5);
    let t2 = DVec3::new(500_040.0, 4_199_980.0, 101.25);
    let mut expected: Vec<DVec3> = first
        .iter()
        .filter(|p| p.1 == 0)
        .map(|&([x, y, z], _)| DVec3::new(z, x, y) + t1)
        .collect();
    expected.extend(
        second
            .iter()
            .filter(|p| p.1 == 0)
            .map(|&([x, y, z], _)| DVec3::new(x, y, z) + t2),
    );
    let scans = vec![
        Scan {
            rotation: [0.5, 0.5, 0.5, 0.5],
            translation: t1.to_array(),
            spherical: false,
            points: first,
            normals: None,
        },
        Scan {
            rotation: [1.0, 0.0, 0.0, 0.0],
            translation: t2.to_array(),
            spherical: false,
            points: second,
            normals: None,
        },
    ];
    (scans, expected)
}

/// [`two_scans`] written to `path`: the points they read back as.
fn write_two_scans(path: &Path) -> Vec<DVec3> {
    let (scans, expected) = two_scans();
    write(path, &scans);
    expected
}

#[test]
fn two_scans_read_back_posed_into_the_files_frame_without_their_invalid_points() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("site.e57");
    let expected = write_two_scans(&path);
    let read = read_e57(&path).unwrap();
    assert_eq!(read.positions.len(), expected.len());
    for (&a, &b) in read.positions.iter().zip(&expected) {
        assert_close(a, b);
    }
    // Scan 1: 40 points, 6 of state 2 and 5 of state 1 (i % 7 = 3, 5); scan 2: one of state 2.
    assert_eq!(read.left_out, 12);
    assert!(!read.has_normals && read.normals.is_empty());
    let sensors: Vec<DVec3> = read.scans.iter().map(|s| s.sensor).collect();
    assert_eq!(
        sensors,
        [
            DVec3::new(500_010.0, 4_200_020.0, 95.5),
            DVec3::new(500_040.0, 4_199_980.0, 101.25)
        ]
    );
    assert_eq!(read.scans[0].points, 0..29);
    assert_eq!(read.scans[1].points, 29..53);
    // Several sensors: no one viewpoint.
    assert_eq!(read.viewpoint(), None);
    assert_eq!(read_e57_viewpoint(&path).unwrap(), None);
}

#[test]
fn an_e57_file_reads_through_the_point_reader_and_the_point_source() {
    let dir = tempfile::tempdir().unwrap();
    // Two scans: the points of both, no viewpoint, so the spanning tree orients the normals.
    let path = dir.path().join("site.e57");
    let expected = write_two_scans(&path);
    let mut reader = crate::points::PointReader::open(&path).unwrap();
    assert_eq!(reader.count(), expected.len() as u64);
    assert_eq!(reader.viewpoint(), None);
    assert!(!reader.has_normals());
    let (mut all, mut chunk) = (Vec::new(), Vec::new());
    while reader.read_chunk(&mut chunk, 10).unwrap() > 0 {
        all.extend(chunk.iter().map(|p| p.position));
    }
    assert_eq!(all.len(), expected.len());
    for (&a, &b) in all.iter().zip(&expected) {
        assert_close(a, b);
    }
    assert!(crate::points::stream::is_point_set(&path).unwrap());
    let source = PointSource::File(path.clone());
    assert_eq!(source.viewpoint().unwrap(), None);
    assert_eq!(
        source.orientation(None).unwrap(),
        (NormalOrientation::SpanningTree, None)
    );

    // One scan in spherical coordinates with normals, rotated 90° about z and moved: its
    // sensor is the viewpoint, and the normals turn with the pose.
    let path = dir.path().join("station.E57");
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let half_pi = std::f64::consts::FRAC_PI_2;
    write(
        &path,
        &[Scan {
            rotation: [h, 0.0, 0.0, h],
            translation: [10.0, -20.0, 1.5],
            spherical: true,
            points: vec![
                ([2.0, 0.0, 0.0], 0),
                ([3.0, half_pi, 0.0], 0),
                ([0.0, 0.0, 0.0], 2),
                ([4.0, 0.0, half_pi], 0),
                ([5.0, half_pi, 0.0], 1),
            ],
            normals: Some(vec![
                [-1.0, 0.0, 0.0],
                [0.0, -2.0, 0.0],
                [0.0, 0.0, 0.0],
                [0.0, 0.0, -1.0],
                [0.0, 0.0, 1.0],
            ]),
        }],
    );
    // (x y z) turned 90° about z is (-y x z).
    let t = DVec3::new(10.0, -20.0, 1.5);
    let expected = [
        (DVec3::new(0.0, 2.0, 0.0) + t, DVec3::new(0.0, -1.0, 0.0)),
        (DVec3::new(-3.0, 0.0, 0.0) + t, DVec3::new(1.0, 0.0, 0.0)),
        (DVec3::new(0.0, 0.0, 4.0) + t, DVec3::new(0.0, 0.0, -1.0)),
    ];
    let mut reader = crate::points::PointReader::open(&path).unwrap();
    assert_eq!(reader.count(), 3);
    assert_eq!(reader.viewpoint(), Some(t));
    assert!(reader.has_normals());
    let mut chunk = Vec::new();
    assert_eq!(reader.read_chunk(&mut chunk, 10).unwrap(), 3);
    for (p, (position, normal)) in chunk.iter().zip(expected) {
        assert_close(p.position, position);
        assert!(
            p.normal.distance(normal) < 1e-6,
            "{} against {normal}",
            p.normal
        );
    }
    assert_eq!(reader.read_chunk(&mut chunk, 10).unwrap(), 0);
    let source = PointSource::File(path.clone());
    assert_eq!(source.viewpoint().unwrap(), Some(t));
    let (orientation, camera) = source.orientation(None).unwrap();
    assert_eq!(orientation, NormalOrientation::Viewpoint(t));
    let camera = camera.unwrap();
    assert_eq!((camera.position, camera.used), (t, true));
    let mut points = source.open().unwrap();
    assert!(points.has_normals());
    assert_eq!(points.read_chunk(&mut chunk, 2).unwrap(), 2);
}

#[test]
fn a_file_that_is_not_e57_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan.e57");
    for content in [&b"x y z\n1 2 3\n"[..], &[0u8; 2048][..]] {
        std::fs::write(&path, content).unwrap();
        for e in [
            read_e57(&path).unwrap_err(),
            read_e57_viewpoint(&path).unwrap_err(),
            crate::points::PointReader::open(&path).err().unwrap(),
        ] {
            assert!(matches!(e, Error::Parse { .. }), "{e:?}");
            let e = e.to_string();
            assert_one_line_naming(&e, &["scan.e57", "E57"]);
        }
    }
    // A file cut short: its XML section is at the end, and gone.
    write_two_scans(&path);
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let e = read_e57(&path).unwrap_err().to_string();
    assert_one_line_naming(&e, &["scan.e57", "E57"]);
}

#[test]
fn corrupted_e57_files_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("source.e57");
    write_two_scans(&source);
    let bytes = std::fs::read(&source).unwrap();
    let mut next = crate::points::test_support::xorshift();
    for round in 0..200 {
        // Cut short, or bytes changed anywhere (a page's checksum finds most of those).
        let mut b = if round % 2 == 0 {
            bytes[..(next() % bytes.len()).max(1)].to_vec()
        } else {
            bytes.clone()
        };
        for _ in 0..1 + round % 3 {
            let at = next() % b.len();
            b[at] = [b' ', b'<', b'0', 0xff, next() as u8][next() % 5];
        }
        let path = dir.path().join(format!("c{round}.e57"));
        std::fs::write(&path, &b).unwrap();
        if let Err(e) = read_e57(&path) {
            let message = e.to_string();
            assert!(message.contains(&format!("c{round}.e57")), "{message}");
            assert_eq!(message.lines().count(), 1, "{message}");
        }
    }
}

/// Issue 76 (R3): a scan whose every record is an integer with minimum = maximum (0 bits a
/// point, legal E57) is refused naming the file: the e57 crate would generate its points
/// without end (at cc1f49d: 8.5 GB in 30 s, then an abort).
#[test]
fn a_scan_stored_in_no_bits_is_refused_not_read_without_end() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("constant.e57");
    // The crate's writer cannot write records of no bits: written with maximum 6, then the
    // XML's maximum set to 5 and the pages' checksums made again.
    let mut writer = E57Writer::from_file(&path, "file-guid").unwrap();
    let prototype = [
        RecordName::CartesianX,
        RecordName::CartesianY,
        RecordName::CartesianZ,
    ]
    .map(|name| Record {
        name,
        data_type: RecordDataType::Integer { min: 5, max: 6 },
    })
    .to_vec();
    let mut cloud = writer.add_pointcloud("scan-guid", prototype).unwrap();
    for _ in 0..10 {
        cloud.add_point(vec![RecordValue::Integer(5); 3]).unwrap();
    }
    cloud.finalize().unwrap();
    writer.finalize().unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    let (from, to) = (b"maximum=\"6\"".as_slice(), b"maximum=\"5\"".as_slice());
    let mut patched = 0;
    for i in 0..bytes.len() - from.len() {
        if &bytes[i..i + from.len()] == from {
            bytes[i..i + to.len()].copy_from_slice(to);
            patched += 1;
        }
    }
    assert_eq!(patched, 3, "the XML's three maxima");
    // E57's pages: 1020 bytes and their CRC-32C (big-endian).
    for page in bytes.chunks_mut(1024) {
        let crc = crc32c(&page[..1020]);
        page[1020..].copy_from_slice(&crc.to_be_bytes());
    }
    std::fs::write(&path, bytes).unwrap();
    let e = read_e57(&path).unwrap_err().to_string();
    assert_one_line_naming(&e, &["constant.e57", "scan 1", "10 points in no bits"]);
    assert_eq!(e57_points(&path).unwrap_err().to_string(), e);
}

/// Issue 76 (R5): a scan announcing more points than the file's bytes can hold is refused
/// before anything is reserved for them (at cc1f49d: 2^26 points reserved from the count, an
/// abort under a 1.5 GB address-space limit).
#[test]
fn a_scan_announcing_more_points_than_the_file_holds_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan.e57");
    std::fs::write(&path, [0u8; 44_000]).unwrap();
    let cloud = |records: u64| {
        let mut pc = PointCloud::default();
        pc.records = records;
        pc.prototype = vec![
            Record::CARTESIAN_X_F64,
            Record::CARTESIAN_Y_F64,
            Record::CARTESIAN_Z_F64,
        ];
        pc
    };
    // 24 bytes a point: 1833 fit in 44,000 bytes, 10^12 do not.
    assert_eq!(held_points(&path, &[cloud(1833)]).unwrap(), 1833);
    let e = held_points(&path, &[cloud(1833), cloud(1_000_000_000_000)])
        .unwrap_err()
        .to_string();
    assert_one_line_naming(&e, &["scan.e57", "scan 2 announces 1000000000000 points"]);
}

/// CRC-32C (Castagnoli), bitwise: the checksum of an E57 page.
fn crc32c(data: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in data {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0x82F6_3B78
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// Writes the seed of the `read_e57` fuzz target (`fuzz/seeds/read_e57`: two scans, one
/// spherical with normals) into `$FUZZ_SEEDS/read_e57`.
#[test]
#[ignore = "writes the fuzz seeds: FUZZ_SEEDS=fuzz/seeds cargo test -- --ignored fuzz_seeds"]
fn write_e57_fuzz_seeds() {
    let dir = Path::new(&std::env::var("FUZZ_SEEDS").expect("FUZZ_SEEDS")).join("read_e57");
    std::fs::create_dir_all(&dir).unwrap();
    let scans = [
        Scan {
            rotation: [1.0, 0.0, 0.0, 0.0],
            translation: [1.0, 2.0, 3.0],
            spherical: false,
            points: vec![([1.0, 2.0, 3.0], 0), ([4.0, 5.0, 6.0], 2)],
            normals: None,
        },
        Scan {
            rotation: [0.0, 0.0, 0.0, 1.0],
            translation: [0.0, 0.0, 0.0],
            spherical: true,
            points: vec![([2.0, 0.5, 0.25], 0), ([3.0, -0.5, 0.0], 1)],
            normals: Some(vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]),
        },
    ];
    write(&dir.join("scans.e57"), &scans);
}
