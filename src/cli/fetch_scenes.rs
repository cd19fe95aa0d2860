//! `fetch-scenes`: downloads the reference scenes (Sponza, Breakfast Room) from AMD's
//! CapsaicinTestMedia (CC BY 3.0), checks every file's size and SHA-256 against the files
//! the measurements used (`scenes/reference/manifest.toml`), and puts them where presets find
//! them ([`crate::scene::scene_path`]). A file is only ever placed after its size and
//! checksum matched (checked in memory, written to `<file>.part`, renamed); files already
//! present and right are kept.

use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow};
use clap::Args;

use crate::scene::scene_path::{self, Manifest, ManifestFile, STANDINS, sha256_hex};

#[derive(Args, Debug, Clone, Default)]
pub struct FetchScenesArgs {
    /// Folder to put the scenes in (default: the user data folder,
    /// `$XDG_DATA_HOME/lightcut-workbench/scenes` or `~/.local/share/lightcut-workbench/scenes`,
    /// which presets search).
    #[arg(long)]
    pub into: Option<PathBuf>,
    /// Where the files come from: a base URL (default: the manifest's, AMD's
    /// CapsaicinTestMedia on GitHub at a fixed commit; downloads use `curl`) or a local folder
    /// with the same layout (a mirror, e.g. `../shared/scenes`).
    #[arg(long)]
    pub from: Option<String>,
    /// Only these scenes (comma-separated folder names: sponza, breakfast_room).
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Only check the files already in the folder (sizes and SHA-256), download nothing.
    #[arg(long)]
    pub check: bool,
}

/// What happened to one file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Already there with the right checksum.
    Present,
    /// Downloaded or copied, checked and placed.
    Fetched,
    /// Written from the built-in stand-in.
    StandIn,
}

/// Fetches `manifest`'s files of `scenes` (all when empty) from `from` into `into`. Returns
/// each file's outcome; the first failure (a download that fails, a checksum that does not
/// match) is an error naming the file, after the other files were tried.
pub fn fetch(
    manifest: &Manifest,
    from: &str,
    into: &Path,
    scenes: &[String],
    check_only: bool,
    log: &mut dyn FnMut(&str),
) -> anyhow::Result<Vec<(String, Outcome)>> {
    let known = manifest.scenes();
    if let Some(s) = scenes.iter().find(|s| !known.contains(s)) {
        return Err(anyhow!(
            "--scenes: no scene '{s}' (the reference scenes: {})",
            known.join(", ")
        ));
    }
    let files: Vec<&ManifestFile> = manifest
        .files
        .iter()
        .filter(|f| scenes.is_empty() || scenes.iter().any(|s| f.path.starts_with(&format!("{s}/"))))
        .collect();
    let mut done = Vec::new();
    let mut failures: Vec<String> = Vec::new();
    for f in files {
        match fetch_one(f, from, into, check_only) {
            Ok(o) => {
                log(&format!(
                    "  {:<52} {:>9.1} kB  {}",
                    f.path,
                    f.bytes as f64 / 1e3,
                    match o {
                        Outcome::Present => "present, checksum ok",
                        Outcome::Fetched => "fetched, checksum ok",
                        Outcome::StandIn => "written (stand-in: missing from the source)",
                    }
                ));
                done.push((f.path.clone(), o));
            }
            Err(e) => {
                log(&format!("  {:<52} FAILED: {e:#}", f.path));
                failures.push(format!("{}: {e:#}", f.path));
            }
        }
    }
    if let Some(first) = failures.first() {
        if check_only {
            return Err(anyhow!(
                "{} of {} file(s) missing or different from the measured ones (first: {first}); fetch-scenes without --check fetches them",
                failures.len(),
                failures.len() + done.len()
            ));
        }
        return Err(anyhow!(
            "{} of {} file(s) failed (nothing wrong was placed); first: {first}",
            failures.len(),
            failures.len() + done.len()
        ));
    }
    Ok(done)
}

fn fetch_one(f: &ManifestFile, from: &str, into: &Path, check_only: bool) -> anyhow::Result<Outcome> {
    let dest = into.join(&f.path);
    if let Ok(bytes) = std::fs::read(&dest)
        && bytes.len() as u64 == f.bytes
        && sha256_hex(&bytes) == f.sha256
    {
        return Ok(Outcome::Present);
    }
    if check_only {
        return Err(anyhow!(
            "{} is missing or differs from the measured file",
            dest.display()
        ));
    }
    let (bytes, outcome) = if f.standin {
        let name = f.path.rsplit('/').next().unwrap_or("");
        let (_, b) = STANDINS
            .iter()
            .find(|(n, _)| *n == name)
            .ok_or_else(|| anyhow!("no built-in stand-in for {name}"))?;
        (b.to_vec(), Outcome::StandIn)
    } else {
        (read_source(from, &f.path)?, Outcome::Fetched)
    };
    let got = sha256_hex(&bytes);
    if bytes.len() as u64 != f.bytes || got != f.sha256 {
        return Err(anyhow!(
            "checksum mismatch: expected {} bytes with SHA-256 {}, got {} bytes with {got}",
            f.bytes,
            f.sha256,
            bytes.len()
        ));
    }
    let parent = dest.parent().unwrap_or(into);
    std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
    let name = dest.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let part = dest.with_file_name(format!("{name}.{}.part", std::process::id()));
    std::fs::write(&part, &bytes).with_context(|| format!("cannot write {}", part.display()))?;
    std::fs::rename(&part, &dest).with_context(|| format!("cannot place {}", dest.display()))?;
    Ok(outcome)
}

