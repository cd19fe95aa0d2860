//! Frame sequences for temporal measurements: a motion (a camera path through bookmarks, a sun
//! sweep, or a still view) walked frame by frame, the ground truth of each frame's VPLs, and
//! per frame the method's raw estimate and the temporal stage's output against it (RMSE, the
//! image-mean ratio, SSIM) and their flicker (frame-to-frame change in static regions beyond
//! the truth's own). Used by `render --camera-path / --sun-sweep` and `results temporal`.

use anyhow::{anyhow, bail};

use crate::base::display::{Tonemap, luminance};
use crate::gpu::readback::ImageF32;
use crate::gpu::timing::PassTimings;
use crate::metrics;
use crate::renderer::Buffer;
use crate::renderer::FrameInput;
use crate::renderer::FrameMode;
use crate::renderer::Renderer;
use crate::scene::{
    Camera, DirectionalLight, Scene,
    camera_path::{CameraPath, sun_sweep},
};
use crate::settings::RenderSettings;
use crate::settings::ViewBuffer;

/// A camera and lights per frame.
#[derive(Clone, Debug)]
pub struct Motion {
    /// "camera path", "sun sweep", "still", or both moving ("camera path + sun sweep").
    pub name: String,
    pub cameras: Vec<Camera>,
    pub lights: Vec<Vec<DirectionalLight>>,
}

impl Motion {
    /// `frames` frames along the spline through the scene's bookmarks named in `names` (all,
    /// in order, when empty), with `lights` fixed.
    pub fn camera_path(
        scene: &Scene,
        names: &[String],
        frames: u32,
        lights: &[DirectionalLight],
    ) -> anyhow::Result<Motion> {
        let keys: Vec<Camera> = if names.is_empty() {
            scene.cameras.clone()
        } else {
            names
                .iter()
                .map(|n| {
                    scene
                        .cameras
                        .iter()
                        .find(|c| c.name == *n)
                        .cloned()
                        .ok_or_else(|| {
                            let all: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
                            anyhow!(
                                "--camera-path: no bookmark '{n}'; the scene has: {}",
                                all.join(", ")
                            )
                        })
                })
                .collect::<anyhow::Result<_>>()?
        };
        Motion::through(&keys, frames, lights).map_err(|e| anyhow!("--camera-path: {e}"))
    }

    /// `frames` frames along the spline through `keys` (two or more), `lights` fixed.
    pub fn through(keys: &[Camera], frames: u32, lights: &[DirectionalLight]) -> anyhow::Result<Motion> {
        let path = CameraPath::through(keys).map_err(|e| anyhow!(e))?;
        Ok(Motion {
            name: "camera path".into(),
            cameras: path.frames(frames),
            lights: vec![lights.to_vec(); frames as usize],
        })
    }

    /// The bookmarks of a path: the scene's cameras, or with fewer than two, `camera` and a
    /// point beside it (`step` metres to its right, turned 10 degrees back towards the view).
    pub fn path_keys(cameras: &[Camera], camera: &Camera, step: f32) -> Vec<Camera> {
        if cameras.len() >= 2 {
            return cameras.to_vec();
        }
        let turn = glam::Quat::from_axis_angle(camera.up, 10f32.to_radians());
        let beside = Camera {
            name: format!("{} (beside)", camera.name),
            position: camera.position + step * camera.right(),
            forward: turn * camera.forward,
            ..camera.clone()
        };
        vec![camera.clone(), beside]
    }

    /// Its first `n` frames.
    pub fn first(mut self, n: usize) -> Motion {
        self.cameras.truncate(n);
        self.lights.truncate(n);
        self
    }

    /// `frames` frames from `camera` while light 0's azimuth turns by `degrees`.
    pub fn sun_sweep(
        camera: &Camera,
        lights: &[DirectionalLight],
        degrees: f32,
        frames: u32,
    ) -> anyhow::Result<Motion> {
        let Some(sun) = lights.first() else {
            bail!("--sun-sweep: the scene has no directional light to sweep");
        };
        let suns = sun_sweep(sun, degrees, frames);
        Ok(Motion {
            name: "sun sweep".into(),
            cameras: vec![camera.clone(); frames as usize],
            lights: suns
                .into_iter()
                .map(|s| {
                    let mut l = lights.to_vec();
                    l[0] = s;
                    l
                })
                .collect(),
        })
    }

    /// `frames` frames of a still view (flicker alone).
    pub fn still(camera: &Camera, lights: &[DirectionalLight], frames: u32) -> Motion {
        Motion {
            name: "still".into(),
            cameras: vec![camera.clone(); frames as usize],
            lights: vec![lights.to_vec(); frames as usize],
        }
    }

    /// This motion's cameras with `other`'s lights (a camera path under a sun sweep).
    pub fn with_lights_of(mut self, other: &Motion) -> Motion {
        self.name = format!("{} + {}", self.name, other.name);
        self.lights = other.lights.clone();
        self
    }

