use super::*;

fn points(n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| Point {
            position: DVec3::new(i as f64, 0.5 * i as f64, -(i as f64)),
            normal: DVec3::new(0.0, 0.0, 1.0),
        })
        .collect()
}

#[test]
fn written_points_read_back_in_chunks() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.ply");
    let mut w = PlyPointWriter::create(&path, 10).unwrap();
    w.write(&points(4)).unwrap();
    w.write(&points(10)[4..]).unwrap();
    w.finish().unwrap();
    let mut r = PointReader::open(&path).unwrap();
    assert_eq!(r.count(), 10);
    assert!(r.has_normals());
    let (mut all, mut chunk) = (Vec::new(), Vec::new());
    while r.read_chunk(&mut chunk, 3).unwrap() > 0 {
        all.extend_from_slice(&chunk);
    }
    assert_eq!(all, points(10));
    // Only the file itself is left in the folder.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// Two writers of one point file at once (the same process, so the same process id, which
/// named the temporary file before): each finishes its own file, and the target is one of
/// the two, complete.
#[test]
fn two_writers_of_one_target_do_not_collide() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.ply");
    let sets: Vec<Vec<Point>> = (0..2)
        .map(|k| {
            let mut p = points(50_000);
            p.iter_mut().for_each(|q| q.position.y = k as f64);
            p
        })
        .collect();
    let barrier = std::sync::Barrier::new(2);
    std::thread::scope(|s| {
        for set in &sets {
            let (path, barrier) = (&path, &barrier);
            s.spawn(move || {
                let mut w = PlyPointWriter::create(path, set.len() as u64).unwrap();
                barrier.wait();
                for chunk in set.chunks(1000) {
                    w.write(chunk).unwrap();
                }
                w.finish().unwrap();
            });
        }
    });
    let mut r = PointReader::open(&path).unwrap();
    let (mut all, mut chunk) = (Vec::new(), Vec::new());
    while r.read_chunk(&mut chunk, 4096).unwrap() > 0 {
        all.extend_from_slice(&chunk);
    }
    assert!(sets.contains(&all), "a mixed or partial file");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn ascii_without_normals_and_extra_properties() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.ply");
    std::fs::write(
        &path,
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty uchar red\n\
         property float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\n\
         end_header\n1 255 2 3\n4 0 5 6\n",
    )
    .unwrap();
    let mut r = PointReader::open(&path).unwrap();
    assert!(!r.has_normals());
    let mut chunk = Vec::new();
    assert_eq!(r.read_chunk(&mut chunk, 10).unwrap(), 2);
    assert_eq!(chunk[1].position, DVec3::new(4.0, 5.0, 6.0));
    assert_eq!(chunk[1].normal, DVec3::ZERO);
}

#[test]
fn a_truncated_file_and_a_short_write_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.ply");
    let mut w = PlyPointWriter::create(&path, 5).unwrap();
    w.write(&points(5)).unwrap();
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 10]).unwrap();
    // Found when the file is opened, from its length (issue 36, item 4: a header's count is
    // checked before anything is sized by it).
    let err = PointReader::open(&path).err().unwrap().to_string();
    assert!(err.contains("truncated") && err.contains("t.ply"), "{err}");
    // Issue 14, item 11: the message gives the complete points before the end (4 of 5
    // here) and the count the header promised.
    assert!(
        err.contains("announces 5 points, the file holds at most 4"),
        "{err}"
    );
    let short = dir.path().join("short.ply");
    let mut w = PlyPointWriter::create(&short, 5).unwrap();
    w.write(&points(2)).unwrap();
    assert!(w.finish().is_err());
    assert!(!short.exists());
}

#[test]
fn elements_before_the_vertices_are_skipped() {
    // A range map's header: a `camera` element (scalars) before `vertex`, faces after.
    let dir = tempfile::tempdir().unwrap();
    let head = "ply\nformat binary_little_endian 1.0\nelement camera 2\nproperty float a\n\
                property int b\nproperty uchar c\nelement vertex 2\nproperty float x\n\
                property float y\nproperty float z\nelement face 1\n\
                property list uchar int vertex_indices\nend_header\n";
    let mut bytes = head.as_bytes().to_vec();
    bytes.extend(std::iter::repeat_n(0xAB, 2 * 9));
    for v in [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0] {
        bytes.extend(v.to_le_bytes());
    }
    bytes.push(3);
    for i in [0i32, 1, 1] {
        bytes.extend(i.to_le_bytes());
    }
    let path = dir.path().join("range.ply");
    std::fs::write(&path, &bytes).unwrap();
    let mut r = PointReader::open(&path).unwrap();
    let mut out = Vec::new();
    assert_eq!(r.read_chunk(&mut out, 10).unwrap(), 2);
    assert_eq!(out[1].position, DVec3::new(4.0, 5.0, 6.0));
    // It has faces: a mesh, unless asked for as points.
    assert!(!is_point_set(&path).unwrap());
    // In ascii, one line per entry.
    let ascii = "ply\nformat ascii 1.0\nelement camera 1\nproperty float a\n\
                 element vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
                 end_header\n9 9 9 9\n1 2 3\n";
    let path = dir.path().join("ascii.ply");
    std::fs::write(&path, ascii).unwrap();
    let mut r = PointReader::open(&path).unwrap();
    assert_eq!(r.read_chunk(&mut out, 10).unwrap(), 1);
    assert_eq!(out[0].position, DVec3::new(1.0, 2.0, 3.0));
    assert!(is_point_set(&path).unwrap());
}