/// The bytes of `rel` under `from`: a local folder (or `file://` URL) is read, an http(s) URL
/// is downloaded with `curl`.
fn read_source(from: &str, rel: &str) -> anyhow::Result<Vec<u8>> {
    let local = from.strip_prefix("file://").unwrap_or(from);
    if !(from.starts_with("http://") || from.starts_with("https://")) {
        let p = Path::new(local).join(rel);
        return std::fs::read(&p).with_context(|| format!("cannot read {}", p.display()));
    }
    let url = format!("{}/{}", from.trim_end_matches('/'), rel);
    let out = std::process::Command::new("curl")
        // A stalled download (under 1 kB/s for a minute) fails instead of hanging.
        .args([
            "-fsSL",
            "--retry",
            "3",
            "--connect-timeout",
            "20",
            "--speed-limit",
            "1000",
            "--speed-time",
            "60",
            &url,
        ])
        .output()
        .map_err(|e| {
            anyhow!(
                "cannot run curl ({e}): install curl, or download the files by hand and pass the folder with --from"
            )
        })?;
    if !out.status.success() {
        return Err(anyhow!(
            "download of {url} failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    Ok(out.stdout)
}

pub fn run(args: &FetchScenesArgs) -> anyhow::Result<()> {
    let manifest = Manifest::embedded();
    let into = match &args.into {
        Some(p) => p.clone(),
        None => scene_path::user_scene_dir()
            .ok_or_else(|| anyhow!("no home folder known (HOME / XDG_DATA_HOME unset): pass --into"))?,
    };
    let from = args.from.clone().unwrap_or_else(|| manifest.source.clone());
    println!(
        "{} the reference scenes{}: {} -> {}",
        if args.check { "checking" } else { "fetching" },
        if args.scenes.is_empty() {
            String::new()
        } else {
            format!(" ({})", args.scenes.join(", "))
        },
        from,
        into.display()
    );
    let done = fetch(&manifest, &from, &into, &args.scenes, args.check, &mut |l| {
        println!("{l}")
    })?;
    let fetched = done.iter().filter(|(_, o)| *o != Outcome::Present).count();
    println!(
        "{} file(s) ok ({} placed now, {} already present); licences: SponzaLicense.txt, BreakfastRoomLicense.txt (CC BY 3.0)",
        done.len(),
        fetched,
        done.len() - fetched
    );
    let on_path = scene_path::search_dirs(None).iter().any(|(d, _)| d == &into);
    if on_path {
        println!("presets find them now: e.g. `lightcut-workbench --scene scenes/sponza.toml`");
    } else {
        println!(
            "{} is not on the scene search path: set {}={} for presets to find them",
            into.display(),
            scene_path::SCENES_ENV,
            into.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("lightcut-fetch-{name}-{}", std::process::id()));
        std::fs::remove_dir_all(&d).ok();
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A two-file manifest over a local mirror: placement, the skip of present files, a
    /// mismatch that places nothing, and a stand-in.
    #[test]
    fn a_local_mirror_is_checked_and_placed() {
        let mirror = tmp("mirror");
        let into = tmp("into");
        std::fs::create_dir_all(mirror.join("room")).unwrap();
        std::fs::write(mirror.join("room/Room.gltf"), b"{\"asset\":{}}").unwrap();
        std::fs::write(mirror.join("room/tex.png"), b"pixels").unwrap();
        let file = |path: &str, bytes: &[u8]| ManifestFile {
            path: path.into(),
            bytes: bytes.len() as u64,
            sha256: sha256_hex(bytes),
            standin: false,
        };
        let (name, standin) = STANDINS[0];
        let mut m = Manifest {
            source: "https://example.invalid".into(),
            files: vec![
                file("room/Room.gltf", b"{\"asset\":{}}"),
                file("room/tex.png", b"pixels"),
                ManifestFile {
                    standin: true,
                    ..file(&format!("room/{name}"), standin)
                },
            ],
        };
        let from = mirror.display().to_string();
        let mut log = |_: &str| {};
        let done = fetch(&m, &from, &into, &[], false, &mut log).unwrap();
        assert_eq!(
            done.iter().map(|(_, o)| *o).collect::<Vec<_>>(),
            [Outcome::Fetched, Outcome::Fetched, Outcome::StandIn]
        );
        assert_eq!(std::fs::read(into.join("room/tex.png")).unwrap(), b"pixels");
        assert_eq!(std::fs::read(into.join("room").join(name)).unwrap(), standin);
        // A second run keeps what is there; --check passes.
        let again = fetch(&m, &from, &into, &["room".into()], true, &mut log).unwrap();
        assert!(again.iter().all(|(_, o)| *o == Outcome::Present));
        // A mirror file that differs from the manifest fails, naming it, and places nothing.
        std::fs::remove_file(into.join("room/tex.png")).unwrap();
        std::fs::write(mirror.join("room/tex.png"), b"pixelz").unwrap();
        let e = fetch(&m, &from, &into, &[], false, &mut log)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("room/tex.png") && e.contains("checksum mismatch"),
            "{e}"
        );
        assert!(!into.join("room/tex.png").exists());
        assert!(
            std::fs::read_dir(into.join("room"))
                .unwrap()
                .all(|e| { !e.unwrap().file_name().to_string_lossy().ends_with(".part") })
        );
        // A file missing from the mirror fails the same way; an unknown scene is refused.
        m.files.push(file("room/gone.bin", b"x"));
        let e = fetch(&m, &from, &into, &[], false, &mut log)
            .unwrap_err()
            .to_string();
        assert!(e.contains("2 of 4"), "{e}");
        let e = fetch(&m, &from, &into, &["hall".into()], false, &mut log)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no scene 'hall'"), "{e}");
        std::fs::remove_dir_all(&mirror).ok();
        std::fs::remove_dir_all(&into).ok();
    }
}
