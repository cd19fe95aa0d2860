//! Embeds the commit the binary is built from (`LIGHTCUT_COMMIT`, read by capture records):
//! `git rev-parse HEAD`, with `-dirty` when tracked files differ from it; `unknown` without git.

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    let commit = git(&["rev-parse", "HEAD"]).filter(|c| !c.is_empty());
    let dirty = git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
    let value = match commit {
        Some(c) if dirty => format!("{c}-dirty"),
        Some(c) => c,
        None => "unknown".to_string(),
    };
    println!("cargo:rustc-env=LIGHTCUT_COMMIT={value}");
    for p in [".git/HEAD", ".git/index", "src", "shaders", "Cargo.toml"] {
        println!("cargo:rerun-if-changed={p}");
    }
}
