//! Where scene files are found: the search path of presets and `--scene`, the user data
//! folder `fetch-scenes` fills, and the manifest of the reference scenes (issue 41).
//!
//! A relative glTF path in a preset (`gltf = "sponza/Sponza.gltf"`) is looked up, in order:
//! 1. beside the preset file;
//! 2. in each folder of `LIGHTCUT_SCENES` (a path list, `:`-separated on Unix);
//! 3. in the user data folder ([`user_scene_dir`]), where `fetch-scenes` puts the scenes;
//! 4. in `shared/scenes` beside the repository (development machines and CI keep the
//!    measured copies there): `../shared/scenes` from the preset's repository and from the
//!    current folder.
//!
//! A `--scene` glTF path that does not exist as given is looked up the same way (without a
//! preset), so `--scene sponza/Sponza.gltf` opens the fetched Sponza.

use std::path::{Path, PathBuf};

/// Environment variable: extra scene folders, searched before the user data folder.
pub const SCENES_ENV: &str = "LIGHTCUT_SCENES";
/// Older name of a single extra folder (still read: tests and scripts set it).
pub const LEGACY_SCENES_ENV: &str = "LIGHTCUT_SHARED_SCENES";

/// The command that downloads the reference scenes, as a user types it.
pub const FETCH_HINT: &str = "fetch the reference scenes with `lightcut-workbench fetch-scenes` (in the repository: `cargo run --release -- fetch-scenes`)";

/// The manifest of the reference scenes: every file with its size and SHA-256.
pub const MANIFEST: &str = include_str!("../../scenes/reference/manifest.toml");

/// The flat-coloured stand-ins for the three Sponza curtain textures the source lacks.
pub const STANDINS: &[(&str, &[u8])] = &[
    (
        "sponza_curtain_diff.png",
        include_bytes!("../../scenes/reference/standins/sponza_curtain_diff.png"),
    ),
    (
        "sponza_curtain_green_diff.png",
        include_bytes!("../../scenes/reference/standins/sponza_curtain_green_diff.png"),
    ),
    (
        "sponza_curtain_blue_diff.png",
        include_bytes!("../../scenes/reference/standins/sponza_curtain_blue_diff.png"),
    ),
];

/// One file of the reference scenes.
#[derive(Clone, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManifestFile {
    /// Path under the scenes folder, `/`-separated (`sponza/Sponza.gltf`).
    pub path: String,
    pub bytes: u64,
    /// Lower-case hex SHA-256 of the file's bytes.
    pub sha256: String,
    /// Not in the source: written from [`STANDINS`].
    #[serde(default)]
    pub standin: bool,
}

/// The parsed [`MANIFEST`].
#[derive(Clone, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Base URL of the files (a file's URL is `source/path`).
    pub source: String,
    #[serde(rename = "file")]
    pub files: Vec<ManifestFile>,
}

impl Manifest {
    pub fn embedded() -> Manifest {
        // The manifest is compiled in; a unit test parses it.
        toml::from_str(MANIFEST).unwrap_or_else(|e| panic!("scenes/reference/manifest.toml: {e}"))
    }

    /// The scene folders named in the manifest (`sponza`, `breakfast_room`).
    pub fn scenes(&self) -> Vec<String> {
        let mut v: Vec<String> = Vec::new();
        for s in self.files.iter().filter_map(|f| f.path.split('/').next()) {
            if !v.iter().any(|x| x == s) {
                v.push(s.to_string());
            }
        }
        v
    }

    /// True when `file_name` (a bare name like `Sponza.gltf`) is one of the manifest's files.
    pub fn knows(&self, file_name: &str) -> bool {
        self.files
            .iter()
            .any(|f| f.path.rsplit('/').next() == Some(file_name))
    }
}

/// The user data folder of the scenes: `$XDG_DATA_HOME/lightcut-workbench/scenes`, else
/// `~/.local/share/lightcut-workbench/scenes` (`%APPDATA%\lightcut-workbench\scenes` on
/// Windows). `None` when no home folder is known.
pub fn user_scene_dir() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_DATA_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            if cfg!(windows) {
                std::env::var_os("APPDATA").map(PathBuf::from)
            } else {
                std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/share"))
            }
        })?;
    Some(base.join("lightcut-workbench").join("scenes"))
}

