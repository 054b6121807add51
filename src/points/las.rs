//! LAS, the ASPRS LiDAR exchange format, and LAZ, its LASzip compression, read as a point set
//! through the `las` crate (versions 1.0–1.4, every point format; LAZ through its `laz`
//! feature): the points' `x y z` with the header's scale and offset applied (the file's units,
//! metres or feet as its coordinate reference system says), in chunks (a LiDAR survey may hold
//! more points than memory). LAS has no normals and no single sensor position (an airborne
//! scanner moves), so the normals are estimated and oriented without a viewpoint.
//!
//! LAZ is read in chunks too: LASzip compresses the points in chunks (50,000 points by default)
//! listed in a chunk table, so a seek decompresses from the start of the chunk holding the point,
//! at most one LASzip chunk more than the points asked for. A LAZ without a chunk table (a
//! writer that did not finish) cannot seek: it reads when its points fit in the first chunk asked
//! for, and a larger one is an error naming the file.
//!
//! Sources: ASPRS, "LAS Specification 1.4 – R15" (2019); M. Isenburg, "LASzip: lossless
//! compression of LiDAR data", Photogrammetric Engineering & Remote Sensing 79(2), 2013, and the
//! LASzip format as `laz` implements it.

use std::path::Path;

use glam::DVec3;

use crate::error::{Error, Result};

/// A LAS file to read in chunks. The crate's reader cannot move between threads (the point
/// readers can), so each chunk opens the file again and seeks to its first point: a header read
/// per chunk of tens of thousands of points.
#[derive(Debug, Clone)]
pub(crate) struct LasPoints {
    count: u64,
}

impl LasPoints {
    /// Opens the LAS file at `path` and reads its header.
    ///
    /// # Errors
    /// [`Error::Parse`] naming the file for a file the `las` crate cannot read (not LAS or LAZ,
    /// a damaged header, a LAZ without its LASzip record).
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let count = decoding(path, || Ok(reader(path)?.header().number_of_points()))?;
        Ok(LasPoints { count })
    }

    /// The number of points the header announces.
    pub(crate) fn count(&self) -> u64 {
        self.count
    }

    /// Appends the positions (model units) of `n` points from point `from` on to `out`; how
    /// many there were (fewer at the end of the file).
    ///
    /// # Errors
    /// [`Error::Parse`] naming `path` for a file or point record the crate cannot read.
    pub(crate) fn read(
        &self,
        path: &Path,
        from: u64,
        n: usize,
        out: &mut Vec<DVec3>,
    ) -> Result<usize> {
        let bad = |e: las::Error| Error::Parse {
            path: path.to_path_buf(),
            line: None,
            message: format!("a point record the las crate cannot read: {e}"),
        };
        let data = decoding(path, || {
            let mut reader = reader(path)?;
            // A fresh reader is at the first point; seeking there would fail for a LAZ without
            // a chunk table.
            if from > 0 {
                reader.seek(from).map_err(bad)?;
            }
            reader.read_points(n as u64).map_err(bad)
        })?;
        let before = out.len();
        out.extend(
            data.x()
                .zip(data.y())
                .zip(data.z())
                .map(|((x, y), z)| DVec3::new(x, y, z)),
        );
        Ok(out.len() - before)
    }
}

/// The fewest bytes a LASzip chunk takes: its first point, stored raw (point format 0 is 20
/// bytes, the smallest).
const MIN_CHUNK_BYTES: u64 = 20;