#[test]
fn a_range_maps_camera_gives_the_viewpoint() {
    // VCG's camera element (as MeshLab writes range maps): view_p among other scalars.
    let dir = tempfile::tempdir().unwrap();
    let vertex = "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
    let camera = "element camera 2\nproperty int flags\nproperty float view_px\n\
                  property double view_py\nproperty float view_pz\nproperty float focal\n";
    for little in [true, false] {
        let order = if little { "little" } else { "big" };
        let mut bytes =
            format!("ply\nformat binary_{order}_endian 1.0\n{camera}{vertex}end_header\n")
                .into_bytes();
        let mut put = |b: &[u8]| {
            let mut b = b.to_vec();
            if !little {
                b.reverse();
            }
            bytes.extend(b);
        };
        // The first camera is read, the second skipped.
        for (x, y, z) in [(1.5f32, -2.25f64, 40.0f32), (9.0, 9.0, 9.0)] {
            put(&7i32.to_le_bytes());
            put(&x.to_le_bytes());
            put(&y.to_le_bytes());
            put(&z.to_le_bytes());
            put(&14.0f32.to_le_bytes());
        }
        for v in [1.0f32, 2.0, 3.0] {
            put(&v.to_le_bytes());
        }
        let path = dir.path().join(format!("cam-{order}.ply"));
        std::fs::write(&path, &bytes).unwrap();
        let mut r = PointReader::open(&path).unwrap();
        assert_eq!(r.viewpoint(), Some(DVec3::new(1.5, -2.25, 40.0)), "{order}");
        let mut out = Vec::new();
        assert_eq!(r.read_chunk(&mut out, 10).unwrap(), 1);
        assert_eq!(out[0].position, DVec3::new(1.0, 2.0, 3.0), "{order}");
    }
    let ascii = format!(
        "ply\nformat ascii 1.0\n{}{vertex}end_header\n7 1.5 -2.25 40 14\n1 1 1 1 1\n1 2 3\n",
        camera
    );
    let path = dir.path().join("cam.ply");
    std::fs::write(&path, ascii).unwrap();
    let mut r = PointReader::open(&path).unwrap();
    assert_eq!(r.viewpoint(), Some(DVec3::new(1.5, -2.25, 40.0)));
    let mut out = Vec::new();
    assert_eq!(r.read_chunk(&mut out, 10).unwrap(), 1);
    assert_eq!(out[0].position, DVec3::new(1.0, 2.0, 3.0));
    // No camera, a camera without its viewpoint, one with a list (whose ascii values cannot be
    // placed), or a non-finite viewpoint: none.
    for (name, head) in [
        ("plain", String::new()),
        (
            "other",
            "element camera 1\nproperty float view_px\nproperty float a\n".into(),
        ),
        (
            "list",
            "element camera 1\nproperty list uchar float k\nproperty float view_px\n\
             property float view_py\nproperty float view_pz\n"
                .into(),
        ),
    ] {
        let body = match name {
            "plain" => "",
            "list" => "2 5 6 1 2 3\n",
            _ => "1 2\n",
        };
        let text = format!("ply\nformat ascii 1.0\n{head}{vertex}end_header\n{body}1 2 3\n");
        let path = dir.path().join(format!("{name}.ply"));
        std::fs::write(&path, text).unwrap();
        assert_eq!(
            PointReader::open(&path).unwrap().viewpoint(),
            None,
            "{name}"
        );
    }
    let nan = format!("ply\nformat ascii 1.0\n{camera}{vertex}end_header\n7 nan 0 0 1\n1 2 3\n")
        .replace("element camera 2", "element camera 1");
    let path = dir.path().join("nan.ply");
    std::fs::write(&path, nan).unwrap();
    assert_eq!(PointReader::open(&path).unwrap().viewpoint(), None);
}

