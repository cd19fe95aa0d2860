//! The research harness: thesis chapter 7's evaluation regenerated headlessly, one function per
//! figure ([`figures`]), each writing CSV + PNG plots ([`plot`]) + images into a results folder
//! and returning a short table and the ratio checks of issue 7.
//!
//! [`Bench`] owns a renderer on one scene and measures configurations: `frames` independent
//! frames each (new random numbers per frame, nothing accumulated: a real-time frame's error),
//! with per-pass GPU timestamps, the wall-clock time of each frame (render, submit, wait until
//! the GPU is idle) and the RMSE / SSIM of each frame's GI against the ground truth of the same
//! VPLs (every VPL at every pixel with a shadow ray, thesis chapter 7). The VPLs do not animate,
//! so every frame regenerates the same VPLs and tree; a checksum of the VPLs taken with the
//! ground truth is compared after every configuration, so a mismatch cannot go unnoticed.

mod csv;
pub mod figures;
pub mod plot;
pub mod sequence;

pub use csv::{Csv, csv_line, num};

use crate::methods::tree_samplers::settings::SamplingSettings;
use std::{
    collections::HashMap,
    path::Path,
    time::{Duration, Instant},
};

use anyhow::{Context, anyhow, bail};

use crate::{
    base::display,
    base::traversal::TraversalStats,
    metrics,
    renderer::{
        Buffer, FrameInput, FrameMode, Renderer,
        readback::ImageF32,
        settings::{RenderSettings, ViewBuffer},
    },
    scene::{Camera, DirectionalLight},
};

/// The light tree's build passes, either tree (the perfect tree's `sst_build`, the radix
/// tree's `lbvh_build` + `lbvh_nodes`), and the usable flags: shared frame work.
pub const TREE_BUILD_PASSES: [&str; 4] = ["sst_build", "lbvh_build", "lbvh_nodes", "sst_classify"];
/// The light paths of `vpl.bounces > 1` (starts, then the paths' VPLs).
pub const LIGHT_PATH_PASSES: [&str; 2] = ["light_path_starts", "light_paths"];
/// The keys and the sort before either build.
pub const SORT_PASSES: [&str; 2] = ["sst_keys", "sst_sort"];

/// GPU passes grouped as the columns of thesis table 7.1.
pub const PASS_GROUPS: [(&str, &[&str]); 8] = [
    ("G-buffer", &["gbuffer_depth", "gbuffer"]),
    ("shadow map", &["rsm"]),
    (
        "VPL generation",
        &[
            "brsm_importance",
            "brsm_filter",
            "pdf_pyramid",
            "vpl_warp",
            "light_path_starts",
            "light_paths",
        ],
    ),
    ("sort VPLs", &SORT_PASSES),
    ("build SST", &TREE_BUILD_PASSES),
    ("light cuts", &["slc_cuts"]),
    (
        "GI",
        &[
            "slc_sample",
            "sst_sample",
            "rtslc_sample",
            "gi_downsample",
            "gi_upsample",
        ],
    ),
    ("direct light", &["direct"]),
];

/// The GI passes of every per-frame method (`MethodInfo::timed_passes`: cuts, sampling,
/// half-resolution down- and upsampling), each once. A frame runs one method, so their sum
/// is that method's GI cost.
pub fn gi_passes() -> Vec<&'static str> {
    let mut v: Vec<&'static str> = Vec::new();
    for m in crate::methods::REGISTRY
        .iter()
        .filter(|m| m.kind == crate::methods::Kind::PerFrame)
    {
        for p in m.timed_passes {
            if !v.contains(p) {
                v.push(p);
            }
        }
    }
    v
}

/// The tree samplers' sampling passes alone (traversal, evaluation, shadow rays).
pub const SAMPLE_PASSES: [&str; 3] = ["slc_sample", "sst_sample", "rtslc_sample"];

/// The median (NaN when empty; the mean of the middle two for an even count).
pub fn median(v: &[f64]) -> f64 {
    let mut s: Vec<f64> = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}

