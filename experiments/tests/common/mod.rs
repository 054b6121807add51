//! What the experiments' tests share.

use std::path::{Path, PathBuf};

/// `data/NAME` of the checkout when it has the model, else the shared model beside the checkout
/// (only the tests named `shared_*`, marked `#[ignore = "needs ../shared: .ci/run runs it"]`,
/// read those).
pub fn model(name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let own = root.join("data").join(name);
    if own.is_file() {
        own
    } else {
        root.join("../shared/data").join(name)
    }
}
