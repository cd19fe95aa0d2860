//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

use lightcut::renderer::context::GpuContext;

/// A headless GPU context, or None (with a message) when this machine has no usable adapter.
/// With `LIGHTCUT_REQUIRE_GPU=1` (set by `.ci/run`) a missing adapter fails the test instead.
pub fn gpu() -> Option<GpuContext> {
    match GpuContext::new_headless() {
        Ok(ctx) => {
            eprintln!("adapter: {}", ctx.describe());
            Some(ctx)
        }
        Err(e) => {
            if std::env::var("LIGHTCUT_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("LIGHTCUT_REQUIRE_GPU=1 but: {e}");
            }
            eprintln!("SKIPPED (no GPU adapter): {e}");
            None
        }
    }
}

/// `../shared/scenes` beside the repository (or `LIGHTCUT_SHARED_SCENES`), if present.
pub fn shared_scenes() -> Option<PathBuf> {
    let p = std::env::var_os("LIGHTCUT_SHARED_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/scenes"));
    if p.is_dir() {
        Some(p)
    } else {
        eprintln!(
            "SKIPPED: shared scenes not found at {} (set LIGHTCUT_SHARED_SCENES)",
            p.display()
        );
        None
    }
}
