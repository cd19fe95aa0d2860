//! One function per figure of thesis chapter 7. Each measures on a [`Bench`], writes
//! `<figure>.csv`, PNG plots and images into the scene's results folder, and returns a
//! [`Report`]: a short text table and the ratio checks of issue 7 it covers.

//!
//! Figures are registered, not listed: each submits a [`FigureDef`] with `inventory::submit!`
//! beside its function, so that a method's own figures live in its folder
//! (`src/methods/<m>/figure.rs`) and `results` finds them ([`all`], [`find`]) without a line
//! here. A figure's code imports [`prelude`].

mod bounces;
mod resolution;
mod temporal;
mod trees;

use crate::methods::tree_samplers::settings::SamplingSettings;
pub use bounces::bounces;
pub use resolution::{scaling, upsampling};
pub use temporal::temporal;
pub use trees::trees;

/// What a figure's code needs: the bench and its measurements, the options, the report and
/// its checks, the CSV and plot writers.
pub mod prelude {
    pub use super::super::{
        Bench, Csv, Frames, Measured, PASS_GROUPS, SAMPLE_PASSES, SORT_PASSES, TREE_BUILD_PASSES, gi_passes,
        mean_std, median, num, plot,
    };
    pub use super::{
        Check, FigureDef, Opts, Report, check, images, interp_loglog, methods, tree_methods, with,
    };
    pub use crate::methods::MethodId;
    pub use crate::settings::RenderSettings;
    pub use anyhow::Context;
    pub use std::path::Path;
}

/// A figure of `results`: its CLI name, the label its rows carry in `checks.csv`,
/// `run.json` and the printed table, its place in a run (figures run in ascending `order`),
/// its one-paragraph description (`results --help`) and the function that makes it.
pub struct FigureDef {
    pub cli: &'static str,
    pub label: &'static str,
    pub order: u32,
    pub doc: &'static str,
    pub make: fn(&mut Bench, &Opts, &Path) -> anyhow::Result<Report>,
}

impl std::fmt::Debug for FigureDef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label)
    }
}

inventory::collect!(FigureDef);

/// Every registered figure, in the order a run makes them.
pub fn all() -> Vec<&'static FigureDef> {
    let mut v: Vec<&'static FigureDef> = inventory::iter::<FigureDef>.into_iter().collect();
    v.sort_by_key(|f| (f.order, f.cli));
    v
}

/// The figure with CLI name `cli`.
pub fn find(cli: &str) -> Option<&'static FigureDef> {
    inventory::iter::<FigureDef>.into_iter().find(|f| f.cli == cli)
}

use std::path::Path;

use anyhow::Context;

use super::{
    Bench, Csv, Frames, PASS_GROUPS, SAMPLE_PASSES, SORT_PASSES, TREE_BUILD_PASSES, gi_passes, mean_std, num,
    plot,
};
use crate::methods::{
    self as gi_methods, MethodId,
    tree_samplers::{RTSLC, SLC, SST},
};
use crate::settings::RenderSettings;

/// What every figure needs besides the bench.
#[derive(Clone, Debug)]
pub struct Opts {
    /// Frame size of every figure but the scaling one.
    pub size: (u32, u32),
    /// Diagnostic frames per configuration (errors and statistics; their means).
    pub frames: u32,
    /// Timed frames per configuration (GPU times: their median), after a warm-up.
    pub timing_frames: u32,
    /// Samples per pixel (cut size) of the equal-time sweep.
    pub spp: Vec<u32>,
    /// Block sizes k of the block sweep.
    pub blocks: Vec<u32>,
    /// log2 of the VPL counts of the scaling sweep.
    pub vpl_exponents: Vec<u32>,
    /// Frame size of the scaling sweep (a ground truth per VPL count).
    pub scaling_size: (u32, u32),
    /// Frame sizes of the upsampling table, as multiples of `size`.
    pub upsampling_scales: Vec<f32>,
    /// The per-frame methods the sweeps compare (registry order; empty: every one).
    pub methods: Vec<MethodId>,
    /// A method's quality-knob values replacing its registry sweep (`results --sweep`).
    pub sweeps: Vec<(MethodId, Vec<f64>)>,
    /// The temporal figure: frames per motion, the camera path's length in frames (its
    /// first `temporal_frames` are measured), the sun sweep's degrees over the frames, and
    /// the frame size of its GPU timings.
    pub temporal_frames: u32,
    pub temporal_path_frames: u32,
    pub sun_sweep_deg: f32,
    pub temporal_timing_size: (u32, u32),
    /// The bounce counts of the bounce-count figure (1 included: its reference row).
    pub bounces: Vec<u32>,
}

