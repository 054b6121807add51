#![no_main]
//! The glTF reader on arbitrary bytes: as .glb when they start with the binary magic, as .gltf
//! (JSON) otherwise.

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    let ext = if data.starts_with(b"glTF") {
        "glb"
    } else {
        "gltf"
    };
    common::read_bytes(data, ext);
});
