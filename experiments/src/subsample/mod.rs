//! Subsampling a point set to a given count: the paper's randomized linear scan and the three
//! simple baselines the reconstruction experiment (Sec. 7.2, Table 2) compares it with. The paper
//! compares with two iterative simplification methods (AS, Alexa et al. 2001; KS, Kitago and Gopi
//! 2006); these baselines are the common fast alternatives instead: uniform random selection,
//! voxel-grid clustering (Pauly, Gross, Kobbelt 2002) and Poisson-disk (dart-throwing)
//! subsampling.
//!
//! Every subsampler returns indices into the input (the kept points keep their normals) and is
//! deterministic for its seed. The baselines with a size parameter search it for a target count
//! ([`spectral_remesh::internal::find_sigma_p`], the same log-log secant search that finds
//! the linear scan's sigma_p).

pub mod linear_scan;
pub mod poisson_disk;
pub mod random;
pub mod voxel_grid;
pub mod weights;

pub use linear_scan::linear_scan_subsample;
pub use poisson_disk::{poisson_disk_subsample, poisson_disk_subsample_to_count};
pub use random::random_subsample;
pub use voxel_grid::{voxel_grid_subsample, voxel_grid_subsample_to_count};
pub use weights::{representation_weights, RepresentationParams, RepresentationWeights};

/// A subsampler of the reconstruction experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Subsampler {
    /// The randomized linear scan (Sec. 6.1, Algorithm 1) with the reconstruction's kernel: its
    /// count sets the others'.
    LinearScan,
    /// A uniformly random subset.
    UniformRandom,
    /// One point per occupied voxel: the one nearest the voxel's centroid.
    VoxelGrid,
    /// Dart throwing on the input points with a minimum distance.
    PoissonDisk,
}

impl Subsampler {
    /// All four, the linear scan first.
    pub const ALL: [Subsampler; 4] = [
        Subsampler::LinearScan,
        Subsampler::UniformRandom,
        Subsampler::VoxelGrid,
        Subsampler::PoissonDisk,
    ];

    /// The short name used on the command line and in reports: `ours`, `random`, `voxel`,
    /// `poisson`.
    pub fn name(self) -> &'static str {
        match self {
            Subsampler::LinearScan => "ours",
            Subsampler::UniformRandom => "random",
            Subsampler::VoxelGrid => "voxel",
            Subsampler::PoissonDisk => "poisson",
        }
    }

    /// The subsampler named `name` (see [`Subsampler::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}