/// Checks a LAS file's header against the file before the `las` crate reads it: the scale
/// factors are finite and not 0 (the format forbids 0, which would flatten every point onto
/// the offset), an uncompressed file's announced points fit in its bytes (each of the
/// header's record length), and a LAZ file's chunk table (which the `laz` crate reserves at
/// its announced size) lies within the file, at its offset at the start of the point data or in
/// the file's last 8 bytes when the writer did not update it (as LASzip and `laz` look for it),
/// and lists no more chunks than the point data's bytes can hold ([`MIN_CHUNK_BYTES`] each). A
/// file too short for a header, or without a chunk table, is left to the crate.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read; [`Error::Parse`] naming the file for a scale of
/// 0 or not finite, more points than the file holds, or a chunk table past its end or
/// announcing more chunks than its bytes hold.
fn check_header(path: &Path) -> Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let bad = |message: String| Error::Parse {
        path: path.to_path_buf(),
        line: None,
        message,
    };
    let mut file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let length = file.metadata().map_err(|e| Error::io(path, e))?.len();
    // LAS 1.0-1.3 headers are 227 bytes at least, 1.4's 375 (its 64-bit count at 247).
    let mut header = Vec::with_capacity(255);
    (&mut file)
        .take(255)
        .read_to_end(&mut header)
        .map_err(|e| Error::io(path, e))?;
    let version = (header.get(24).copied(), header.get(25).copied());
    let needed = if version >= (Some(1), Some(4)) {
        255
    } else {
        227
    };
    if header.len() < needed || &header[..4] != b"LASF" {
        return Ok(()); // Not LAS, or a header cut short: the crate says so.
    }
    let f64_at = |at: usize| f64::from_le_bytes(header[at..at + 8].try_into().unwrap());
    for (axis, at) in [("x", 131), ("y", 139), ("z", 147)] {
        let scale = f64_at(at);
        if !(scale.is_finite() && scale != 0.0) {
            return Err(bad(format!("the header's {axis} scale factor is {scale}")));
        }
    }
    let data_start = u32::from_le_bytes(header[96..100].try_into().unwrap()) as u64;
    let record = u16::from_le_bytes(header[105..107].try_into().unwrap()) as u64;
    let legacy = u32::from_le_bytes(header[107..111].try_into().unwrap()) as u64;
    let count = if needed == 255 {
        u64::from_le_bytes(header[247..255].try_into().unwrap())
    } else {
        legacy
    };
    if needed == 255 {
        check_extended_records(path, &mut file, &header, length)?;
    }
    let compressed = header[104] & 0x80 != 0;
    let laszip = if compressed {
        check_laszip_record(path, &mut file, &header, length)?
    } else {
        None
    };
    if !compressed {
        let bytes = length.saturating_sub(data_start);
        if (count as u128) * (record as u128) > bytes as u128 {
            return Err(bad(format!(
                "the header announces {count} points of {record} bytes and the file holds \
                 {bytes} bytes of points"
            )));
        }
        return Ok(());
    }
    let mut read_i64_at = |at: SeekFrom| -> Option<i64> {
        let mut b = [0u8; 8];
        file.seek(at).ok()?;
        file.read_exact(&mut b).ok()?;
        Some(i64::from_le_bytes(b))
    };
    let Some(mut offset) = read_i64_at(SeekFrom::Start(data_start)) else {
        return Ok(()); // No point data: the crate says so.
    };
    if offset <= data_start as i64 {
        match read_i64_at(SeekFrom::End(-8)) {
            Some(o) if o > data_start as i64 => offset = o,
            _ => return Ok(()), // No chunk table: read from the start only.
        }
    }
    let offset = offset as u64;
    if offset.saturating_add(8) > length {
        return Err(bad(format!(
            "the LAZ chunk table's offset {offset} is past the end of the file ({length} bytes)"
        )));
    }
    let mut table = [0u8; 8];
    file.seek(SeekFrom::Start(offset))
        .and_then(|_| file.read_exact(&mut table))
        .map_err(|e| Error::io(path, e))?;
    let chunks = u32::from_le_bytes(table[4..].try_into().unwrap()) as u64;
    let most = offset.saturating_sub(data_start + 8) / MIN_CHUNK_BYTES;
    if chunks > most.max(1) {
        return Err(bad(format!(
            "the LAZ chunk table lists {chunks} chunks and the {} bytes of point data hold at \
             most {most}",
            offset.saturating_sub(data_start + 8)
        )));
    }
    // Variable-size chunks: the `laz` crate takes each chunk's point count from the table as
    // it reads, and indexed past a table that lists fewer points than the header (found by the
    // read_las fuzz target: a table of no chunks).
    if let Some(vlr) = laszip.and_then(|data| laz::LazVlr::from_buffer(data).ok()) {
        if vlr.uses_variable_size_chunks() {
            file.seek(SeekFrom::Start(data_start))
                .map_err(|e| Error::io(path, e))?;
            let listed = match laz::laszip::ChunkTable::read_from(&mut file, &vlr) {
                Ok(table) => table.as_ref().iter().map(|c| c.point_count).sum::<u64>(),
                Err(e) => return Err(bad(format!("the LAZ chunk table cannot be read: {e}"))),
            };
            if listed < count {
                return Err(bad(format!(
                    "the LAZ chunk table lists {listed} points in chunks of variable size and \
                     the header announces {count}"
                )));
            }
        }
    }
    Ok(())
}

