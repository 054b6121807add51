//! Point sets without connectivity, the paper's native input (Sec. 3): streaming PLY reading and
//! writing, dense random point sets drawn from meshes for tests and benchmarks, and the
//! out-of-core randomized linear scan.

pub mod generate;
pub mod normals;
pub mod out_of_core;
pub mod ply_stream;
pub mod rimls;

pub use ply_stream::{PlyPointReader, PlyPointWriter, Point};
