//! Stanford PLY. Headers are read and written by `ply-rs-bw` (its grammar, checked here for
//! what it lets through); mesh payloads are read by `ply-rs-bw` too ([`read`]), point-set
//! payloads by the fixed-record decoder of `points::stream`. Every file the crate writes as
//! PLY goes through the one binary writer, [`BinaryPlyWriter`].

mod read;
mod write;

use std::io::BufRead;
use std::path::Path;

use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{DefaultElement, Header};

use super::one_line;
use crate::error::{Error, Result};

pub(super) use read::read;
pub(crate) use write::{encode_mesh, BinaryPlyWriter};

/// Reads a PLY header with `ply-rs-bw` from `reader`, which is left at the first payload byte
/// (`reader.line()` is then the line number of the first payload line of an ascii file).
///
/// Besides the grammar (which `ply-rs-bw` checks), every header line must declare something the
/// parsed header keeps: `ply-rs-bw` keeps element and property names in maps, so a name declared
/// twice would silently drop a property and misalign every record after it.
///
/// # Errors
/// [`Error::Parse`] naming `path`, on one line, with the header line where known.
pub(crate) fn read_header<T: BufRead>(path: &Path, reader: &mut Reader<T>) -> Result<Header> {
    // The element type only matters for payloads.
    let header = Parser::<DefaultElement>::new()
        .read_header(reader)
        .map_err(|e| Error::parse(path, e.line(), one_line(&strip_line_prefix(&e.to_string()))))?;
    // The reader counts lines from 1 and ends one past `end_header`.
    let lines = reader.line().saturating_sub(1);
    let kept = 3 // ply, format, end_header
        + header.comments.len()
        + header.obj_infos.len()
        + header
            .elements
            .values()
            .map(|e| 1 + e.properties.len())
            .sum::<usize>();
    if lines != kept {
        return Err(Error::parse(
            path,
            None,
            "the header declares an element or property name twice (or repeats its format line)",
        ));
    }
    Ok(header)
}

/// `ply-rs-bw` prefixes messages with "Line N: "; we carry the line separately.
fn strip_line_prefix(message: &str) -> String {
    if let Some(rest) = message.strip_prefix("Line ") {
        if let Some((num, tail)) = rest.split_once(": ") {
            if num.chars().all(|c| c.is_ascii_digit()) {
                return tail.to_string();
            }
        }
    }
    message.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(text: &str) -> Result<(Header, usize)> {
        let mut reader = Reader::new(text.as_bytes());
        let h = read_header(Path::new("t.ply"), &mut reader)?;
        Ok((h, reader.line()))
    }

    #[test]
    fn a_header_is_read_up_to_its_end() {
        let (h, line) = header(
            "ply\nformat ascii 1.0\ncomment c\nelement vertex 2\nproperty float x\n\
             property float y\nelement face 0\nproperty list uchar int vertex_indices\n\
             end_header\n1 2\n",
        )
        .unwrap();
        assert_eq!(h.elements["vertex"].count, 2);
        assert_eq!(h.elements["vertex"].properties.len(), 2);
        assert_eq!(line, 10, "the first payload line");
    }

    #[test]
    fn names_declared_twice_and_bad_lines_are_errors_naming_the_file() {
        for text in [
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float x\nend_header\n",
            "ply\nformat ascii 1.0\nelement vertex 1\nelement vertex 1\nend_header\n",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n",
            "ply\nformat ascii one\nend_header\n",
            "pl\n",
        ] {
            let e = header(text).unwrap_err();
            assert!(matches!(&e, Error::Parse { path, .. } if path == Path::new("t.ply")));
            assert_eq!(e.to_string().lines().count(), 1, "{e}");
        }
    }
}
