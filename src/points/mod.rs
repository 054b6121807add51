//! Point sets without connectivity, the paper's native input (Sec. 3): streaming reading (PLY,
//! XYZ/CSV, LAS and LAZ; PCD and E57 read whole) and writing, dense random point sets drawn from
//! meshes for tests and benchmarks, the out-of-core randomized linear scan, normal estimation,
//! and the RIMLS surface of a point set.

pub mod area_guess;
pub mod boundary;
pub(crate) mod buckets;
pub mod e57;
pub mod far_groups;
pub mod flatness;
pub mod generate;
pub(crate) mod las;
pub mod normals;
pub mod out_of_core;
pub mod outliers;
pub mod pcd;
pub mod rimls;
pub mod source;
pub mod stream;
pub mod visibility;

pub use stream::{PlyPointWriter, Point, PointReader};

#[cfg(test)]
pub(crate) mod test_support {
    /// A xorshift generator (Marsaglia 2003) from a fixed state: the same numbers every run,
    /// for the readers' corruption tests.
    pub(crate) fn xorshift() -> impl FnMut() -> usize {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state as usize
        }
    }

    /// Asserts that the error message `e` is one line and names each of `mentions` (the file,
    /// the format), as every reader's errors must.
    pub(crate) fn assert_one_line_naming(e: &str, mentions: &[&str]) {
        assert!(mentions.iter().all(|m| e.contains(m)), "{e}");
        assert!(!e.contains('\n'), "one line: {e}");
    }
}
