//! Point sets without connectivity, the paper's native input (Sec. 3): streaming PLY reading and
//! writing, and dense random point sets drawn from meshes for tests and benchmarks.

pub mod generate;
pub mod ply_stream;

pub use ply_stream::{PlyPointReader, PlyPointWriter, Point};
