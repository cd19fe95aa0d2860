//! Embeds the commit the binary is built from (`LIGHTCUT_COMMIT`, read by capture records):
//! `git rev-parse HEAD`, with `-dirty` when tracked files differ from it; `unknown` without git.

use std::path::Path;
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    let commit = git(&["rev-parse", "HEAD"]).filter(|c| !c.is_empty());
    // `--no-optional-locks`: status must not rewrite the index (a rewritten index would
    // rerun this script, and rebuild the crate, at every cargo command).
    let dirty = git(&[
        "--no-optional-locks",
        "status",
        "--porcelain",
        "--untracked-files=no",
    ])
    .is_some_and(|s| !s.is_empty());
    let value = match commit {
        Some(c) if dirty => format!("{c}-dirty"),
        Some(c) => c,
        None => "unknown".to_string(),
    };
    println!("cargo:rustc-env=LIGHTCUT_COMMIT={value}");
    // Rerun when HEAD moves (a checkout: HEAD; a commit: the branch's ref) or the sources
    // change (not on the index: `git add` alone changes no build). Only paths that exist (a missing one reruns it at every build), and
    // git's own paths (a worktree's `.git` is a file).
    let mut watch: Vec<String> = ["src", "shaders", "Cargo.toml"].map(String::from).to_vec();
    for p in ["HEAD", "packed-refs"] {
        watch.extend(git(&["rev-parse", "--git-path", p]));
    }
    if let Some(r) = git(&["symbolic-ref", "-q", "HEAD"]) {
        watch.extend(git(&["rev-parse", "--git-path", &r]));
    }
    for p in watch.iter().filter(|p| Path::new(p).exists()) {
        println!("cargo:rerun-if-changed={p}");
    }
}
