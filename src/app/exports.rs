//! Files the workbench writes and finds: view exports (PNG as displayed, EXR of the buffer),
//! comparison sheets, fresh file names, the scene presets.

use super::*;

/// A file name in `dir` that does not exist yet: `stem_NNN.ext`.
pub(super) fn fresh_path(dir: &std::path::Path, stem: &str, ext: &str) -> PathBuf {
    let slug: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    let mut n = 0;
    loop {
        let p = dir.join(format!("{slug}_{n:03}.{ext}"));
        if !p.exists() {
            return p;
        }
        n += 1;
    }
}

/// Writes a comparison sheet (PNG + JSON of its metrics) into `dir`; returns the paths.
pub fn write_sheet(sheet: &crate::sheet::Sheet, dir: &std::path::Path) -> Result<(PathBuf, PathBuf), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let canvas = crate::sheet::compose(sheet)?;
    let png = fresh_path(dir, "comparison sheet", "png");
    crate::export::write_png(&png, canvas.width, canvas.height, &canvas.rgba).map_err(|e| e.to_string())?;
    let json = png.with_extension("json");
    std::fs::write(&json, crate::sheet::metrics_json(sheet))
        .map_err(|e| format!("cannot write {}: {e}", json.display()))?;
    Ok((png, json))
}

/// The files of one view export (see [`WorkbenchApp::export_view`]).
pub fn export_view_files(
    r: &Renderer,
    slot: usize,
    spec: &crate::gpu::views::ViewSpec,
    kind: ExportKind,
    dir: &std::path::Path,
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let name = spec.buffer.name();
    match kind {
        ExportKind::Png => {
            let (w, h, bytes) = r.read_view_rgba8_at(slot).map_err(|e| e.to_string())?;
            let path = fresh_path(dir, name, "png");
            crate::export::write_png(&path, w, h, &bytes).map_err(|e| e.to_string())?;
            Ok(vec![path])
        }
        ExportKind::Exr => {
            let images = match spec.effective_ab() {
                Some(ab) => vec![
                    (format!("{name} A {}", ab.a.name()), r.read_ab_source(ab.a)),
                    (format!("{name} B {}", ab.b.name()), r.read_ab_source(ab.b)),
                ],
                None => vec![(name.to_string(), r.read_view_buffer(spec.buffer))],
            };
            let mut files = Vec::new();
            for (stem, img) in images {
                let img = img.map_err(|e| e.to_string())?.ok_or_else(|| {
                    format!("'{stem}' has no linear image now (PNG export shows it as displayed)")
                })?;
                let path = fresh_path(dir, &stem, "exr");
                crate::export::write_exr(&path, &img).map_err(|e| e.to_string())?;
                files.push(path);
            }
            Ok(files)
        }
    }
}

/// The capture record of what the workbench shows: settings, scene and its file's hash,
/// camera, lights (with the sun as edited), render size, frame index and frames averaged,
/// the adapter and the commit.
pub(super) fn capture_of(
    r: &Renderer,
    open: &OpenScene,
    lights: &[DirectionalLight],
    what: &str,
) -> (crate::capture::Capture, crate::settings::RenderSettings) {
    let mut c = crate::capture::Capture::new(what, &r.ctx.adapter_info, &open.source, open.file.as_deref());
    c.camera = (&open.camera).into();
    c.lights = lights.iter().map(Into::into).collect();
    (c.width, c.height) = r.size();
    c.seed = r.settings().vpl.seed;
    c.frames = r.sampling_frames().max(1);
    c.frame_index = r.frame_index();
    // The image is the last `frames` frames (one without accumulation).
    c.first_frame = r
        .settings()
        .gi
        .method
        .per_frame()
        .then(|| r.frame_index().saturating_sub(c.frames as u64));
    (c, r.settings().clone())
}

/// Writes the capture record beside each of `files` (`name.capture.toml`; one per stem).
pub(super) fn write_capture_records(
    mut c: crate::capture::Capture,
    settings: &crate::settings::RenderSettings,
    files: &[PathBuf],
) -> Result<(), String> {
    c.files = files
        .iter()
        .filter_map(|f| f.file_name().map(|n| n.to_string_lossy().to_string()))
        .collect();
    let mut done = std::collections::BTreeSet::new();
    for f in files {
        let rec = crate::capture::sidecar_path(f);
        if done.insert(rec.clone()) {
            crate::capture::write_record(&rec, &c, settings)?;
        }
    }
    Ok(())
}

impl WorkbenchApp {
    /// [`capture_of`] the open scene, with the sun as edited.
    pub fn capture_record(
        &self,
        what: &str,
    ) -> Option<(crate::capture::Capture, crate::settings::RenderSettings)> {
        let r = self.renderer.as_ref()?;
        let open = self.open.as_ref()?;
        let lights = super::frame::lights_with_sun(&open.scene, self.sun.as_ref());
        Some(capture_of(r, open, &lights, what))
    }

    /// Writes the record of what is shown beside each of `files`; errors go to the status.
    pub(super) fn record_captures(&mut self, what: &str, files: &[PathBuf]) {
        if let Some((c, s)) = self.capture_record(what)
            && let Err(e) = write_capture_records(c, &s, files)
        {
            self.errors.push(format!("capture record: {e}"));
        }
    }
}

/// Preset files shipped under `scenes/` (next to the executable's working directory).
pub fn preset_files() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir("scenes")
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}