/// The folders searched for a relative scene path, in order, each with where it came from.
pub fn search_dirs(preset_dir: Option<&Path>) -> Vec<(PathBuf, &'static str)> {
    let mut v: Vec<(PathBuf, &'static str)> = Vec::new();
    if let Some(d) = preset_dir {
        v.push((d.to_path_buf(), "beside the preset"));
    }
    if let Some(list) = std::env::var_os(SCENES_ENV) {
        v.extend(
            std::env::split_paths(&list)
                .filter(|p| !p.as_os_str().is_empty())
                .map(|p| (p, SCENES_ENV)),
        );
    }
    if let Some(p) = std::env::var_os(LEGACY_SCENES_ENV).filter(|p| !p.is_empty()) {
        v.push((PathBuf::from(p), LEGACY_SCENES_ENV));
    }
    if let Some(d) = user_scene_dir() {
        v.push((d, "the user data folder"));
    }
    if let Some(d) = preset_dir {
        v.push((
            d.join("../../shared/scenes"),
            "shared/scenes beside the repository",
        ));
    }
    v.push((
        PathBuf::from("../shared/scenes"),
        "shared/scenes beside the repository",
    ));
    v
}

/// Finds a scene file: an absolute path or one that exists as given is itself; a relative
/// one is looked up in [`search_dirs`]. The error is one line naming where it looked and,
/// for the reference scenes, the command that fetches them.
pub fn find(rel: &Path, preset_dir: Option<&Path>) -> Result<PathBuf, String> {
    if rel.is_absolute() {
        return if rel.exists() {
            Ok(rel.to_path_buf())
        } else {
            Err(missing_message(rel, &[]))
        };
    }
    if preset_dir.is_none() && rel.exists() {
        return Ok(rel.to_path_buf());
    }
    let dirs = search_dirs(preset_dir);
    for (d, _) in &dirs {
        let p = d.join(rel);
        if p.is_file() {
            return Ok(p);
        }
    }
    Err(missing_message(rel, &dirs))
}

fn missing_message(rel: &Path, dirs: &[(PathBuf, &'static str)]) -> String {
    let looked = if dirs.is_empty() {
        String::new()
    } else {
        let mut seen: Vec<String> = Vec::new();
        for (d, _) in dirs {
            let s = d.display().to_string();
            if !seen.contains(&s) {
                seen.push(s);
            }
        }
        format!(" (looked in {})", seen.join(", "))
    };
    let name = rel.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let hint = if Manifest::embedded().knows(name) {
        format!("; {FETCH_HINT}")
    } else {
        format!("; set {SCENES_ENV} to the folder that holds it")
    };
    format!("scene file {} not found{looked}{hint}", rel.display())
}

/// Lower-case hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    let d = sha2::Sha256::digest(bytes);
    d.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_manifest_parses_and_its_standins_match() {
        let m = Manifest::embedded();
        assert_eq!(m.scenes(), ["sponza", "breakfast_room"]);
        assert!(m.knows("Sponza.gltf") && m.knows("BreakfastRoom.gltf"));
        let standins: Vec<&ManifestFile> = m.files.iter().filter(|f| f.standin).collect();
        assert_eq!(standins.len(), STANDINS.len());
        for f in standins {
            let name = f.path.rsplit('/').next().unwrap();
            let (_, bytes) = STANDINS.iter().find(|(n, _)| *n == name).unwrap();
            assert_eq!(bytes.len() as u64, f.bytes, "{name}");
            assert_eq!(sha256_hex(bytes), f.sha256, "{name}");
        }
        for f in &m.files {
            assert_eq!(f.sha256.len(), 64, "{}", f.path);
            assert!(!f.path.contains(".."), "{}", f.path);
        }
    }

    #[test]
    fn sha256_of_known_strings() {
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn a_preset_relative_file_is_found_beside_it_first_and_a_missing_one_names_the_fetch() {
        let dir = std::env::temp_dir().join(format!("lightcut-scene-path-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sponza")).unwrap();
        std::fs::write(dir.join("sponza/Sponza.gltf"), "{}").unwrap();
        let found = find(Path::new("sponza/Sponza.gltf"), Some(&dir)).unwrap();
        assert_eq!(found, dir.join("sponza/Sponza.gltf"));
        let e = find(Path::new("nowhere/Sponza.gltf"), Some(&dir)).unwrap_err();
        assert!(
            e.contains("fetch-scenes") && e.contains("looked in") && !e.contains('\n'),
            "{e}"
        );
        let e = find(Path::new("nowhere/mine.gltf"), Some(&dir)).unwrap_err();
        assert!(e.contains(SCENES_ENV) && !e.contains("fetch-scenes"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