/// Checks a LAS 1.4 file's extended variable-length records (after the points; each announces
/// its length in 64 bits, which the `las` crate reserves as it reads): each lies within the
/// file.
///
/// # Errors
/// [`Error::Parse`] naming the file for an extended record past its end.
fn check_extended_records(
    path: &Path,
    file: &mut std::fs::File,
    header: &[u8],
    length: u64,
) -> Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let mut at = u64::from_le_bytes(header[235..243].try_into().unwrap());
    let count = u32::from_le_bytes(header[243..247].try_into().unwrap());
    for k in 0..count {
        let mut record = [0u8; 60];
        let read = at.checked_add(60).is_some_and(|end| end <= length)
            && file.seek(SeekFrom::Start(at)).is_ok()
            && file.read_exact(&mut record).is_ok();
        let size = u64::from_le_bytes(record[20..28].try_into().unwrap());
        let end = at.saturating_add(60).saturating_add(size);
        if !read || end > length {
            return Err(Error::Parse {
                path: path.to_path_buf(),
                line: None,
                message: format!(
                    "extended record {} of {count} (at byte {at}, {size} bytes) is past the end \
                     of the file ({length} bytes)",
                    k + 1
                ),
            });
        }
        at = end;
    }
    Ok(())
}

/// The LASzip record's user id and record id (the VLR that describes a LAZ's point items).
const LASZIP_RECORD: (&[u8], u16) = (b"laszip encoded", 22204);