impl Opts {
    /// The frames of one configuration: `timing_frames` timed, `frames` diagnostic.
    pub fn per_config(&self) -> Frames {
        Frames {
            timed: self.timing_frames.max(1),
            diagnostic: self.frames.max(1),
        }
    }

    /// The values of `method`'s quality knob in the equal-time sweep: `--sweep` for it, else
    /// its registry sweep (the tree samplers' `--spp` list with `base_spp` added).
    pub fn sweep_values(&self, method: MethodId, base_spp: u32) -> Vec<f64> {
        if let Some((_, v)) = self.sweeps.iter().find(|(m, _)| *m == method) {
            return v.clone();
        }
        match method.info().sweep {
            Some(sw) if !sw.values.is_empty() => sw.values.to_vec(),
            _ => {
                let mut spp = self.spp.clone();
                if !spp.contains(&base_spp) {
                    spp.push(base_spp);
                }
                spp.sort_unstable();
                spp.dedup();
                spp.into_iter().map(f64::from).collect()
            }
        }
    }
}

/// A ratio the issue asks for: `value` must be <= `limit` (or >= it with `at_least`).
#[derive(Clone, Debug)]
pub struct Check {
    pub scene: String,
    pub name: String,
    pub value: f64,
    pub limit: f64,
    pub at_least: bool,
    /// How the value was measured.
    pub detail: String,
}

impl Check {
    pub fn pass(&self) -> bool {
        if self.at_least {
            self.value >= self.limit
        } else {
            self.value <= self.limit
        }
    }
    pub fn line(&self) -> String {
        format!(
            "{:<16} {:<44} {:>8.3} {} {:<6} {}",
            self.scene,
            self.name,
            self.value,
            if self.at_least { ">=" } else { "<=" },
            self.limit,
            if self.pass() { "met" } else { "MISSED" }
        )
    }
}

/// What a figure prints and checks.
#[derive(Default)]
pub struct Report {
    pub table: String,
    pub checks: Vec<Check>,
}

/// The methods of every sweep, in the order (and colours) of every plot: the thesis's
/// comparison first, SLC, RTSLC, SST, then any other per-frame method of the registry; only
/// those of `o.methods` when it names some.
pub fn methods(o: &Opts) -> Vec<(MethodId, &'static str)> {
    let thesis = [SLC, RTSLC, SST];
    let mut v = thesis.to_vec();
    v.extend(
        gi_methods::per_frame()
            .into_iter()
            .filter(|m| !thesis.contains(m)),
    );
    v.into_iter()
        .filter(|m| o.methods.is_empty() || o.methods.contains(m))
        .map(|m| (m, m.info().short))
        .collect()
}

/// The tree samplers among [`methods`] (the traversal figures).
pub fn tree_methods(o: &Opts) -> Vec<(MethodId, &'static str)> {
    methods(o).into_iter().filter(|(m, _)| m.samples_tree()).collect()
}

/// The bench's base settings changed by `f`.
pub fn with(b: &Bench, f: impl FnOnce(&mut RenderSettings)) -> RenderSettings {
    let mut s = b.base.clone();
    f(&mut s);
    s
}

/// `<dir>/images`, created.
pub fn images(dir: &Path) -> anyhow::Result<std::path::PathBuf> {
    let d = dir.join("images");
    std::fs::create_dir_all(&d).with_context(|| format!("cannot create {}", d.display()))?;
    Ok(d)
}

/// A check on the bench's scene.
pub fn check(b: &Bench, name: &str, value: f64, limit: f64, at_least: bool, detail: String) -> Check {
    Check {
        scene: b.scene.clone(),
        name: name.into(),
        value,
        limit,
        at_least,
        detail,
    }
}

inventory::submit! {
    FigureDef {
        cli: "timings",
        label: "Timings",
        order: 10,
        doc: "Table 7.1: GPU time per pass (median, mean and spread over many timed frames).",
        make: timings,
    }
}

