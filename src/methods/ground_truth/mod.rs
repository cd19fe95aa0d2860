//! The thesis's ground truth (chapter 7): every VPL of the frame at every pixel with a BVH
//! shadow ray, in VPL batches, accumulated over frames (progressive; restarts when anything
//! it depends on changes). It is also the comparison's truth: the renderer runs a second
//! instance beside a per-frame method, on the same VPLs, into its own buffers.

pub mod pass;
mod ui;

use super::{FrameCx, Kind, Method, MethodId, MethodInfo, Module, Resource};
use crate::base::field::Field;
use crate::base::progress::GiProgress;
use crate::gpu::gpu_data::GpuVpl;
use crate::gpu::shaders::ShaderError;
use crate::settings::GiSettings;
use crate::settings::RenderSettings;
use pass::GpuGtParams;
use pass::GroundTruthPass;

pub const ID: MethodId = MethodId::new("ground-truth");

/// Its WGSL files (paths under `shaders/`), embedded; the GPU layer finds them through
/// `gpu::shaders::ShaderTable` without naming the method.
const SHADERS: &[(&str, &str)] = &[(
    "methods/ground_truth/ground_truth.wgsl",
    include_str!("../../../shaders/methods/ground_truth/ground_truth.wgsl"),
)];

/// Those of its files that are entry points.
const ENTRY_SHADERS: &[&str] = &["methods/ground_truth/ground_truth.wgsl"];

inventory::submit! {
    crate::gpu::shaders::ShaderTable {
        files: SHADERS,
        entries: ENTRY_SHADERS,
    }
}

pub static MODULE: Module = Module {
    name: "ground_truth",
    create,
    shaders: SHADERS,
    entry_shaders: ENTRY_SHADERS,
    wgsl_twins: pass::WGSL_TWINS,
    own_workgroups: &[],
    flags: &[],
};

pub static INFO: MethodInfo = MethodInfo {
    id: ID,
    aliases: &["gt"],
    label: "ground truth (all VPLs)",
    short: "ground truth",
    about: "Thesis chapter 7: every VPL at every pixel with a shadow ray (progressive).",
    progress_unit: "VPLs",
    kind: Kind::Progressive,
    module: &MODULE,
    reads: &[Resource::Gbuffer, Resource::Vpls, Resource::Bvh],
    views: &[],
    timed_passes: &["ground_truth"],
    story: false,
    shadow_ray_switch: true,
    visibility: None,
    truth_of_vpls: true,
    one_bounce: false,
    glossy: true,
    validate,
    fields,
    invalid_example: Some(|s| {
        s.gi.rays_per_frame = 0;
        "gi.rays_per_frame"
    }),
    ui: ui::settings_ui,
    tests: &[
        "vpl::ground_truth_on_the_gpu_equals_a_cpu_evaluation_of_the_same_vpls",
        "slc::the_comparison_ground_truth_equals_the_ground_truth_method",
        "vpl::ground_truth_with_ggx_equals_a_cpu_evaluation_with_the_brdf",
    ],
    sweep: None,
    bias: |_| super::Bias::NotCompared,
    unbiased: None,
};

/// Its numeric setting (in `[gi]`), declared once (validation, the GUI's slider, `--set`).
pub static FIELDS: &[Field<GiSettings>] = &[crate::field!(
    GiSettings,
    rays_per_frame: u32,
    "shadow rays / frame",
    "",
    1,
    u32::MAX,
    Log,
    "the progressive truth's budget: more finishes sooner, but each frame takes longer"
)];

fn validate(s: &RenderSettings) -> Result<(), String> {
    crate::base::field::check("gi", FIELDS, &s.gi)
}

/// The stride of the order the truth sums the VPLs in (step i: VPL i x stride mod n): near
/// n / golden ratio (consecutive steps land far apart, as a rank-1 lattice), coprime with n
/// (a permutation), and small enough that (n - 1) x stride fits in 32 bits.
pub fn visit_stride(n: u32) -> u32 {
    fn gcd(a: u64, b: u64) -> u64 {
        if b == 0 { a } else { gcd(b, a % b) }
    }
    if n <= 2 {
        return 1;
    }
    let golden = (n as f64 / 1.618_033_988_75).round() as u64;
    let cap = (u32::MAX as u64 / n as u64).max(1);
    let mut p = golden.min(cap).max(1);
    while gcd(p, n as u64) != 1 {
        p -= 1;
    }
    p as u32
}

/// The composite's scale of a sum over the first `done` of `total` VPLs: total / done, so
/// that a view of the truth while it converges reads at its final brightness (an estimate
/// from the VPLs so far) instead of fading in from black; 1 when finished (issue 41).
pub fn partial_scale(p: GiProgress) -> f32 {
    if p.done == 0 || p.done >= p.total {
        1.0
    } else {
        p.total as f32 / p.done as f32
    }
}

