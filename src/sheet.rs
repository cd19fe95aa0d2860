//! Comparison sheets: the chosen methods side by side on the same VPLs and tree, each with its
//! final image, the relative error of its GI against the ground truth of those VPLs (log false
//! colour, as the relative-error view), and a caption (method, settings, RMSE with the
//! image-mean ratio against the ground truth beside it, relative RMSE, SSIM, FLIP, GPU time
//! per frame). One image, for papers and reports.
//!
//! [`SheetJob`] does the work one frame per [`SheetJob::step`], so the GUI stays responsive,
//! shows progress and can cancel; the `sheet` command loops it. [`compose`] draws the sheet
//! (text with the Hack font egui ships, rasterised by `ab_glyph`).

use crate::methods::tree_samplers::settings::SamplingSettings;
use ab_glyph::{Font, FontRef, PxScale, ScaleFont};

use crate::{
    base::{colormap::false_color, display},
    metrics::{self, Metrics},
    renderer::{
        Buffer, FrameInput, FrameMode, Renderer,
        readback::ImageF32,
        settings::{MethodId, RenderSettings, ViewBuffer},
    },
    scene::{Camera, DirectionalLight},
};

/// One method's column.
pub struct SheetColumn {
    pub method: MethodId,
    pub final_: ImageF32,
    pub indirect: ImageF32,
    /// Its GI against the ground truth's.
    pub metrics: Metrics,
    /// Mean GPU time of a frame (all passes), ms; None without timestamps.
    pub gpu_ms: Option<f64>,
    pub frames: u32,
}

/// Everything a sheet shows.
pub struct Sheet {
    pub reference_final: ImageF32,
    pub reference_indirect: ImageF32,
    pub columns: Vec<SheetColumn>,
    pub settings: RenderSettings,
    pub vpls: u32,
    /// Scene and camera, for the title.
    pub title: String,
}

enum Stage {
    Truth {
        frame: u32,
    },
    Method {
        i: usize,
        frame: u32,
        ms: f64,
        timed: u32,
    },
    Done,
}

/// What a step did.
pub enum Step {
    Running { fraction: f32, label: String },
    Done(Box<Sheet>),
}

/// The work of one sheet, a frame at a time: the ground truth of the frame's VPLs (the VPLs
/// and tree are then frozen), then every method for `frames` accumulated frames.
pub struct SheetJob {
    base: RenderSettings,
    methods: Vec<MethodId>,
    frames: u32,
    gt_rays_per_frame: Option<u32>,
    stage: Stage,
    gt: Option<(ImageF32, ImageF32)>,
    columns: Vec<SheetColumn>,
    title: String,
    /// The renderer's frame mode before the job (the methods' frames are timed; restored).
    mode_before: Option<FrameMode>,
}

impl SheetJob {
    /// `methods`: tree samplers (SLC, SST, RTSLC) or the converged reference; `frames` >= 1.
    /// `gt_rays_per_frame` speeds the ground truth up where interactivity does not matter.
    pub fn new(
        base: RenderSettings,
        methods: Vec<MethodId>,
        frames: u32,
        gt_rays_per_frame: Option<u32>,
        title: String,
    ) -> Result<Self, String> {
        if methods.is_empty() {
            return Err("a sheet needs at least one method".into());
        }
        let columns = crate::methods::sheet_columns();
        if let Some(m) = methods.iter().find(|m| !columns.contains(m)) {
            let names: Vec<&str> = columns.iter().map(|c| c.name()).collect();
            return Err(format!(
                "'{}' cannot be a sheet column (use {})",
                m.name(),
                names.join(", ")
            ));
        }
        if frames == 0 || frames > 4096 {
            return Err(format!("frames must be 1..=4096 (got {frames})"));
        }
        Ok(Self {
            base,
            methods,
            frames,
            gt_rays_per_frame,
            stage: Stage::Truth { frame: 0 },
            gt: None,
            columns: Vec::new(),
            title,
            mode_before: None,
        })
    }