/// Thesis table 7.1: GPU time per pass group, median, mean and spread over the timed frames
/// of SLC at the base settings, plus the wall-clock frame time.
pub fn timings(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let s = with(b, |s| s.gi.method = SLC);
    let m = b.measure(
        &s,
        o.size,
        Frames {
            timed: o.timing_frames.max(1),
            diagnostic: 0,
        },
        false,
    )?;
    let mut csv = Csv::new(&[
        "scene",
        "group",
        "passes",
        "median_ms",
        "mean_ms",
        "std_ms",
        "min_ms",
        "max_ms",
        "frames",
    ]);
    let mut bars = Vec::new();
    let mut table = format!(
        "per-pass GPU time, {} frames of SLC at {}x{} ({}):\n",
        m.passes.len(),
        o.size.0,
        o.size.1,
        b.adapter
    );
    let mut rows: Vec<(String, String, Vec<f64>)> = PASS_GROUPS
        .iter()
        .map(|(g, names)| (g.to_string(), names.join("+"), m.pass_ms_per_frame(Some(names))))
        .collect();
    rows.push(("all passes (GPU)".into(), "sum".into(), m.pass_ms_per_frame(None)));
    rows.push((
        "frame (wall clock)".into(),
        "render+submit+wait".into(),
        m.frame_ms.clone(),
    ));
    for (i, (g, passes, v)) in rows.iter().enumerate() {
        let (mean, std) = mean_std(v);
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        csv.row(vec![
            b.scene.clone(),
            g.clone(),
            passes.clone(),
            num(super::median(v)),
            num(mean),
            num(std),
            num(min),
            num(max),
            v.len().to_string(),
        ]);
        table.push_str(&format!(
            "  {g:<20} {:>10.3} ms (median; mean {mean:.3} ± {std:.3})\n",
            super::median(v)
        ));
        if i < PASS_GROUPS.len() {
            bars.push(plot::Bar {
                label: g.clone(),
                value: super::median(v),
                spread: std,
                color: 0,
            });
        }
    }
    csv.write(&dir.join("timings.csv"))?;
    // Every timed frame's groups, in order (drift and outliers over the run).
    let mut frames = Csv::new(&["scene", "frame", "group", "ms"]);
    for (g, names) in PASS_GROUPS.iter() {
        for (i, v) in m.pass_ms_per_frame(Some(names)).iter().enumerate() {
            frames.row(vec![b.scene.clone(), i.to_string(), g.to_string(), num(*v)]);
        }
    }
    for (i, v) in m.frame_ms.iter().enumerate() {
        frames.row(vec![
            b.scene.clone(),
            i.to_string(),
            "frame (wall clock)".into(),
            num(*v),
        ]);
    }
    frames.write(&dir.join("timings_frames.csv"))?;
    plot::bars(
        &dir.join("timings.png"),
        &format!("{}: GPU time per pass ({}x{})", b.scene, o.size.0, o.size.1),
        "ms (log)",
        &bars,
        true,
    )?;
    Ok(Report {
        table,
        checks: Vec::new(),
    })
}

/// Piecewise-linear interpolation of log(y) over log(x) through points sorted by x; outside
/// the range the nearest segment is extended. Returns (y, extrapolated).
pub fn interp_loglog(points: &[(f64, f64)], x: f64) -> (f64, bool) {
    let mut p: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(a, b)| *a > 0.0 && *b > 0.0 && a.is_finite() && b.is_finite())
        .map(|(a, b)| (a.ln(), b.ln()))
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    if p.is_empty() || x <= 0.0 {
        return (f64::NAN, true);
    }
    if p.len() == 1 {
        return (p[0].1.exp(), (p[0].0 - x.ln()).abs() > 1e-9);
    }
    let lx = x.ln();
    let outside = lx < p[0].0 || lx > p[p.len() - 1].0;
    let i = p
        .iter()
        .position(|q| q.0 >= lx)
        .unwrap_or(p.len() - 1)
        .clamp(1, p.len() - 1);
    let (a, c) = (p[i - 1], p[i]);
    let t = if (c.0 - a.0).abs() < 1e-12 {
        0.0
    } else {
        (lx - a.0) / (c.0 - a.0)
    };
    ((a.1 + t * (c.1 - a.1)).exp(), outside)
}

/// One point of the equal-time sweep: GI GPU ms, RMSE, SSIM, the knob's value.
type SweepPoint = (f64, f64, f64, f64);

/// A knob value as the CSV writes it.
fn knob(v: f64, integer: bool) -> String {
    if integer {
        format!("{}", v.round() as i64)
    } else {
        format!("{v}")
    }
}

