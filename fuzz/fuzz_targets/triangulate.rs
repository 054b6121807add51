#![no_main]
//! The triangulation (tangent-plane Delaunay umbrellas, votes, clean-up) of noisy point sets on a
//! sphere or a torus, shaped by the fuzzer's bytes (noisy_points.rs): the assembly must always
//! return an edge- and vertex-manifold, consistently oriented mesh without degenerate or
//! duplicate faces.

use libfuzzer_sys::fuzz_target;

#[path = "noisy_points.rs"]
mod noisy_points;

fuzz_target!(|data: &[u8]| {
    let (positions, normals) = noisy_points::noisy_points(data);
    noisy_points::assert_triangulation_is_clean(positions, &normals);
});