    /// Renders one frame of the job. Errors leave the renderer's settings to [`Self::restore`].
    pub fn step(
        &mut self,
        r: &mut Renderer,
        camera: &Camera,
        lights: &[DirectionalLight],
    ) -> Result<Step, String> {
        let frame = |r: &mut Renderer| {
            r.render(&FrameInput {
                camera,
                lights,
                view: ViewBuffer::Final,
            })
        };
        let n_methods = self.methods.len() as f32;
        match &mut self.stage {
            Stage::Truth { frame: f } => {
                if *f == 0 {
                    let mut s = self.base.clone();
                    s.gi.method = crate::methods::comparison_truth();
                    if let Some(rays) = self.gt_rays_per_frame {
                        s.gi.rays_per_frame = rays;
                    }
                    r.set_freeze_tree(false);
                    r.set_settings(s).map_err(|e| e.to_string())?;
                }
                frame(r);
                // Every method then samples these VPLs and this tree.
                r.set_freeze_tree(true);
                *f += 1;
                let p = r.gi_progress().unwrap_or_default();
                if p.finished() && *f > 1 {
                    let fin = r.read(Buffer::Final).map_err(|e| e.to_string())?;
                    let ind = r.read(Buffer::Indirect).map_err(|e| e.to_string())?;
                    self.gt = Some((fin, ind));
                    self.stage = Stage::Method {
                        i: 0,
                        frame: 0,
                        ms: 0.0,
                        timed: 0,
                    };
                }
                Ok(Step::Running {
                    fraction: 0.5 * p.fraction(),
                    label: format!("ground truth: {} / {} VPLs", p.done, p.total),
                })
            }
            Stage::Method {
                i,
                frame: f,
                ms,
                timed,
            } => {
                let method = self.methods[*i];
                if *f == 0 {
                    let mut s = self.base.clone();
                    s.gi.method = method;
                    s.frame.accumulate = true;
                    r.set_settings(s).map_err(|e| e.to_string())?;
                    // Every frame of the method timed, without diagnostics; drain the timings
                    // of earlier frames (the readback skips frames while one is pending).
                    self.mode_before.get_or_insert(r.frame_mode());
                    r.set_frame_mode(FrameMode::Timed);
                    let _ = r.wait_new_timings();
                }
                frame(r);
                if let Some(t) = r.wait_new_timings() {
                    *ms += t.total_ms();
                    *timed += 1;
                }
                *f += 1;
                let label = format!("{}: frame {} / {}", method.name(), *f, self.frames);
                let fraction = 0.5 + 0.5 * (*i as f32 + *f as f32 / self.frames as f32) / n_methods;
                if *f >= self.frames {
                    let final_ = r.read(Buffer::Final).map_err(|e| e.to_string())?;
                    let indirect = r.read(Buffer::Indirect).map_err(|e| e.to_string())?;
                    let (_, gt) = self.gt.as_ref().ok_or("no ground truth")?;
                    let d = &self.base.display;
                    let m = metrics::compare(&indirect, gt, d.exposure_ev, d.tonemap);
                    self.columns.push(SheetColumn {
                        method,
                        final_,
                        indirect,
                        metrics: m,
                        gpu_ms: (*timed > 0).then(|| *ms / *timed as f64),
                        frames: self.frames,
                    });
                    let next = *i + 1;
                    self.stage = if next < self.methods.len() {
                        Stage::Method {
                            i: next,
                            frame: 0,
                            ms: 0.0,
                            timed: 0,
                        }
                    } else {
                        Stage::Done
                    };
                }
                if matches!(self.stage, Stage::Done) {
                    let (reference_final, reference_indirect) = self.gt.take().ok_or("no ground truth")?;
                    self.restore(r);
                    return Ok(Step::Done(Box::new(Sheet {
                        reference_final,
                        reference_indirect,
                        columns: std::mem::take(&mut self.columns),
                        settings: self.base.clone(),
                        vpls: r.vpl_frame().count,
                        title: self.title.clone(),
                    })));
                }
                Ok(Step::Running { fraction, label })
            }
            Stage::Done => Err("the sheet is finished".into()),
        }
    }

    /// Puts the renderer back as it was (the job's settings, tree unfrozen).
    pub fn restore(&self, r: &mut Renderer) {
        r.set_freeze_tree(false);
        if let Some(m) = self.mode_before {
            r.set_frame_mode(m);
        }
        let _ = r.set_settings(self.base.clone());
    }

    /// Runs the whole job (the `sheet` command).
    pub fn run(
        mut self,
        r: &mut Renderer,
        camera: &Camera,
        lights: &[DirectionalLight],
        mut progress: impl FnMut(f32, &str),
    ) -> Result<Sheet, String> {
        loop {
            match self.step(r, camera, lights) {
                Ok(Step::Running { fraction, label }) => progress(fraction, &label),
                Ok(Step::Done(sheet)) => return Ok(*sheet),
                Err(e) => {
                    self.restore(r);
                    return Err(e);
                }
            }
        }
    }
}