/// Mean and sample standard deviation.
pub fn mean_std(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = if v.len() > 1 {
        v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (m, var.sqrt())
}

/// What one configuration measured over its frames.
#[derive(Clone, Debug, Default)]
pub struct Measured {
    /// Wall-clock ms per timed frame (render + submit + wait).
    pub frame_ms: Vec<f64>,
    /// GPU timestamps per pass, one entry per timed frame.
    pub passes: Vec<Vec<(String, f64)>>,
    /// The frame mode the timed frames ran in (`FrameMode`'s name).
    pub frame_kind: String,
    /// Per diagnostic frame: GI against the ground truth (tree samplers with a ground truth).
    pub rmse: Vec<f64>,
    pub ssim: Vec<f64>,
    /// Per diagnostic frame: the image-mean ratio mean(GI) / mean(ground truth)
    /// (`metrics::Metrics::mean_ratio`, the bias indicator beside the RMSE; see
    /// [`Measured::mean_ratio`]).
    pub mean_ratio: Vec<f64>,
    /// The frames' error split into bias and noise (`metrics::bias_noise`: RMSEs of the
    /// frames' mean and of a frame around it); NaN without a ground truth or with one frame.
    pub bias_rmse: f64,
    pub noise_rmse: f64,
    /// Per frame: RMSE over the pixels without a similar cut only (NaN when there are none).
    pub rmse_fallback: Vec<f64>,
    /// Sampler statistics summed over the diagnostic frames.
    pub stats: Option<TraversalStats>,
    /// The last diagnostic frame's GI.
    pub indirect: Option<ImageF32>,
    /// A diagnostic frame's traversal steps per traversal, per GI pixel (NaN without
    /// geometry).
    pub steps: Option<(u32, u32, Vec<f32>)>,
    /// The pixels without a similar cut.
    pub fallback: Option<Vec<bool>>,
    /// The method's own statistics (`Method::stats`: Lightcuts' cut sizes, ...), mean over
    /// the diagnostic frames.
    pub method_stats: Vec<(&'static str, f64)>,
}

impl Measured {
    pub fn frame_ms(&self) -> (f64, f64) {
        mean_std(&self.frame_ms)
    }
    /// GPU time of the method's whole GI cost (cuts, sampling, half-resolution down- and
    /// upsampling: [`gi_passes`]) over the timed frames (median, standard deviation): what
    /// equal time is decided on.
    pub fn gi_ms(&self) -> (f64, f64) {
        self.pass_ms(&gi_passes())
    }
    /// Every timestamped pass of the timed frames, in order, joined by '+' ("varies" when
    /// the frames timed different passes).
    pub fn timed_frame_passes(&self) -> String {
        let names = |f: &Vec<(String, f64)>| f.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>().join("+");
        match self.passes.first() {
            Some(first) if self.passes.iter().all(|f| names(f) == names(first)) => names(first),
            Some(_) => "varies".into(),
            None => String::new(),
        }
    }
    /// The passes of `names` that the timed frames timed (what a sum over `names` adds).
    pub fn timed_of(&self, names: &[&str]) -> String {
        let mut seen: Vec<&str> = Vec::new();
        for f in &self.passes {
            for (n, _) in f {
                if names.contains(&n.as_str()) && !seen.contains(&n.as_str()) {
                    seen.push(n);
                }
            }
        }
        seen.join("+")
    }
    /// GPU time of a group of passes in each timed frame (`None`: every pass).
    pub fn pass_ms_per_frame(&self, names: Option<&[&str]>) -> Vec<f64> {
        self.passes
            .iter()
            .map(|f| {
                f.iter()
                    .filter(|(n, _)| names.is_none_or(|names| names.contains(&n.as_str())))
                    .map(|(_, t)| t)
                    .sum()
            })
            .collect()
    }
    /// The fastest timed frame's GPU time of a group of passes (stable on an adapter whose
    /// speed switches between states, as a shared CPU's does).
    pub fn pass_ms_min(&self, names: &[&str]) -> f64 {
        self.pass_ms_per_frame(Some(names))
            .into_iter()
            .fold(f64::NAN, f64::min)
    }
    /// GPU time of a group of passes over the timed frames: the median (robust to the odd
    /// interrupted frame) and the standard deviation.
    pub fn pass_ms(&self, names: &[&str]) -> (f64, f64) {
        let v = self.pass_ms_per_frame(Some(names));
        (median(&v), mean_std(&v).1)
    }
    pub fn rmse(&self) -> (f64, f64) {
        mean_std(&self.rmse)
    }
    pub fn ssim(&self) -> (f64, f64) {
        mean_std(&self.ssim)
    }
    /// The image-mean ratio against the ground truth: the mean and sample standard deviation
    /// over the diagnostic frames, averaged as [`Measured::rmse`] is. Every frame is compared
    /// with the same ground truth and the ratio is linear in the image, so this mean equals
    /// the ratio of the frames' mean image (the image `bias_rmse` is measured on) up to
    /// rounding: the bias split's mean image and this column tell the same bias.
    pub fn mean_ratio(&self) -> (f64, f64) {
        mean_std(&self.mean_ratio)
    }
    pub fn steps_per_traversal(&self) -> f64 {
        self.stats.map_or(f64::NAN, |s| s.steps_per_traversal())
    }
    pub fn steps_per_pixel(&self) -> f64 {
        self.stats.map_or(f64::NAN, |s| s.steps_per_pixel())
    }
    pub fn fallback_fraction(&self) -> f64 {
        self.stats.map_or(f64::NAN, |s| s.fallback_fraction())
    }
}

/// A renderer on one scene and camera, with the base settings of every figure and a cache of
/// ground truths (per VPL count and resolution).
pub struct Bench {
    pub r: Renderer,
    pub camera: Camera,
    pub lights: Vec<DirectionalLight>,
    /// The scene's bookmarks (the temporal figure's camera path) and bounding radius.
    pub bookmarks: Vec<Camera>,
    pub scene_radius: f32,
    pub base: RenderSettings,
    /// Scene label (file stem), for file names and tables.
    pub scene: String,
    /// Exposure (EV) of the GI-only images and of SSIM / FLIP (the GI is much darker than the
    /// final image).
    pub gi_exposure: f32,
    pub adapter: String,
    /// Ground truths by (VPL count, seed, width | height << 16, shadow rays).
    /// Ground truths by ((VPL count, seed, size, shadow rays), (bounces, roulette, path
    /// start flux mix)).
    #[allow(clippy::type_complexity)]
    gt: HashMap<((u32, u32, u32, bool), (u32, bool, u32)), (ImageF32, u64)>,
    /// Progress lines to stderr.
    pub verbose: bool,
    /// Wall clock spent rendering and waiting for the GPU (the rest of a figure's wall time
    /// is CPU work: readbacks, metrics, plots, PNGs).
    pub gpu_wall: Duration,
    /// The figure being measured (set by `results` before each; names [`BaseTiming`]s).
    pub figure: String,
    /// Every measurement of SLC at the base settings, by figure: what each figure timed of
    /// the same configuration (`results` compares them: `timing_agreement.csv`).
    pub base_timings: Vec<BaseTiming>,
}

/// One timed measurement of SLC at the base settings ([`Bench::base_timings`]): the sampling
/// pass's time and what was timed, to compare across figures without asserting a time.
#[derive(Clone, Debug, PartialEq)]
pub struct BaseTiming {
    pub figure: String,
    pub size: (u32, u32),
    /// The sampling pass's GPU time: fastest timed frame and median, ms.
    pub sample_ms_min: f64,
    pub sample_ms_median: f64,
    /// The passes summed into it (those of [`SAMPLE_PASSES`] the frames timed).
    pub timed_passes: String,
    /// Every timestamped pass of the timed frames, in order ("varies" if they differ).
    pub frame_passes: String,
    /// The frame mode of the timed frames (`FrameMode`'s name).
    pub frame_kind: String,
    pub timed_frames: usize,
}

/// Frames of one configuration's measurement ([`Bench::measure`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frames {
    /// Timed frames (GPU timestamps; at least 1).
    pub timed: u32,
    /// Diagnostic frames (errors against the ground truth, sampler statistics; 0: none).
    pub diagnostic: u32,
}

/// Untimed frames before a configuration's timed frames (see `Bench::warm_up`).
pub const WARMUP_FRAMES: u32 = 2;
/// ... and at least this much wall clock of back-to-back frames.
pub const WARMUP_MS: f64 = 150.0;

impl Bench {
    pub fn new(
        r: Renderer,
        camera: Camera,
        lights: Vec<DirectionalLight>,
        mut base: RenderSettings,
        scene: String,
        adapter: String,
    ) -> Self {
        // Same VPLs every frame (the ground truth must match them); a new sampler seed per
        // frame (independent frames).
        base.vpl.animate = false;
        base.frame.accumulate = false;
        base.frame.fixed_seed = false;
        let gi_exposure = base.display.exposure_ev + 3.0;
        Self {
            r,
            camera,
            lights,
            bookmarks: Vec::new(),
            scene_radius: 1.0,
            base,
            scene,
            gi_exposure,
            adapter,
            gt: HashMap::new(),
            verbose: true,
            gpu_wall: Duration::ZERO,
            figure: String::new(),
            base_timings: Vec::new(),
        }
    }

    fn say(&self, s: &str) {
        if self.verbose {
            eprintln!("[{}] {s}", self.scene);
        }
    }

    fn frame(&mut self) {
        let lights = self.lights.clone();
        self.r.render(&FrameInput {
            camera: &self.camera,
            lights: &lights,
            view: ViewBuffer::Final,
        });
    }

    fn apply(&mut self, s: &RenderSettings, size: (u32, u32)) -> anyhow::Result<()> {
        s.validate().map_err(|e| anyhow!("{e}"))?;
        if self.r.size() != size {
            self.r.resize(size.0, size.1)?;
        }
        self.r.set_settings(s.clone())?;
        // Every configuration starts at frame 0: its numbers do not depend on what ran
        // before it (a sharded sweep gives an unsharded one's numbers, `results --shard`).
        self.r.restart_frame_index();
        Ok(())
    }

    /// A checksum of the current VPLs (positions, normals, flux).
    fn vpl_hash(&self) -> anyhow::Result<u64> {
        let v = self.r.read_vpls()?;
        let bytes: &[u8] = bytemuck::cast_slice(&v);
        // FNV-1a.
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        for b in bytes {
            h ^= *b as u64;
            h = h.wrapping_mul(0x100_0000_01b3);
        }
        Ok(h)
    }

    /// The ground truth's GI for settings `s` at `size` (cached per VPL count, seed, size and
    /// visibility: without shadow rays, the unshadowed truth).
    pub fn ground_truth(&mut self, s: &RenderSettings, size: (u32, u32)) -> anyhow::Result<ImageF32> {
        Ok(self.ground_truth_and_hash(s, size)?.0)
    }

    /// The ground truth and the checksum of the VPLs it evaluated.
    fn ground_truth_and_hash(
        &mut self,
        s: &RenderSettings,
        size: (u32, u32),
    ) -> anyhow::Result<(ImageF32, u64)> {
        let v = &s.vpl;
        let key = (
            (v.count, v.seed, size.0 | size.1 << 16, s.gi.shadow_rays),
            (v.bounces, v.roulette, v.path_flux_mix.to_bits()),
        );
        if let Some(cached) = self.gt.get(&key) {
            return Ok(cached.clone());
        }
        let mut g = s.clone();
        g.gi.method = crate::methods::comparison_truth();
        g.gi.rays_per_frame = 1 << 26;
        self.apply(&g, size)?;
        self.say(&format!(
            "ground truth: {} VPLs at every pixel of {}x{}",
            g.vpl.count, size.0, size.1
        ));
        let t = Instant::now();
        let mut frames = 0;
        loop {
            let tf = Instant::now();
            self.frame();
            self.gpu_wall += tf.elapsed();
            frames += 1;
            let p = self.r.gi_progress().unwrap_or_default();
            if p.finished() && frames > 1 {
                break;
            }
            if frames > 100_000 {
                bail!("the ground truth did not finish");
            }
        }
        let tw = Instant::now();
        self.r.wait_idle();
        self.gpu_wall += tw.elapsed();
        let img = self.r.read(Buffer::Indirect)?;
        let hash = self.vpl_hash()?;
        self.say(&format!(
            "ground truth done in {:.1} s",
            t.elapsed().as_secs_f64()
        ));
        self.gt.insert(key, (img.clone(), hash));
        Ok((img, hash))
    }

    /// Renders and submits one frame and waits for the GPU; the wait counts as GPU time.
    fn frame_wait(&mut self) {
        let t = Instant::now();
        self.frame();
        self.r.wait_idle();
        self.gpu_wall += t.elapsed();
    }

    /// Back-to-back untimed frames before the timed ones: at least [`WARMUP_FRAMES`] (the
    /// first after a settings change builds pipelines and buffers) and at least
    /// [`WARMUP_MS`] of wall clock, so that a GPU that idled during the CPU work before
    /// (ground truth readback, metrics, PNGs) is back at its working clocks.
    fn warm_up(&mut self) {
        let t = Instant::now();
        let mut n = 0;
        while n < WARMUP_FRAMES || (t.elapsed().as_secs_f64() * 1e3 < WARMUP_MS && n < 64) {
            self.frame_wait();
            n += 1;
        }
        let _ = self.r.wait_new_timings();
    }

    /// Measures settings `s` at `size` in two phases:
    ///
    /// 1. **Timed**: after a warm-up, `frames.timed` frames back to back in
    ///    `FrameMode::Timed`: the method's passes without diagnostics, nothing read back but
    ///    the timestamps, no CPU work between frames. Their GPU timestamps and wall clock are
    ///    the measurement.
    /// 2. **Diagnostic** (untimed): `frames.diagnostic` independent frames that record the
    ///    samplers' counters and per-pixel diagnostics; each one's GI is read back and, with
    ///    `with_gt`, compared with the ground truth of the same VPLs (RMSE, SSIM, mean ratio;
    ///    FLIP only where a figure asks for it, [`Bench::flip`]).
    pub fn measure(
        &mut self,
        s: &RenderSettings,
        size: (u32, u32),
        frames: Frames,
        with_gt: bool,
    ) -> anyhow::Result<Measured> {
        let tree = s.gi.method.per_frame();
        let gt = if with_gt && tree {
            Some(self.ground_truth_and_hash(s, size)?)
        } else {
            None
        };
        self.apply(s, size)?;
        let mut m = Measured {
            bias_rmse: f64::NAN,
            noise_rmse: f64::NAN,
            ..Default::default()
        };
        // 1. Timed frames.
        self.r.set_frame_mode(FrameMode::Timed);
        self.warm_up();
        for _ in 0..frames.timed.max(1) {
            let t0 = Instant::now();
            self.frame_wait();
            m.frame_ms.push(t0.elapsed().as_secs_f64() * 1e3);
            if let Some(t) = self.r.wait_new_timings() {
                m.passes.push(t.passes);
            }
        }
        m.frame_kind = format!("{:?}", self.r.frame_mode());
        let mut base_slc = self.base.clone();
        base_slc.gi.method = crate::methods::tree_samplers::SLC;
        if crate::methods::same_settings(s, &base_slc) && !m.passes.is_empty() {
            self.base_timings.push(BaseTiming {
                figure: self.figure.clone(),
                size,
                sample_ms_min: m.pass_ms_min(&SAMPLE_PASSES),
                sample_ms_median: m.pass_ms(&SAMPLE_PASSES).0,
                timed_passes: m.timed_of(&SAMPLE_PASSES),
                frame_passes: m.timed_frame_passes(),
                frame_kind: m.frame_kind.clone(),
                timed_frames: m.passes.len(),
            });
        }
        // 2. Diagnostic frames (untimed). They start at frame 0 again: the warm-up runs for a
        // time, not a frame count, and the errors must not depend on how fast it went.
        self.r.set_frame_mode(FrameMode::Diagnostic);
        self.r.restart_frame_index();
        if !tree {
            return Ok(m);
        }
        // Sum of the frames' GI (for the bias / noise split).
        let mut sum: Option<ImageF32> = None;
        // Pixels without a similar cut: a property of the G-buffer and the cuts, the same
        // in every frame (read from the first).
        let mut fallback_mask: Option<Vec<bool>> = None;
        let samples_tree = s.gi.method.samples_tree();
        for _ in 0..frames.diagnostic {
            self.frame_wait();
            if samples_tree && let Some(st) = self.r.sampling_stats_blocking() {
                m.stats = Some(m.stats.map_or(st, |a| a + st));
            }
            let k = frames.diagnostic.max(1) as f64;
            for (name, v) in self.r.method_stats_blocking() {
                match m.method_stats.iter_mut().find(|(n, _)| *n == name) {
                    Some((_, sum)) => *sum += v / k,
                    None => m.method_stats.push((name, v / k)),
                }
            }
            let ind = self.r.read(Buffer::Indirect)?;
            // Steps and fallback flags are per GI pixel: read at full GI resolution only.
            if samples_tree && m.steps.is_none() && !SamplingSettings::of(s).half_resolution {
                let (w, h, steps, fb) = self.read_steps()?;
                m.steps = Some((w, h, steps));
                fallback_mask = Some(fb.clone());
                m.fallback = Some(fb);
            }
            if let Some((gt, _)) = &gt {
                let c = metrics::compare_without_flip(&ind, gt, self.gi_exposure, self.base.display.tonemap);
                m.rmse.push(c.rmse);
                m.ssim.push(c.ssim);
                m.mean_ratio.push(c.mean_ratio);
                let acc = sum.get_or_insert_with(|| ImageF32 {
                    pixels: vec![[0.0; 4]; ind.pixels.len()],
                    ..ind.clone()
                });
                for (a, p) in acc.pixels.iter_mut().zip(&ind.pixels) {
                    for c in 0..3 {
                        a[c] += p[c];
                    }
                }
                if let Some(fb) = &fallback_mask {
                    m.rmse_fallback.push(if fb.iter().any(|f| *f) {
                        metrics::rmse(&ind, gt, Some(fb))
                    } else {
                        f64::NAN
                    });
                }
            }
            m.indirect = Some(ind);
        }
        if let (Some((gt, _)), Some(mut mean)) = (&gt, sum) {
            let k = m.rmse.len() as f32;
            mean.pixels
                .iter_mut()
                .for_each(|p| p[..3].iter_mut().for_each(|c| *c /= k));
            let mses: Vec<f64> = m.rmse.iter().map(|r| r * r).collect();
            (m.bias_rmse, m.noise_rmse) = metrics::bias_noise(&mses, metrics::rmse(&mean, gt, None).powi(2));
        }
        if let Some((_, hash)) = gt
            && self.vpl_hash()? != hash
        {
            bail!(
                "the VPLs changed between the ground truth and the measurement (non-deterministic VPL generation?)"
            );
        }
        Ok(m)
    }

    /// Mean FLIP of `img` against `gt` as displayed at the GI exposure (costly: only for the
    /// images a figure writes).
    pub fn flip(&self, img: &ImageF32, gt: &ImageF32) -> f64 {
        metrics::flip(img, gt, self.gi_exposure, self.base.display.tonemap)
    }

    /// Traversal steps per traversal of the last frame, per pixel (NaN where no geometry), and
    /// the pixels without a similar cut.
    fn read_steps(&self) -> anyhow::Result<(u32, u32, Vec<f32>, Vec<bool>)> {
        let (w, h) = self.r.size();
        let Some(crate::base::traversal::TraversalPixels { steps, fallback }) =
            self.r.read_traversal_pixels()?
        else {
            bail!(
                "{} keeps no per-pixel traversal counts",
                self.r.settings().gi.method.name()
            );
        };
        let pos = self.r.read(Buffer::Position)?;
        let n = (w * h) as usize;
        if steps.len() < n || fallback.len() < n || pos.pixels.len() < n {
            bail!("diagnostics buffer smaller than the frame");
        }
        let v = (0..n)
            .map(|i| {
                if pos.pixels[i][3] > 0.0 {
                    steps[i]
                } else {
                    f32::NAN
                }
            })
            .collect();
        let fb = (0..n).map(|i| pos.pixels[i][3] > 0.0 && fallback[i]).collect();
        Ok((w, h, v, fb))
    }

    /// Writes the GI as an sRGB PNG at the GI exposure.
    pub fn write_gi_png(&self, path: &Path, img: &ImageF32) -> anyhow::Result<()> {
        let tm = self.base.display.tonemap;
        let rgba: Vec<u8> = img
            .pixels
            .iter()
            .flat_map(|p| display::encode(*p, self.gi_exposure, tm))
            .collect();
        crate::export::write_png(path, img.width, img.height, &rgba)
            .with_context(|| format!("cannot write {}", path.display()))
    }

    /// Writes the relative error |a - b| / b of the GI (log false colour, as the sheets).
    pub fn write_error_png(&self, path: &Path, img: &ImageF32, gt: &ImageF32) -> anyhow::Result<()> {
        let rgba: Vec<u8> = img
            .pixels
            .iter()
            .zip(&gt.pixels)
            .flat_map(|(a, b)| {
                let c = crate::sheet::relative_error_rgb8(*a, *b);
                [c[0], c[1], c[2], 255]
            })
            .collect();
        crate::export::write_png(path, img.width, img.height, &rgba)
            .with_context(|| format!("cannot write {}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`Measured::mean_ratio`]'s claim: against one ground truth, the mean of the frames'
    /// ratios is the ratio of the frames' mean image.
    #[test]
    fn the_frames_mean_ratio_is_their_mean_images_ratio() {
        let img = |f: &dyn Fn(usize) -> f32| ImageF32 {
            width: 4,
            height: 2,
            pixels: (0..8)
                .map(|i| {
                    let v = f(i);
                    [v, 0.5 * v, 2.0 * v, 1.0]
                })
                .collect(),
        };
        let truth = img(&|i| 0.1 + 0.05 * i as f32);
        let frames: Vec<ImageF32> = (0..3)
            .map(|k| img(&|i| 0.08 + 0.03 * ((i * 7 + k * 5) % 4) as f32))
            .collect();
        let ratio =
            |a: &ImageF32| metrics::compare_without_flip(a, &truth, 0.0, display::Tonemap::Clamp).mean_ratio;
        let m = Measured {
            mean_ratio: frames.iter().map(ratio).collect(),
            ..Default::default()
        };
        let mut mean = img(&|_| 0.0);
        for f in &frames {
            for (a, p) in mean.pixels.iter_mut().zip(&f.pixels) {
                for c in 0..3 {
                    a[c] += p[c] / frames.len() as f32;
                }
            }
        }
        let (r, _) = m.mean_ratio();
        assert!((r - ratio(&mean)).abs() < 1e-6, "{r} vs {}", ratio(&mean));
        assert!((r - 1.0).abs() > 0.1, "a biased example: {r}");
    }
}