/// State between frames: a snapshot of the VPLs it evaluates, and how far it got. Any change
/// of `FrameCx::key` restarts it.
struct GtState {
    key: u64,
    progress: GiProgress,
    snapshot: wgpu::Buffer,
}

pub struct GroundTruth {
    pass: GroundTruthPass,
    state: Option<GtState>,
}

fn create(device: &wgpu::Device) -> Result<Box<dyn Method>, ShaderError> {
    Ok(Box::new(GroundTruth {
        pass: GroundTruthPass::new(device)?,
        state: None,
    }))
}

impl Method for GroundTruth {
    /// Starts (when the key changed: snapshot of the frame's VPLs, accumulation cleared) or
    /// continues, adding at most `gi.rays_per_frame` shadow rays' worth of VPL batches.
    fn record(&mut self, cx: &mut FrameCx<'_>, enc: &mut wgpu::CommandEncoder) -> f32 {
        let total = cx.vpl_frame.count;
        if self.state.as_ref().is_none_or(|g| g.key != cx.key) {
            let bytes = (std::mem::size_of::<GpuVpl>() as u64) * cx.vpl_buffers.capacity as u64;
            let snapshot = match self.state.take() {
                Some(g) if g.snapshot.size() == bytes => g.snapshot,
                _ => cx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("ground_truth::vpl_snapshot"),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE
                        | wgpu::BufferUsages::COPY_DST
                        | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
            };
            enc.copy_buffer_to_buffer(&cx.vpl_buffers.vpls, 0, &snapshot, 0, bytes);
            enc.clear_buffer(cx.gi_accum, 0, None);
            self.state = Some(GtState {
                key: cx.key,
                progress: GiProgress { done: 0, total },
                snapshot,
            });
        }
        let Some(gt) = self.state.as_mut() else { return 1.0 };
        if gt.progress.finished() {
            return 1.0;
        }
        let g = &cx.settings.gi;
        let pixels = (cx.size.0 as u64 * cx.size.1 as u64).max(1);
        let budget_vpls = (g.rays_per_frame as u64 / pixels).max(1);
        let batch = budget_vpls.div_ceil(pass::MAX_BATCHES as u64).max(1) as u32;
        let end = (gt.progress.done as u64 + budget_vpls).min(gt.progress.total as u64) as u32;
        let base = GpuGtParams {
            begin: gt.progress.done,
            end,
            width: cx.size.0,
            height: cx.size.1,
            epsilon: g.distance_epsilon,
            ray_offset: g.ray_offset,
            shadow_rays: g.shadow_rays as u32,
            brdf: cx.brdf.gpu(),
            eye: cx.eye.extend(0.0).to_array(),
            order: [visit_stride(total), total, 0, 0],
        };
        gt.progress.done = self.pass.record(cx, enc, base, batch, &gt.snapshot);
        partial_scale(gt.progress)
    }

    fn progress(&self) -> Option<GiProgress> {
        self.state.as_ref().map(|g| g.progress)
    }

    fn reset(&mut self) {
        self.state = None;
    }
}

/// `MethodInfo::fields`.
fn fields() -> Vec<super::FieldSection> {
    vec![super::FieldSection::of("gi", FIELDS, false)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_visit_order_is_a_permutation_that_spreads_and_does_not_overflow() {
        for n in [
            1u32,
            2,
            3,
            7,
            100,
            1000,
            4096,
            4097,
            65_536,
            1 << 20,
            3 * (1 << 18),
        ] {
            let p = visit_stride(n);
            assert!(
                (n as u64).saturating_sub(1) * p as u64 <= u32::MAX as u64,
                "n {n}, stride {p}"
            );
            if n <= 65_536 {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let j = ((i as u64 * p as u64) % n as u64) as usize;
                    assert!(!std::mem::replace(&mut seen[j], true), "n {n}: {j} twice");
                }
            }
        }
        // The first tenth of 4096 VPLs reaches every tenth of the array.
        let (n, p) = (4096u32, visit_stride(4096));
        let mut deciles = [false; 10];
        for i in 0..n / 10 {
            deciles[((i * p) % n * 10 / n) as usize] = true;
        }
        assert!(deciles.iter().all(|&d| d), "{deciles:?}");
        assert_eq!(
            partial_scale(GiProgress {
                done: 1024,
                total: 4096
            }),
            4.0
        );
        assert_eq!(partial_scale(GiProgress { done: 0, total: 4096 }), 1.0);
        assert_eq!(
            partial_scale(GiProgress {
                done: 4096,
                total: 4096
            }),
            1.0
        );
    }
}
