#![no_main]
//! The LAS point reader on arbitrary bytes (seeds: `fuzz/seeds/read_las`): see points_common.rs.

use libfuzzer_sys::fuzz_target;

#[path = "points_common.rs"]
mod points_common;

fuzz_target!(|data: &[u8]| {
    // The reader turns a panic inside the laz crate's decoder (corrupt compressed data) into an
    // error (`points/las.rs`, `decoding`): such a panic unwinds to it instead of aborting. Any
    // other panic is a finding, as libFuzzer's hook makes it.
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let finding = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let in_laz = info.location().is_some_and(|l| l.file().contains("/laz-"));
            if !in_laz {
                finding(info);
            }
        }));
    });
    points_common::read_points(data, "las");
});