inventory::submit! {
    FigureDef {
        cli: "equal-time",
        label: "EqualTime",
        order: 30,
        doc: "Fig. 7.1 / 7.3: RMSE and SSIM over GI GPU time for every per-frame method (SLC, RTSLC, SST over spp; Lightcuts over its relative error); equal-time table.",
        make: equal_time,
    }
}

/// Thesis fig. 7.1 and 7.3, for every per-frame method: each over a sweep of its quality
/// knob (samples per pixel for the tree samplers, the relative error for Lightcuts: the
/// registry's `Sweep`), RMSE and SSIM against the ground truth of the same VPLs over the GPU
/// time of the method's whole GI cost (its registry `timed_passes`, GPU timestamps of timed
/// frames); the equal-time table (each method's RMSE interpolated at SLC's GI time at the
/// base cut size), and the images, error maps and FLIP of each method at its knob's value
/// for that time. Frame wall clock stays a separate column.
pub fn equal_time(b: &mut Bench, o: &Opts, dir: &Path) -> anyhow::Result<Report> {
    let base_spp = SamplingSettings::of(&b.base).cut_size;
    let ms = methods(o);
    let curves = sweep_curves(b, o, &ms, base_spp, dir)?;
    plot_curves(b, dir, &ms, &curves)?;
    // The matched time: SLC's GI at the base cut size (else the first method's first point).
    let slc = ms.iter().position(|(m, _)| *m == SLC);
    let t_match = slc
        .and_then(|i| curves[i].iter().find(|p| p.3 == base_spp as f64))
        .or_else(|| curves.iter().flatten().next())
        .map_or(f64::NAN, |p| p.0);
    let mut table = format!(
        "equal time: {t_match:.2} ms of GI on the GPU per frame ({})\n",
        if slc.is_some() {
            format!("SLC at {base_spp} spp")
        } else {
            "the first method's first point".into()
        }
    );
    let mut at = Vec::new();
    let mut matched = Csv::new(&[
        "scene",
        "method",
        "matched_gi_gpu_ms",
        "rmse_interpolated",
        "ssim_interpolated",
        "extrapolated",
        "spp_at_matched_time",
        "setting",
        "value_at_matched_time",
        "measured_gi_gpu_ms",
        "measured_frame_wall_ms",
        "measured_rmse",
        "measured_ssim",
        "measured_flip",
        "measured_mean_ratio",
        "measured_bias_rmse",
    ]);
    let gt = b.ground_truth(&b.base.clone(), o.size)?;
    let img = images(dir)?;
    b.write_gi_png(&img.join("ground_truth.png"), &gt)?;
    for (i, (method, label)) in ms.iter().enumerate() {
        let Some(sweep) = method.info().sweep else {
            at.push((*method, f64::NAN));
            continue;
        };
        let rt: Vec<(f64, f64)> = curves[i].iter().map(|p| (p.0, p.1)).collect();
        let qt: Vec<(f64, f64)> = curves[i].iter().map(|p| (p.0, p.2)).collect();
        let st: Vec<(f64, f64)> = curves[i].iter().map(|p| (p.0, p.3)).collect();
        let (r, ex) = interp_loglog(&rt, t_match);
        let (q, _) = interp_loglog(&qt, t_match);
        let (v, _) = interp_loglog(&st, t_match);
        let v = knob_at(sweep, &st, v, base_spp);
        let s = with(b, |s| {
            s.gi.method = *method;
            (sweep.apply)(s, v);
        });
        let m = b.measure(&s, o.size, o.per_config(), true)?;
        let flip = m.indirect.as_ref().map_or(f64::NAN, |ind| b.flip(ind, &gt));
        if let Some(ind) = &m.indirect {
            b.write_gi_png(&img.join(format!("equal_time_{}.png", label.to_lowercase())), ind)?;
            b.write_error_png(
                &img.join(format!("equal_time_{}_error.png", label.to_lowercase())),
                ind,
                &gt,
            )?;
        }
        let value = knob(v, sweep.integer);
        matched.row(vec![
            b.scene.clone(),
            label.to_string(),
            num(t_match),
            num(r),
            num(q),
            ex.to_string(),
            if sweep.name == "spp" {
                value.clone()
            } else {
                String::new()
            },
            sweep.name.to_string(),
            value.clone(),
            num(m.gi_ms().0),
            num(m.frame_ms().0),
            num(m.rmse().0),
            num(m.ssim().0),
            num(flip),
            num(m.mean_ratio().0),
            num(m.bias_rmse),
        ]);
        table.push_str(&format!(
            "  {label:<9} RMSE {r:.4e}{} SSIM {q:.3} · {} {value} at that time (measured: GI {:.2} ms GPU, RMSE {:.4e}, of it bias {:.2e}, mean {:.3}x GT, FLIP {flip:.4})\n",
            if ex { " (extrapolated)" } else { "" },
            sweep.name,
            m.gi_ms().0,
            m.rmse().0,
            m.bias_rmse,
            m.mean_ratio().0
        ));
        at.push((*method, r));
    }
    matched.write(&dir.join("equal_time_matched.csv"))?;
    let detail = format!("RMSE interpolated (log-log) at SLC's GI GPU time with {base_spp} spp");
    let rmse_of = |id: MethodId| at.iter().find(|(m, _)| *m == id).map(|(_, r)| *r);
    let mut checks = Vec::new();
    if let (Some(slc), Some(rtslc), Some(sst)) = (rmse_of(SLC), rmse_of(RTSLC), rmse_of(SST)) {
        checks.push(check(
            b,
            "equal-time RMSE SLC / RTSLC",
            slc / rtslc,
            0.8,
            false,
            detail.clone(),
        ));
        checks.push(check(
            b,
            "equal-time RMSE SLC / SST",
            slc / sst,
            0.6,
            false,
            detail,
        ));
    }
    Ok(Report { table, checks })
}

