use super::*;
use crate::points::test_support::assert_one_line_naming;

/// Writes `n` points at a survey's coordinates (UTM metres, the header's scale a millimetre) to
/// `path` with the crate's writer, LASzip-compressed when the name ends in `.laz`; returns them.
fn write_survey(path: &Path, n: usize) -> Vec<DVec3> {
    let written: Vec<DVec3> = (0..n)
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
    let mut writer = las::Writer::from_path(path, header.into_header().unwrap()).unwrap();
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
    written
}

/// Reads `path` through the point reader the pipeline uses, in chunks of `chunk`, and checks
/// the points against `written` within the millimetre scale.
fn read_back(path: &Path, written: &[DVec3], chunk: usize) {
    let mut reader = crate::points::PointReader::open(path).unwrap();
    assert_eq!(reader.count(), written.len() as u64);
    assert_eq!(reader.viewpoint(), None);
    assert!(!reader.has_normals());
    let (mut all, mut points) = (Vec::new(), Vec::new());
    while reader.read_chunk(&mut points, chunk).unwrap() > 0 {
        all.extend(points.iter().map(|p| p.position));
    }
    assert_eq!(all.len(), written.len());
    for (a, b) in all.iter().zip(written) {
        assert!(a.distance(*b) <= 0.001, "{a} against {b}");
    }
    assert!(crate::points::stream::is_point_set(path).unwrap());
}

#[test]
fn a_las_file_written_reads_back_its_points_in_chunks() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("survey.las");
    let written = write_survey(&path, 1000);
    read_back(&path, &written, 300);
}

#[test]
fn a_laz_file_written_reads_back_its_points_in_chunks_across_laszip_chunks() {
    let dir = tempfile::tempdir().unwrap();
    // More than two LASzip chunks (50,000 points each by default), read in chunks of 30,000:
    // every read after the first seeks into the middle of a LASzip chunk.
    let path = dir.path().join("survey.laz");
    let written = write_survey(&path, 120_000);
    let header = las::Reader::from_path(&path).unwrap().header().clone();
    assert!(header.point_format().is_compressed, "written as LAZ");
    // Compressed: well below the 20 bytes a point of format 0 takes in a LAS file.
    let size = std::fs::metadata(&path).unwrap().len();
    assert!(size < 120_000 * 20 / 2, "{size} bytes");
    read_back(&path, &written, 30_000);
    // The same name in capitals, and a small file read in one chunk.
    let path = dir.path().join("SMALL.LAZ");
    let written = write_survey(&path, 10);
    read_back(&path, &written, 1 << 16);
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
    assert_one_line_naming(&e, &["scan.las", "LAS"]);
}

#[test]
fn a_file_that_is_not_laz_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan.laz");
    std::fs::write(&path, [0u8; 400]).unwrap();
    let Err(e) = crate::points::PointReader::open(&path) else {
        panic!("read as LAZ");
    };
    let e = e.to_string();
    assert_one_line_naming(&e, &["scan.laz", "LAZ"]);
}

/// Issue 76 (R4, R9): a LAZ whose chunk table announces 0xFFFFFFFF chunks, or lies past the
/// end of the file, is refused naming the file before the `laz` crate reserves the table (at
/// cc1f49d: an abort on a 68 GB allocation whatever the limits; 556 MB then exit 3).
#[test]
fn a_laz_chunk_table_the_file_cannot_hold_is_refused_before_it_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("survey.laz");
    let written = write_survey(&path, 2000);
    let honest = std::fs::read(&path).unwrap();
    let data_start = u32::from_le_bytes(honest[96..100].try_into().unwrap()) as usize;
    let table = i64::from_le_bytes(honest[data_start..data_start + 8].try_into().unwrap());
    assert!(table as usize > data_start && (table as usize) < honest.len());
    read_back(&path, &written, 700);
    // 0xFFFFFFFF chunks.
    let mut bytes = honest.clone();
    bytes[table as usize + 4..table as usize + 8].copy_from_slice(&u32::MAX.to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let e = LasPoints::open(&path).unwrap_err().to_string();
    assert_one_line_naming(&e, &["survey.laz", "4294967295 chunks"]);
    // The table's offset past the end of the file.
    let mut bytes = honest.clone();
    let past = (honest.len() as i64 + 1_000_000).to_le_bytes();
    bytes[data_start..data_start + 8].copy_from_slice(&past);
    std::fs::write(&path, &bytes).unwrap();
    let e = LasPoints::open(&path).unwrap_err().to_string();
    assert_one_line_naming(&e, &["survey.laz", "past the end of the file"]);
}

/// Writes the seeds of the `read_las` fuzz target (`fuzz/seeds/read_las`: a LAS and a LAZ of
/// a few points) into `$FUZZ_SEEDS/read_las`.
#[test]
#[ignore = "writes the fuzz seeds: FUZZ_SEEDS=fuzz/seeds cargo test -- --ignored fuzz_seeds"]
fn write_las_fuzz_seeds() {
    let dir = Path::new(&std::env::var("FUZZ_SEEDS").expect("FUZZ_SEEDS")).join("read_las");
    std::fs::create_dir_all(&dir).unwrap();
    write_survey(&dir.join("survey.las"), 20);
    write_survey(&dir.join("survey.laz"), 20);
}

/// Issue 76 (R11): a LAS header announcing more points than the file holds, or a scale factor
/// of 0 (the format forbids it), is an error naming the field (at cc1f49d: "Invalid argument
/// (os error 22)" for a count of 2^62; a z scale of 0 read silently, flattening the points).
#[test]
fn a_las_header_the_file_contradicts_is_an_error_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("survey.las");
    write_survey(&path, 50);
    let honest = std::fs::read(&path).unwrap();
    let mut bytes = honest.clone();
    bytes[107..111].copy_from_slice(&(1u32 << 30).to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let e = LasPoints::open(&path).unwrap_err().to_string();
    assert_one_line_naming(&e, &["survey.las", "announces 1073741824 points"]);
    let mut bytes = honest.clone();
    bytes[147..155].copy_from_slice(&0f64.to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let e = LasPoints::open(&path).unwrap_err().to_string();
    assert_one_line_naming(&e, &["survey.las", "z scale factor is 0"]);
    std::fs::write(&path, &honest).unwrap();
    assert_eq!(LasPoints::open(&path).unwrap().count(), 50);
}