/// The sheet's numbers as JSON (per column: method, frames, GPU ms per frame, and the metrics
/// against the ground truth under `vs_ground_truth`: `rmse`, `relative_rmse`, `ssim`,
/// `mean_ratio`, `reference_mean`, `flip`; NaN is written as null).
pub fn metrics_json(sheet: &Sheet) -> String {
    let columns: Vec<serde_json::Value> = sheet
        .columns
        .iter()
        .map(|c| {
            serde_json::json!({
                "method": format!("{:?}", c.method),
                "frames": c.frames,
                "gpu_ms_per_frame": c.gpu_ms,
                "vs_ground_truth": c.metrics,
            })
        })
        .collect();
    let json = serde_json::json!({
        "title": sheet.title,
        "width": sheet.reference_final.width,
        "height": sheet.reference_final.height,
        "vpls": sheet.vpls,
        "columns": columns,
        "settings": sheet.settings,
    });
    serde_json::to_string_pretty(&json).unwrap_or_default()
}

/// An RGBA8 canvas.
pub struct Canvas {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl Canvas {
    fn new(width: u32, height: u32, bg: [u8; 3]) -> Self {
        let mut rgba = Vec::with_capacity((width * height * 4) as usize);
        for _ in 0..width * height {
            rgba.extend_from_slice(&[bg[0], bg[1], bg[2], 255]);
        }
        Self { width, height, rgba }
    }

    fn blend(&mut self, x: i32, y: i32, c: [u8; 3], a: f32) {
        if x < 0 || y < 0 || x >= self.width as i32 || y >= self.height as i32 {
            return;
        }
        let i = ((y as u32 * self.width + x as u32) * 4) as usize;
        for (dst, src) in self.rgba[i..i + 3].iter_mut().zip(c) {
            let d = *dst as f32;
            *dst = (d + (src as f32 - d) * a.clamp(0.0, 1.0)).round() as u8;
        }
    }

    /// `img` (RGB8 per pixel) scaled by `s` (nearest) with its top-left at (x, y).
    fn blit(&mut self, x: u32, y: u32, w: u32, h: u32, s: u32, px: impl Fn(u32, u32) -> [u8; 3]) {
        for j in 0..h * s {
            for i in 0..w * s {
                self.blend((x + i) as i32, (y + j) as i32, px(i / s, j / s), 1.0);
            }
        }
    }