    pub fn len(&self) -> usize {
        self.cameras.len()
    }

    pub fn is_empty(&self) -> bool {
        self.cameras.is_empty()
    }

    /// Whether frame i shows what frame i - 1 showed (the truth can be reused).
    fn same_as_previous(&self, i: usize) -> bool {
        i > 0 && self.cameras[i] == self.cameras[i - 1] && self.lights[i] == self.lights[i - 1]
    }

    /// Renders frame `i`.
    pub fn render(&self, r: &mut Renderer, i: usize) {
        r.render(&FrameInput {
            camera: &self.cameras[i],
            lights: &self.lights[i],
            view: ViewBuffer::Final,
        });
    }
}

/// A checksum of the renderer's current VPLs (FNV-1a of their records).
pub fn vpl_hash(r: &Renderer) -> anyhow::Result<u64> {
    let v = r.read_vpls()?;
    let bytes: &[u8] = bytemuck::cast_slice(&v);
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x100_0000_01b3);
    }
    Ok(h)
}

/// One frame's truth: the ground truth of its VPLs (GI radiance), their checksum, and the
/// frame's G-buffer positions (the static-region test of the flicker).
#[derive(Clone, Debug)]
pub struct Truth {
    pub gi: ImageF32,
    pub vpls: u64,
    pub position: ImageF32,
}

/// The ground truth of every frame of `m` (the comparison truth of each frame's own VPLs,
/// run to the end), with `base`'s VPL and shading settings; frames that repeat the previous
/// one reuse its truth. The renderer keeps the ground truth's settings afterwards.
pub fn ground_truths(
    r: &mut Renderer,
    base: &RenderSettings,
    m: &Motion,
    mut progress: impl FnMut(usize),
) -> anyhow::Result<Vec<Truth>> {
    let mut g = base.clone();
    g.gi.method = crate::methods::comparison_truth();
    g.gi.rays_per_frame = 1 << 26;
    g.vpl.animate = false;
    r.set_settings(g)?;
    r.set_frame_mode(FrameMode::Diagnostic);
    let mut out: Vec<Truth> = Vec::new();
    for i in 0..m.len() {
        if m.same_as_previous(i)
            && let Some(t) = out.last()
        {
            out.push(t.clone());
            continue;
        }
        let mut frames = 0;
        loop {
            m.render(r, i);
            frames += 1;
            if r.gi_progress().is_some_and(|p| p.finished()) && frames > 1 {
                break;
            }
            if frames > 100_000 {
                bail!("the ground truth of frame {i} did not finish");
            }
        }
        r.wait_idle();
        out.push(Truth {
            gi: r.read(Buffer::Indirect)?,
            vpls: vpl_hash(r)?,
            position: r.read(Buffer::Position)?,
        });
        progress(i);
    }
    Ok(out)
}

/// One frame of a measured sequence.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SeqFrame {
    pub rmse_raw: f64,
    pub rmse_filtered: f64,
    /// Image-mean ratio mean(image) / mean(truth) of the raw estimate and of the stage's
    /// output against the frame's truth (`metrics::Metrics::mean_ratio`: the bias beside the
    /// RMSE).
    pub mean_ratio_raw: f64,
    pub mean_ratio_filtered: f64,
    pub ssim_raw: f64,
    pub ssim_filtered: f64,
    /// Relative frame-to-frame change in static pixels beyond the truth's change (NaN on the
    /// first frame or without static pixels).
    pub flicker_raw: f64,
    pub flicker_filtered: f64,
    /// Pixels counted as static against the previous frame.
    pub static_pixels: usize,
}

/// Flicker of `cur` after `prev` against the truths' change: sum over static pixels of
/// |dI - dG| (luminance) / sum of G. Static: a covered pixel whose world position moved less
/// than 1e-4 of its distance to the camera and kept its material. Returns (flicker, count);
/// NaN when fewer than 1% of the pixels are static (a moving camera).
pub fn flicker(
    prev: &ImageF32,
    cur: &ImageF32,
    t_prev: &Truth,
    t_cur: &Truth,
    eye: glam::Vec3,
) -> (f64, usize) {
    let lum = |p: &[f32; 4]| luminance(glam::Vec3::from_slice(&p[..3])) as f64;
    let (mut num, mut den, mut n) = (0.0f64, 0.0f64, 0usize);
    for k in 0..cur.pixels.len() {
        let (a, b) = (t_prev.position.pixels[k], t_cur.position.pixels[k]);
        if b[3] == 0.0 || a[3] != b[3] {
            continue;
        }
        let pa = glam::Vec3::from_slice(&a[..3]);
        let pb = glam::Vec3::from_slice(&b[..3]);
        if pa.distance(pb) > 1e-4 * pb.distance(eye) {
            continue;
        }
        let di = lum(&cur.pixels[k]) - lum(&prev.pixels[k]);
        let dg = lum(&t_cur.gi.pixels[k]) - lum(&t_prev.gi.pixels[k]);
        num += (di - dg).abs();
        den += lum(&t_cur.gi.pixels[k]);
        n += 1;
    }
    // Fewer than 1% of the pixels static (a moving camera): no measurement.
    if n * 100 < cur.pixels.len() || den <= 0.0 {
        (f64::NAN, n)
    } else {
        (num / den, n)
    }
}