#[test]
fn bad_ply_headers_are_one_line_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let vertex = "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
    let cases = [
        ("not ply", "v 0 0 0\n".to_string(), "not a PLY file"),
        (
            "list first",
            format!(
                "ply\nformat binary_little_endian 1.0\nelement face 1\n\
                 property list uchar int vertex_indices\n{vertex}end_header\n"
            ),
            "cannot be skipped",
        ),
        (
            "list",
            format!("ply\nformat ascii 1.0\n{vertex}property list uchar int n\nend_header\n"),
            "list properties",
        ),
        (
            "no z",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
             end_header\n"
                .to_string(),
            "no `z`",
        ),
        (
            "twice",
            format!("ply\nformat binary_little_endian 1.0\n{vertex}property float x\nend_header\n"),
            "twice",
        ),
        (
            "no end",
            format!("ply\nformat ascii 1.0\n{vertex}"),
            "end_header",
        ),
        (
            "bad format",
            format!("ply\nformat binary 1.0\n{vertex}end_header\n"),
            "",
        ),
    ];
    for (name, text, mentions) in cases {
        let path = dir.path().join(format!("{name}.ply"));
        std::fs::write(&path, text).unwrap();
        let err = PointReader::open(&path).err().unwrap().to_string();
        assert!(err.contains(&format!("{name}.ply")), "{err}");
        assert!(err.contains(mentions), "{name}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

/// Corrupted headers and cut files: an error naming the file or a result, never a panic.
#[test]
fn corrupted_point_files_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("source.ply");
    let mut w = PlyPointWriter::create_with_levels(&source, 20).unwrap();
    w.write_levels(&points(20), &[1; 20]).unwrap();
    w.finish().unwrap();
    let bytes = std::fs::read(&source).unwrap();
    let header_len = 250.min(bytes.len());
    let mut next = crate::points::test_support::xorshift();
    for round in 0..200 {
        let mut b = bytes[..(next() % bytes.len()).max(1)].to_vec();
        for _ in 0..round % 4 {
            let at = next() % header_len.min(b.len());
            b[at] = [b' ', b'\n', b'0', b'x', 0xff, next() as u8][next() % 6];
        }
        let path = dir.path().join(format!("c{round}.ply"));
        std::fs::write(&path, &b).unwrap();
        let result = PointReader::open(&path).and_then(|mut r| {
            let mut chunk = Vec::new();
            while r.read_chunk(&mut chunk, 7)? > 0 {}
            Ok(())
        });
        if let Err(e) = result {
            let message = e.to_string();
            assert!(message.contains(&format!("c{round}.ply")), "{message}");
            assert_eq!(message.lines().count(), 1, "{message}");
        }
    }
}

#[test]
fn text_point_sets_xyz_and_csv() {
    let dir = tempfile::tempdir().unwrap();
    // .pts: a count line, blanks, comments, four columns (the fourth, intensity, skipped).
    let xyz = dir.path().join("a.pts");
    std::fs::write(&xyz, "2\n# scan 1\n\n1 2 3 7\n  4\t5 6 8\n").unwrap();
    let mut r = PointReader::open(&xyz).unwrap();
    assert_eq!(r.count(), 2);
    assert!(!r.has_normals());
    let mut chunk = Vec::new();
    assert_eq!(r.read_chunk(&mut chunk, 10).unwrap(), 2);
    assert_eq!(chunk[1].position, DVec3::new(4.0, 5.0, 6.0));
    assert_eq!(r.read_chunk(&mut chunk, 10).unwrap(), 0);
    // CSV with named columns in another order.
    let csv = dir.path().join("b.csv");
    std::fs::write(
        &csv,
        "id,NZ,x,y,z,nx,ny\n0,2,1.5,2.5,3.5,0,0\n1,0,-1,-2,-3,3,0\n",
    )
    .unwrap();
    let mut r = PointReader::open(&csv).unwrap();
    assert_eq!(r.count(), 2);
    assert!(r.has_normals());
    assert_eq!(r.read_chunk(&mut chunk, 1).unwrap(), 1);
    assert_eq!(chunk[0].position, DVec3::new(1.5, 2.5, 3.5));
    assert_eq!(chunk[0].normal, DVec3::Z);
    assert_eq!(r.read_chunk(&mut chunk, 1).unwrap(), 1);
    assert_eq!(chunk[0].normal, DVec3::X);
    // Six unnamed columns are x y z nx ny nz.
    let six = dir.path().join("c.xyz");
    std::fs::write(&six, "0;0;0;0;1;0\n").unwrap();
    let mut r = PointReader::open(&six).unwrap();
    assert!(r.has_normals());
    r.read_chunk(&mut chunk, 5).unwrap();
    assert_eq!(chunk[0].normal, DVec3::Y);
}

#[test]
fn bad_text_point_sets_are_errors_naming_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let two = dir.path().join("two.xyz");
    std::fs::write(&two, "1 2\n").unwrap();
    let err = PointReader::open(&two).err().unwrap().to_string();
    assert!(
        err.contains("two.xyz") && err.contains("three numbers"),
        "{err}"
    );
    let bad = dir.path().join("bad.xyz");
    std::fs::write(&bad, "1 2 3\n4 five 6\n").unwrap();
    let mut r = PointReader::open(&bad).unwrap();
    let err = r.read_chunk(&mut Vec::new(), 10).unwrap_err().to_string();
    assert!(
        err.contains("bad.xyz") && err.contains("five") && err.contains('2'),
        "{err}"
    );
    let names = dir.path().join("names.csv");
    std::fs::write(&names, "a,b,c\n1,2,3\n").unwrap();
    let err = PointReader::open(&names).err().unwrap().to_string();
    assert!(err.contains("`x`"), "{err}");
    let nan = dir.path().join("nan.csv");
    std::fs::write(&nan, "1,2,NaN\n").unwrap();
    let mut r = PointReader::open(&nan).unwrap();
    assert!(r.read_chunk(&mut Vec::new(), 10).is_err());
}