    /// Text with its top-left at (x, y), `size` pixels high; returns its width.
    fn text(&mut self, font: &FontRef<'_>, x: f32, y: f32, size: f32, c: [u8; 3], s: &str) -> f32 {
        let scaled = font.as_scaled(PxScale::from(size));
        let mut pen = x;
        let baseline = y + scaled.ascent();
        let mut prev = None;
        for ch in s.chars() {
            let id = scaled.glyph_id(ch);
            if let Some(p) = prev {
                pen += scaled.kern(p, id);
            }
            let g = id.with_scale_and_position(PxScale::from(size), ab_glyph::point(pen, baseline));
            pen += scaled.h_advance(id);
            prev = Some(id);
            if let Some(out) = font.outline_glyph(g) {
                let b = out.px_bounds();
                out.draw(|gx, gy, cov| {
                    self.blend(b.min.x as i32 + gx as i32, b.min.y as i32 + gy as i32, c, cov);
                });
            }
        }
        pen - x
    }
}

/// Relative error |lum(a) - lum(b)| / lum(b), log10 false colour from 1e-2 to 1e1 (the
/// relative-error view's map); black where both are black.
pub fn relative_error_rgb8(a: [f32; 4], b: [f32; 4]) -> [u8; 3] {
    let l = |p: [f32; 4]| display::luminance(glam::Vec3::new(p[0], p[1], p[2]));
    let (la, lb) = (l(a), l(b));
    if la <= 0.0 && lb <= 0.0 {
        return [0, 0, 0];
    }
    let rel = (la - lb).abs() / lb.max(1e-6);
    let t = (rel.max(1e-30).log10() + 2.0) / 3.0;
    false_color(t).map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

/// The caption lines under a method's images (at most [`CAPTION_LINES`]): the frames, then
/// the RMSE with the image-mean ratio against the ground truth beside it (a bias cannot hide
/// behind a small RMSE), the relative RMSE and SSIM, FLIP, and the GPU time.
pub fn caption(cl: &SheetColumn) -> Vec<String> {
    let m = &cl.metrics;
    vec![
        format!("{} frames accumulated", cl.frames),
        format!("RMSE {:.3e} · mean {:.3}x", m.rmse, m.mean_ratio),
        format!("rel. RMSE {:.3} · SSIM {:.4}", m.relative_rmse, m.ssim),
        format!("FLIP {:.4}", m.flip),
        match cl.gpu_ms {
            Some(t) => format!("GPU {t:.2} ms / frame (all passes)"),
            None => "GPU time: no timestamps".into(),
        },
    ]
}

/// Lines of a column's caption (room the sheet keeps under every column).
pub const CAPTION_LINES: usize = 5;

/// Draws the sheet: a title, then one column for the ground truth and one per method (final
/// image; relative error of the GI, or the reference GI; caption), and the error legend.
pub fn compose(sheet: &Sheet) -> Result<Canvas, String> {
    let font = FontRef::try_from_slice(epaint_default_fonts::HACK_REGULAR).map_err(|e| e.to_string())?;
    let (w, h) = (sheet.reference_final.width, sheet.reference_final.height);
    if w == 0 || h == 0 {
        return Err("empty images".into());
    }
    let s = 320u32.div_ceil(w).max(1);
    let (cw, ch) = (w * s, h * s);
    let (margin, gap, text) = (16u32, 12u32, 13.0f32);
    let line = (text * 1.35) as u32;
    let n = 1 + sheet.columns.len() as u32;
    let caption_lines = CAPTION_LINES as u32;
    let width = 2 * margin + n * cw + (n - 1) * gap;
    let header = 2 * line + 8;
    let height = margin + header + 2 * (ch + line + 6) + caption_lines * line + 3 * line + margin;
    let mut c = Canvas::new(width, height, [24, 24, 24]);
    let d = &sheet.settings.display;
    let white = [235, 235, 235];
    let grey = [170, 170, 170];
    c.text(
        &font,
        margin as f32,
        margin as f32,
        text + 3.0,
        white,
        &sheet.title,
    );
    let st = &sheet.settings;
    c.text(
        &font,
        margin as f32,
        (margin + line + 4) as f32,
        text,
        grey,
        &format!(
            "{w}x{h} · {} VPLs (the same VPLs and tree for every column) · v_min {} · σ_max {} m · k {} · cut size {} · exposure {} EV, {}",
            sheet.vpls,
            st.tree.v_min,
            st.tree.sigma_max,
            SamplingSettings::of(st).block_size,
            SamplingSettings::of(st).cut_size,
            d.exposure_ev,
            d.tonemap.name()
        ),
    );
    let top = margin + header;
    fn shown<'a>(
        img: &'a ImageF32,
        d: &'a crate::settings::DisplaySettings,
    ) -> impl Fn(u32, u32) -> [u8; 3] + 'a {
        move |x: u32, y: u32| {
            let e = display::encode(img.get(x, y), d.exposure_ev, d.tonemap);
            [e[0], e[1], e[2]]
        }
    }
    for col in 0..n {
        let x = margin + col * (cw + gap);
        let mut y = top;
        let (name, fin) = if col == 0 {
            ("ground truth (same VPLs)".to_string(), &sheet.reference_final)
        } else {
            let cl = &sheet.columns[col as usize - 1];
            (cl.method.name().to_string(), &cl.final_)
        };
        c.text(&font, x as f32, y as f32, text, white, &format!("{name}: final"));
        y += line;
        c.blit(x, y, w, h, s, shown(fin, d));
        y += ch + 6;
        if col == 0 {
            c.text(&font, x as f32, y as f32, text, white, "ground truth: GI only");
            y += line;
            c.blit(x, y, w, h, s, shown(&sheet.reference_indirect, d));
        } else {
            let cl = &sheet.columns[col as usize - 1];
            c.text(&font, x as f32, y as f32, text, white, "relative error of the GI");
            y += line;
            let (a, b) = (&cl.indirect, &sheet.reference_indirect);
            c.blit(x, y, w, h, s, |i, j| {
                relative_error_rgb8(a.get(i, j), b.get(i, j))
            });
        }
        y += ch + 6;
        let lines: Vec<String> = if col == 0 {
            vec!["every VPL, one shadow ray each".into(), {
                let m = sheet.reference_indirect.mean_rgb().map(|v| v as f32);
                format!(
                    "GI mean {:.4e} W/(m² sr) (lum.)",
                    display::luminance(glam::Vec3::from(m))
                )
            }]
        } else {
            caption(&sheet.columns[col as usize - 1])
        };
        for l in lines {
            c.text(&font, x as f32, y as f32, text, grey, &l);
            y += line;
        }
    }
    // The error legend.
    let ly = height - margin - 2 * line;
    let lw = 260u32.min(width - 2 * margin);
    c.text(
        &font,
        margin as f32,
        (ly - line) as f32,
        text,
        grey,
        "relative error |GI - ground truth| / ground truth (log)",
    );
    for i in 0..lw {
        let t = (i as f32 + 0.5) / lw as f32;
        let col = false_color(t).map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8);
        for j in 0..10 {
            c.blend((margin + i) as i32, (ly + j) as i32, col, 1.0);
        }
    }
    for (k, label) in ["1e-2", "1e-1", "1", "10"].iter().enumerate() {
        let x = margin as f32 + lw as f32 * k as f32 / 3.0 - 8.0;
        c.text(
            &font,
            x.max(margin as f32),
            (ly + 12) as f32,
            text - 2.0,
            grey,
            label,
        );
    }
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn column(m: Metrics, gpu_ms: Option<f64>, frames: u32) -> SheetColumn {
        let img = ImageF32 {
            width: 2,
            height: 2,
            pixels: vec![[0.5, 0.5, 0.5, 1.0]; 4],
        };
        SheetColumn {
            method: crate::methods::per_frame()[0],
            final_: img.clone(),
            indirect: img,
            metrics: m,
            gpu_ms,
            frames,
        }
    }

    fn metrics(rmse: f64, mean_ratio: f64) -> Metrics {
        Metrics {
            rmse,
            relative_rmse: 0.123,
            ssim: 0.9876,
            mean_ratio,
            reference_mean: 0.1,
            flip: 0.0543,
        }
    }

    #[test]
    fn the_caption_shows_the_mean_ratio_beside_the_rmse_and_fits_its_column() {
        let lines = caption(&column(metrics(0.012, 0.98), Some(1.5), 16));
        assert!(lines.len() <= CAPTION_LINES, "{lines:?}");
        assert_eq!(lines[1], "RMSE 1.200e-2 · mean 0.980x");
        assert!(lines.iter().any(|l| l.contains("SSIM 0.9876")), "{lines:?}");
        assert!(lines.iter().any(|l| l.contains("FLIP 0.0543")), "{lines:?}");
        // The widest numbers stay within the narrowest column (320 px at the captions'
        // 13 px).
        let font = FontRef::try_from_slice(epaint_default_fonts::HACK_REGULAR).expect("Hack");
        let mut c = Canvas::new(1, 1, [0, 0, 0]);
        let wide = Metrics {
            relative_rmse: 123.456,
            ssim: -0.1234,
            ..metrics(1.234e-12, 123.456)
        };
        for l in caption(&column(wide, Some(12345.67), 4096)) {
            let w = c.text(&font, 0.0, 0.0, 13.0, [255; 3], &l);
            assert!(w <= 320.0, "'{l}' is {w} px wide");
        }
    }

    #[test]
    fn the_json_has_each_methods_mean_ratio() {
        let img = ImageF32 {
            width: 2,
            height: 2,
            pixels: vec![[0.5, 0.5, 0.5, 1.0]; 4],
        };
        let sheet = Sheet {
            reference_final: img.clone(),
            reference_indirect: img,
            columns: vec![
                column(metrics(0.012, 0.98), None, 4),
                column(metrics(0.02, 1.25), Some(2.0), 4),
            ],
            settings: RenderSettings::default(),
            vpls: 256,
            title: "test".into(),
        };
        let json: serde_json::Value =
            serde_json::from_str(&metrics_json(&sheet)).expect("the sheet's JSON parses");
        let ratios: Vec<f64> = json["columns"]
            .as_array()
            .expect("columns")
            .iter()
            .filter_map(|c| c["vs_ground_truth"]["mean_ratio"].as_f64())
            .collect();
        assert_eq!(ratios, [0.98, 1.25]);
    }
}