/// Every method over its sweep (`equal_time.csv`): per method its (GI ms, RMSE, SSIM, knob)
/// points, empty for a method without a sweep.
fn sweep_curves(
    b: &mut Bench,
    o: &Opts,
    ms: &[(MethodId, &str)],
    base_spp: u32,
    dir: &Path,
) -> anyhow::Result<Vec<Vec<SweepPoint>>> {
    let mut csv = Csv::new(&[
        "scene",
        "method",
        "spp",
        "setting",
        "value",
        "gi_gpu_ms",
        "gi_gpu_ms_std",
        "sample_gpu_ms",
        "gi_gpu_ms_min",
        "sample_gpu_ms_min",
        "frame_wall_ms",
        "frame_wall_ms_std",
        "rmse",
        "rmse_std",
        "ssim",
        "ssim_std",
        "mean_ratio",
        "bias_rmse",
        "noise_rmse",
        "steps_per_traversal",
        "steps_per_pixel",
        "method_stats",
    ]);
    let mut curves: Vec<Vec<SweepPoint>> = Vec::new();
    for (method, label) in ms {
        let Some(sweep) = method.info().sweep else {
            curves.push(Vec::new());
            continue;
        };
        let mut pts = Vec::new();
        for v in o.sweep_values(*method, base_spp) {
            let s = with(b, |s| {
                s.gi.method = *method;
                (sweep.apply)(s, v);
            });
            let m = b.measure(&s, o.size, o.per_config(), true)?;
            let (t, ts) = m.gi_ms();
            let (wall, wall_s) = m.frame_ms();
            let (r, rs) = m.rmse();
            let (q, qs) = m.ssim();
            let value = knob(v, sweep.integer);
            let stats: Vec<String> = m
                .method_stats
                .iter()
                .map(|(k, x)| format!("{k}={x:.4}"))
                .collect();
            csv.row(vec![
                b.scene.clone(),
                label.to_string(),
                if sweep.name == "spp" {
                    value.clone()
                } else {
                    String::new()
                },
                sweep.name.to_string(),
                value.clone(),
                num(t),
                num(ts),
                num(m.pass_ms(&SAMPLE_PASSES).0),
                num(m.pass_ms_min(&gi_passes())),
                num(m.pass_ms_min(&SAMPLE_PASSES)),
                num(wall),
                num(wall_s),
                num(r),
                num(rs),
                num(q),
                num(qs),
                num(m.mean_ratio().0),
                num(m.bias_rmse),
                num(m.noise_rmse),
                num(m.steps_per_traversal()),
                num(m.steps_per_pixel()),
                stats.join(" "),
            ]);
            eprintln!(
                "[{}] {label} {} {value}: GI {t:.2} ms GPU (frame {wall:.1} ms wall), RMSE {r:.4e} (bias {:.2e}, noise {:.2e}, mean ratio {:.3}), SSIM {q:.3}",
                b.scene,
                sweep.name,
                m.bias_rmse,
                m.noise_rmse,
                m.mean_ratio().0
            );
            pts.push((t, r, q, v));
        }
        curves.push(pts);
    }
    csv.write(&dir.join("equal_time.csv"))?;
    Ok(curves)
}

