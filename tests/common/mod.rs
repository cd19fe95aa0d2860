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

/// Header and rows of a CSV written by the harness (no quoted cells in numeric columns).
pub fn read_csv(path: &std::path::Path) -> (Vec<String>, Vec<std::collections::HashMap<String, String>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines
        .map(|l| {
            // Split on commas outside quotes.
            let mut cells = Vec::new();
            let (mut cur, mut quoted) = (String::new(), false);
            for ch in l.chars() {
                match ch {
                    '"' => quoted = !quoted,
                    ',' if !quoted => cells.push(std::mem::take(&mut cur)),
                    c => cur.push(c),
                }
            }
            cells.push(cur);
            assert_eq!(cells.len(), header.len(), "{}: {l}", path.display());
            header.iter().cloned().zip(cells).collect()
        })
        .collect();
    (header, rows)
}
