use super::*;

#[test]
fn a_las_file_written_reads_back_its_points_in_chunks() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("survey.las");
    // Coordinates as a survey's (UTM metres), at the header's scale of a millimetre.
    let written: Vec<DVec3> = (0..1000)
        .map(|i| {
            let t = i as f64;
            DVec3::new(
                500_000.0 + 0.125 * t,
                4_200_000.0 + 0.5 * (t * 0.1).sin(),
                100.0 + 0.001 * t,
            )
        })
        .collect();
    let mut header = las::Builder::default();
    header.transforms = las::Vector {
        x: las::Transform {
            scale: 0.001,
            offset: 500_000.0,
        },
        y: las::Transform {
            scale: 0.001,
            offset: 4_200_000.0,
        },
        z: las::Transform {
            scale: 0.001,
            offset: 0.0,
        },
    };
    let mut writer = las::Writer::from_path(&path, header.into_header().unwrap()).unwrap();
    for p in &written {
        writer
            .write_point(las::Point {
                x: p.x,
                y: p.y,
                z: p.z,
                ..Default::default()
            })
            .unwrap();
    }
    writer.close().unwrap();
    drop(writer);
    let mut reader = crate::points::PointReader::open(&path).unwrap();
    assert_eq!(reader.count(), 1000);
    assert_eq!(reader.viewpoint(), None);
    assert!(!reader.has_normals());
    let (mut all, mut chunk) = (Vec::new(), Vec::new());
    while reader.read_chunk(&mut chunk, 300).unwrap() > 0 {
        all.extend(chunk.iter().map(|p| p.position));
    }
    assert_eq!(all.len(), written.len());
    for (a, b) in all.iter().zip(&written) {
        assert!(a.distance(*b) <= 0.001, "{a} against {b}");
    }
    assert!(crate::points::stream::is_point_set(&path).unwrap());
}

#[test]
fn a_file_that_is_not_las_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan.las");
    std::fs::write(&path, "x y z\n1 2 3\n").unwrap();
    let Err(e) = crate::points::PointReader::open(&path) else {
        panic!("read as LAS");
    };
    let e = e.to_string();
    assert!(e.contains("scan.las") && e.contains("LAS"), "{e}");
    assert!(!e.contains('\n'), "one line: {e}");
}