/// RMSE and SSIM over GI GPU time, a curve per method.
fn plot_curves(
    b: &Bench,
    dir: &Path,
    ms: &[(MethodId, &str)],
    curves: &[Vec<SweepPoint>],
) -> anyhow::Result<()> {
    let series = |f: &dyn Fn(&SweepPoint) -> (f64, f64)| -> Vec<plot::Series> {
        ms.iter()
            .enumerate()
            .map(|(i, (_, l))| plot::Series {
                name: l.to_string(),
                color: i,
                points: curves[i].iter().map(f).collect(),
            })
            .collect()
    };
    let knobs: Vec<String> = ms
        .iter()
        .filter_map(|(m, l)| m.info().sweep.map(|sw| format!("{l}: {}", sw.name)))
        .collect();
    plot::lines(
        &dir.join("equal_time_rmse.png"),
        &format!("{}: RMSE vs GI GPU time (swept: {})", b.scene, knobs.join(", ")),
        "GI time (ms, GPU timestamps of each method's passes)",
        "RMSE of one frame's GI (W/(m² sr))",
        &series(&|p| (p.0, p.1)),
        true,
        true,
    )?;
    plot::lines(
        &dir.join("equal_time_ssim.png"),
        &format!("{}: SSIM vs GI GPU time", b.scene),
        "GI time (ms, GPU timestamps of each method's passes)",
        "SSIM of one frame's GI",
        &series(&|p| (p.0, p.2)),
        true,
        false,
    )?;
    Ok(())
}

/// The knob's value at the matched time `v` (interpolated over the sweep's (time, value)
/// points `st`), within the swept range (integers rounded); outside any measured time the
/// base spp, else the first value.
fn knob_at(sweep: &crate::methods::Sweep, st: &[(f64, f64)], v: f64, base_spp: u32) -> f64 {
    let (lo, hi) = st
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.1), hi.max(p.1)));
    if v.is_finite() && lo <= hi {
        let v = v.clamp(lo, hi);
        if sweep.integer { v.round() } else { v }
    } else if sweep.name == "spp" {
        base_spp as f64
    } else {
        st.first().map_or(f64::NAN, |p| p.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loglog_interpolation() {
        // y = x^-0.5 is a line in log-log.
        let p: Vec<(f64, f64)> = [1.0f64, 4.0, 16.0].iter().map(|x| (*x, x.powf(-0.5))).collect();
        let (y, ex) = interp_loglog(&p, 8.0);
        assert!((y - 8f64.powf(-0.5)).abs() < 1e-12 && !ex);
        let (y, ex) = interp_loglog(&p, 64.0);
        assert!((y - 64f64.powf(-0.5)).abs() < 1e-12 && ex);
        assert!(interp_loglog(&[], 1.0).0.is_nan());
    }

    /// Every figure once (CLI name, label and place unique), the thesis's own in its order
    /// with the methods' studies between them where they were when the list was written by
    /// hand.
    #[test]
    fn figures_are_registered_once_in_a_runs_order() {
        let figs = all();
        for key in [
            |f: &FigureDef| f.cli.to_string(),
            |f: &FigureDef| f.label.to_string(),
            |f: &FigureDef| f.order.to_string(),
        ] {
            let mut k: Vec<String> = figs.iter().map(|f| key(f)).collect();
            k.sort();
            let n = k.len();
            k.dedup();
            assert_eq!(k.len(), n, "a figure registered twice: {figs:?}");
        }
        let before = [
            "Timings",
            "Steps",
            "EqualTime",
            "Interpolation",
            "Culling",
            "Val",
            "Temporal",
            "Trees",
            "Bounces",
            "Blocks",
            "Blending",
            "Upsampling",
            "Scaling",
        ];
        let kept: Vec<&str> = figs
            .iter()
            .map(|f| f.label)
            .filter(|l| before.contains(l))
            .collect();
        assert_eq!(kept, before);
        for f in &figs {
            assert_eq!(find(f.cli).map(|g| g.label), Some(f.label));
            assert!(!f.doc.is_empty(), "{} has no description", f.cli);
        }
    }
}