/// Walks `m` with settings `s` (a per-frame method; its temporal stage as `s.temporal` says)
/// from a fresh history, diagnostic frames, and compares each frame's raw estimate and its
/// output with `truths` (RMSE, mean ratio, SSIM at `exposure_ev`). Checks that every frame
/// saw its truth's VPLs. `on_frame(r, i)` runs after each frame (writing its images, say).
/// Also returns the wall time spent rendering and waiting for the GPU (the rest is readbacks
/// and metrics).
pub fn measure(
    r: &mut Renderer,
    s: &RenderSettings,
    m: &Motion,
    truths: &[Truth],
    exposure_ev: f32,
    tonemap: Tonemap,
    mut on_frame: impl FnMut(&mut Renderer, usize) -> anyhow::Result<()>,
) -> anyhow::Result<(Vec<SeqFrame>, std::time::Duration)> {
    r.set_settings(s.clone())?;
    r.set_frame_mode(FrameMode::Diagnostic);
    r.reset_temporal();
    let mut out = Vec::new();
    let mut prev: Option<(ImageF32, ImageF32)> = None;
    let mut rendering = std::time::Duration::ZERO;
    for i in 0..m.len() {
        let t = std::time::Instant::now();
        m.render(r, i);
        r.wait_idle();
        rendering += t.elapsed();
        on_frame(r, i)?;
        let filtered = r.read(Buffer::Indirect)?;
        let raw = r.read_temporal_raw()?.unwrap_or_else(|| filtered.clone());
        let t = &truths[i];
        if vpl_hash(r)? != t.vpls {
            bail!(
                "frame {i} of the {}: the VPLs differ from its ground truth's (non-deterministic VPL generation?)",
                m.name
            );
        }
        let a = metrics::compare_without_flip(&raw, &t.gi, exposure_ev, tonemap);
        let b = metrics::compare_without_flip(&filtered, &t.gi, exposure_ev, tonemap);
        let mut f = SeqFrame {
            rmse_raw: a.rmse,
            rmse_filtered: b.rmse,
            mean_ratio_raw: a.mean_ratio,
            mean_ratio_filtered: b.mean_ratio,
            ssim_raw: a.ssim,
            ssim_filtered: b.ssim,
            flicker_raw: f64::NAN,
            flicker_filtered: f64::NAN,
            static_pixels: 0,
        };
        if let Some((praw, pfilt)) = &prev {
            let eye = m.cameras[i].position;
            (f.flicker_raw, f.static_pixels) = flicker(praw, &raw, &truths[i - 1], t, eye);
            f.flicker_filtered = flicker(pfilt, &filtered, &truths[i - 1], t, eye).0;
        }
        prev = Some((raw, filtered));
        out.push(f);
    }
    Ok((out, rendering))
}

/// Walks `m` with settings `s` in diagnostic frames from a fresh history, calling
/// `on_frame(r, i)` after each.
pub fn walk(
    r: &mut Renderer,
    s: &RenderSettings,
    m: &Motion,
    mut on_frame: impl FnMut(&mut Renderer, usize) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    r.set_settings(s.clone())?;
    r.set_frame_mode(FrameMode::Diagnostic);
    r.reset_temporal();
    for i in 0..m.len() {
        m.render(r, i);
        r.wait_idle();
        on_frame(r, i)?;
    }
    Ok(())
}

/// Walks the first `n` frames of `m` with settings `s` in timed frames (no diagnostics, no
/// readbacks) from a fresh history, after `warmup` untimed frames of its first view; returns
/// each frame's GPU timestamps.
pub fn time(
    r: &mut Renderer,
    s: &RenderSettings,
    m: &Motion,
    n: usize,
    warmup: usize,
) -> anyhow::Result<Vec<PassTimings>> {
    r.set_settings(s.clone())?;
    r.set_frame_mode(FrameMode::Timed);
    for _ in 0..warmup {
        m.render(r, 0);
        r.wait_idle();
    }
    let _ = r.wait_new_timings();
    r.reset_temporal();
    let mut out = Vec::new();
    for i in 0..n.min(m.len()) {
        m.render(r, i);
        r.wait_idle();
        if let Some(t) = r.wait_new_timings() {
            out.push(t);
        }
    }
    r.set_frame_mode(FrameMode::Diagnostic);
    Ok(out)
}

/// The GPU time of the temporal stage's passes in one frame (ms).
pub fn temporal_ms(t: &PassTimings) -> f64 {
    t.passes
        .iter()
        .filter(|(n, _)| n.starts_with("temporal_"))
        .map(|(_, ms)| ms)
        .sum()
}
