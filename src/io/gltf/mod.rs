//! glTF 2.0 (`.gltf` and `.glb`): reading the triangles of a scene with the `gltf` crate
//! (`read.rs`), and writing one mesh as a binary or embedded glTF asset (`write.rs`).
//!
//! Reading parses and validates the document with `gltf`, loads only its buffers (not its
//! images: data URIs decoded by `base64`, file paths by `percent-encoding`), and decodes
//! accessors with our own bounds-checked code: the `gltf` crate's accessor iterators and
//! importer can panic on some malformed files (a GLB header length below 12, an accessor of
//! count 0, a buffer URI that is not UTF-8 once percent-decoded).

mod read;
mod write;

pub(super) use read::read;
pub(super) use write::{as_written, encode_glb, encode_gltf};