/// Checks a LAZ file's LASzip record (the variable-length record after the header that lists
/// the compressed point's items): when present, it lists at least one item and holds them (the
/// `laz` crate panics on a record of no items). A missing record is left to the crate, which
/// says so.
///
/// Returns the record's data when there is one.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read; [`Error::Parse`] naming the file for a LASzip
/// record of no items or shorter than its items.
fn check_laszip_record(
    path: &Path,
    file: &mut std::fs::File,
    header: &[u8],
    length: u64,
) -> Result<Option<Vec<u8>>> {
    use std::io::{Read, Seek, SeekFrom};
    // The records follow the header, which the las crate reads whole whatever its size field
    // says (a field of 226 in a LAS 1.2 file put the crate's LASzip record one byte past ours:
    // found by the read_las fuzz target).
    let least = match (header[24], header[25]) {
        (1, 0..=2) => 227,
        (1, 3) => 235,
        _ => 375,
    };
    let header_size = (u16::from_le_bytes(header[94..96].try_into().unwrap()) as u64).max(least);
    let records = u32::from_le_bytes(header[100..104].try_into().unwrap());
    let mut at = header_size;
    for _ in 0..records.min(1 << 16) {
        let mut vlr = [0u8; 54];
        if at + 54 > length
            || file.seek(SeekFrom::Start(at)).is_err()
            || file.read_exact(&mut vlr).is_err()
        {
            return Ok(None); // Records cut short: the crate says so.
        }
        let user = &vlr[2..18];
        let user = &user[..user.iter().position(|&b| b == 0).unwrap_or(16)];
        let id = u16::from_le_bytes(vlr[18..20].try_into().unwrap());
        let size = u16::from_le_bytes(vlr[20..22].try_into().unwrap()) as u64;
        if (user, id) == LASZIP_RECORD {
            let mut data = vec![0u8; size as usize];
            // compressor, coder (u16 each), version (u8, u8, u16), options, chunk size (u32
            // each), special EVLRs' count and offset (i64 each): the item count at 32, the
            // items (type, size, version: u16 each) from 34.
            let items = if file.read_exact(&mut data).is_ok() && data.len() >= 34 {
                u16::from_le_bytes(data[32..34].try_into().unwrap()) as u64
            } else {
                0
            };
            if items == 0 || size < 34 + 6 * items {
                return Err(Error::Parse {
                    path: path.to_path_buf(),
                    line: None,
                    message: format!(
                        "the LAZ's LASzip record lists {items} point items in {size} bytes (at \
                         least one, 6 bytes each after 34)"
                    ),
                });
            }
            // Each item of a fixed size as LASzip defines it (the laz crate splits the record
            // by the sizes it knows: a wave packet item declared 20 bytes split past the
            // record), and the items fill the header's record.
            let record = u16::from_le_bytes(header[105..107].try_into().unwrap()) as u64;
            let mut total = 0u64;
            for i in 0..items as usize {
                let at = 34 + 6 * i;
                let kind = u16::from_le_bytes(data[at..at + 2].try_into().unwrap());
                let declared = u16::from_le_bytes(data[at + 2..at + 4].try_into().unwrap());
                let fixed = match kind {
                    6 => Some(20),      // Point10
                    7 => Some(8),       // GpsTime11
                    8 | 11 => Some(6),  // RGB12, RGB14
                    9 | 13 => Some(29), // WavePacket13, WavePacket14
                    10 => Some(30),     // Point14
                    12 => Some(8),      // RGBNIR14
                    _ => None,          // extra bytes: any size
                };
                if fixed.is_some_and(|f| f != declared) {
                    return Err(Error::Parse {
                        path: path.to_path_buf(),
                        line: None,
                        message: format!(
                            "the LAZ's LASzip record gives its item {} (type {kind}) {declared} \
                             bytes, and that type has {}",
                            i + 1,
                            fixed.unwrap_or(0)
                        ),
                    });
                }
                total += declared as u64;
            }
            if total != record {
                return Err(Error::Parse {
                    path: path.to_path_buf(),
                    line: None,
                    message: format!(
                        "the LAZ's LASzip items take {total} bytes and the header's point \
                         record {record}"
                    ),
                });
            }
            // Chunks of variable size (chunk size 0 or 2^32 - 1) need a chunked compressor: the
            // `laz` crate panics ("Variable-size chunks, but no chunk table") on the pointwise
            // one, which has no chunk table (found by the read_las fuzz target).
            let compressor = u16::from_le_bytes(data[0..2].try_into().unwrap());
            let chunk_size = u32::from_le_bytes(data[12..16].try_into().unwrap());
            if (chunk_size == 0 || chunk_size == u32::MAX) && compressor < 2 {
                return Err(Error::Parse {
                    path: path.to_path_buf(),
                    line: None,
                    message: format!(
                        "the LAZ's LASzip record asks for chunks of variable size with \
                         compressor {compressor}, which has no chunks"
                    ),
                });
            }
            return Ok(Some(data));
        }
        at += 54 + size;
    }
    Ok(None)
}

/// The crate's reader of `path`, its header read (checked first against the file:
/// `check_header`).
fn reader(path: &Path) -> Result<las::Reader> {
    check_header(path)?;
    las::Reader::from_path(path).map_err(|e| Error::Parse {
        path: path.to_path_buf(),
        line: None,
        message: format!("not a LAS or LAZ file the las crate can read: {e}"),
    })
}

/// Runs `read` (the `las` and `laz` crates at work on the file at `path`), a panic inside it an
/// error naming the file. The `laz` crate's arithmetic decoder indexes its tables with values
/// decoded from the compressed bytes and panics on corrupt ones ("index out of bounds" in
/// `decoders.rs`, found by the read_las fuzz target): compressed data can be corrupt anywhere,
/// which no check of the header rules out. (The process's panic hook still sees the panic: the
/// command line's records it silently.)
///
/// # Errors
/// `read`'s, or [`Error::Parse`] naming the file and the panic's message.
fn decoding<T>(path: &Path, read: impl FnOnce() -> Result<T>) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(read)).unwrap_or_else(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown cause".into());
        Err(Error::Parse {
            path: path.to_path_buf(),
            line: None,
            message: format!(
                "the compressed points are corrupt (the LAZ decoder failed: {})",
                message.replace('\n', " ")
            ),
        })
    })
}

/// Whether `path`'s extension is `.las` or `.laz` (any case): the `las` crate reads both, and
/// tells them apart by the header's point format, not by the name.
pub(crate) fn is_las_extension(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("las") || e.eq_ignore_ascii_case("laz"))
}

#[cfg(test)]
mod tests;
