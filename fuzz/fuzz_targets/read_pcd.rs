#![no_main]
//! The PCD point reader on arbitrary bytes (seeds: `fuzz/seeds/read_pcd`): see points_common.rs.

use libfuzzer_sys::fuzz_target;

#[path = "points_common.rs"]
mod points_common;

fuzz_target!(|data: &[u8]| {
    points_common::read_points(data, "pcd");
});
