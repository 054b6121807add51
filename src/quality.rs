//! The quality report: the triangle measures of the paper's Table 1, topology, and distance to the
//! input surface.
