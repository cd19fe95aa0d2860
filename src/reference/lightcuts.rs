//! Lightcuts (Walter et al. 2005, "Lightcuts: a scalable approach to illumination", summarised
//! in Rehfeld & Dachsbacher, "Lightcut Interpolation", section 2): the CPU twin of
//! `shaders/methods/lightcuts/lc_build.wgsl` (normal cones and representative VPLs per node)
//! and `lightcuts.wgsl` (the per-pixel cut refinement). Written for clarity, not speed.
//!
//! **The tree** is the frame's light tree (`sst_tree`: a perfect binary tree over the VPLs in
//! Morton order, implicit indexing, root 1, leaf i at `leaves + i`), whose nodes carry the
//! summed flux I_C and the bounding box of their VPLs. Lightcuts adds two things per node:
//! - a **normal cone** (axis, half-angle) containing every VPL normal of the node, merged
//!   bottom-up as the smallest cone around the children's cones ([`merge_cones`]);
//! - a **representative VPL**, drawn bottom-up: a node takes its first child's representative
//!   with probability lum(I_a) / (lum(I_a) + lum(I_b)), else its second child's, with a random
//!   number per node and build ([`rep_random`]). A VPL j of node C is its representative with
//!   probability lum(I_j) / lum(I_C) (the product telescopes), as Walter et al. choose it (3.1),
//!   and a node shares its representative with one of its children, so refining it reuses
//!   that evaluation (and its shadow ray).
//!
//! **A cluster's estimate** is its representative's contribution with the cluster's intensity:
//! flux_j x lum(I_C) / lum(flux_j) (the representative's colour, the cluster's luminance). Over
//! builds its mean is sum_j flux_j x f_j per channel, i.e. unbiased for a fixed cut (Walter et
//! al. carry I_C itself, unbiased only when the cluster's VPLs share one colour).
//!
//! **The error bound** of a cluster (Walter et al. 4.1) for a Lambertian receiver at x with
//! normal n: lum(I_C) / pi x cos_x_ub x cos_v_ub / max(d_min^2, eps^2), visibility bounded by
//! 1, where d_min is the distance from x to the node's box, cos_x_ub bounds the cosine at the
//! receiver over the box and cos_v_ub the emitter cosine over the box and the normal cone
//! ([`cos_bound`], [`error_bound`]). The receiver's rho / pi is common to every cluster, so the
//! refinement compares irradiance-like sums (sum of flux / pi x G x V, luminance): a node is
//! refined while its bound exceeds `relative_error` x the current estimate and the cut is
//! below `max_cut`. Leaves are exact (bound 0). The cut's choice depends on the estimates, so
//! over builds the adaptive cut is not exactly unbiased (docs/lightcuts.md measures how far).

use glam::Vec3;

use crate::base::{
    display::luminance,
    gpu_layout::{GpuVpl, VPL_NONE},
    sst_node::{SstNode, Topology, basis},
};
use crate::reference::brdf;
use crate::reference::vpl::{pcg_hash, u01};
use crate::scene::bvh::{Bvh, Ray};

/// Largest cut the GPU kernel can hold (its per-thread heap; Walter et al. cap cuts at 1000).
pub const MAX_CUT: u32 = 1024;

/// Added to every cone's half-angle in the bound (radians): covers the f32 rounding of the
/// merges so that the bound stays a bound.
pub const CONE_MARGIN: f32 = 1e-3;

/// A cone of directions: every normal within `half_angle` of `axis`. Twin: `vec4` (axis,
/// half-angle) in `lc_build.wgsl`; a negative half-angle marks an empty node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    pub axis: Vec3,
    pub half_angle: f32,
}

impl Cone {
    pub const EMPTY: Cone = Cone {
        axis: Vec3::Z,
        half_angle: -1.0,
    };

    pub fn is_empty(&self) -> bool {
        self.half_angle < 0.0
    }

    /// The GPU's record: xyz axis, w half-angle.
    pub fn to_gpu(self) -> [f32; 4] {
        [self.axis.x, self.axis.y, self.axis.z, self.half_angle]
    }

    pub fn from_gpu(v: [f32; 4]) -> Cone {
        Cone {
            axis: Vec3::new(v[0], v[1], v[2]),
            half_angle: v[3],
        }
    }
}

fn angle_between(a: Vec3, b: Vec3) -> f32 {
    a.dot(b).clamp(-1.0, 1.0).acos()
}

/// The smallest cone containing cones `a` and `b` (the union of two cones on the sphere).
/// Twin: `merge_cones` in `lc_build.wgsl`.
pub fn merge_cones(a: Cone, b: Cone) -> Cone {
    if a.is_empty() {
        return b;
    }
    if b.is_empty() {
        return a;
    }
    // `w` the wider cone, `n` the narrower.
    let (w, n) = if a.half_angle >= b.half_angle {
        (a, b)
    } else {
        (b, a)
    };
    let pi = std::f32::consts::PI;
    let d = angle_between(w.axis, n.axis);
    if (d + n.half_angle).min(pi) <= w.half_angle {
        return w;
    }
    let half = 0.5 * (w.half_angle + d + n.half_angle);
    if half >= pi {
        return Cone {
            axis: w.axis,
            half_angle: pi,
        };
    }
    // Rotate the wider axis towards the narrower by (half - w.half_angle).
    let rot = half - w.half_angle;
    let perp = n.axis - w.axis * w.axis.dot(n.axis);
    let axis = if perp.length_squared() > 1e-12 {
        (w.axis * rot.cos() + perp.normalize() * rot.sin()).normalize()
    } else {
        // Opposite axes: any perpendicular will do; the cone then spans both.
        let (t, _) = basis(w.axis);
        (w.axis * rot.cos() + t * rot.sin()).normalize()
    };
    Cone {
        axis,
        half_angle: half,
    }
}

/// The random number node `node` uses to pick its representative in the build with `seed`.
/// Twin: `rep_random` in `lc_build.wgsl`.
pub fn rep_random(node: u32, seed: u32) -> f32 {
    u01(pcg_hash(node ^ pcg_hash(seed)))
}

/// Per node (index = node id, node 0 unused): its normal cone and its representative (a leaf
/// index into the sorted VPLs, `VPL_NONE` for an empty node).
#[derive(Clone, Debug, PartialEq)]
pub struct LcTree {
    pub cones: Vec<Cone>,
    pub reps: Vec<u32>,
}

/// Cones and representatives over the frame's tree (`nodes`: 2 x leaves decoded nodes, the
/// sorted VPLs one per leaf). Twin: `lc_build.wgsl` (one dispatch per level, bottom-up).
pub fn build(nodes: &[SstNode], sorted: &[GpuVpl], seed: u32) -> LcTree {
    build_on(nodes, Topology::perfect_of(nodes), sorted, seed)
}

/// [`build`] on either tree: the radix tree's inner nodes in post-order (their children may
/// have lower ids). Twin of the radix tree's: `lc_build_radix.wgsl` (one thread per leaf,
/// arrival counters).
pub fn build_on(nodes: &[SstNode], topo: Topology<'_>, sorted: &[GpuVpl], seed: u32) -> LcTree {
    let leaves = topo.leaves as usize;
    let mut cones = vec![Cone::EMPTY; 2 * leaves];
    let mut reps = vec![VPL_NONE; 2 * leaves];
    for (i, v) in sorted.iter().enumerate().take(leaves) {
        if v.id != VPL_NONE {
            cones[leaves + i] = Cone {
                axis: Vec3::from_array(v.normal).normalize(),
                half_angle: 0.0,
            };
            reps[leaves + i] = i as u32;
        }
    }
    // Inner nodes, children first.
    let mut order = Vec::with_capacity(leaves);
    let mut stack = vec![(1u32, false)];
    while let Some((n, expanded)) = stack.pop() {
        if topo.is_leaf(n) {
            continue;
        }
        if expanded {
            order.push(n);
        } else {
            let (a, b) = topo.children(n);
            stack.push((n, true));
            stack.push((b, false));
            stack.push((a, false));
        }
    }
    for n in order {
        let (a, b) = topo.children(n);
        let (a, b, n) = (a as usize, b as usize, n as usize);
        cones[n] = merge_cones(cones[a], cones[b]);
        reps[n] = pick_rep(
            reps[a],
            reps[b],
            luminance(nodes[a].intensity),
            luminance(nodes[b].intensity),
            rep_random(n as u32, seed),
        );
    }
    LcTree { cones, reps }
}

/// A node's representative from its children's (`u` uniform in [0, 1)).
pub fn pick_rep(ra: u32, rb: u32, la: f32, lb: f32, u: f32) -> u32 {
    if ra == VPL_NONE {
        return rb;
    }
    if rb == VPL_NONE {
        return ra;
    }
    if la + lb <= 0.0 || u * (la + lb) < la {
        ra
    } else {
        rb
    }
}

/// Upper bound of max(0, cos(angle between unit `axis` and p - x)) over p in the box
/// [lo, hi]: the box's extent in the frame (t, b, axis) of the axis is [l, h] per axis; for
/// h.z > 0 the cosine z / |p| is at most h.z / sqrt(dx^2 + dy^2 + h.z^2), where dx, dy are the
/// smallest |x|, |y| of that extent (Walter et al. 4.1). Twin: `lc_cos_bound`.
pub fn cos_bound(axis: Vec3, x: Vec3, lo: Vec3, hi: Vec3) -> f32 {
    let (t, b) = basis(axis);
    let c = 0.5 * (lo + hi) - x;
    let r = 0.5 * (hi - lo);
    let extent = |e: Vec3| {
        let m = e.dot(c);
        let s = e.abs().dot(r);
        (m - s, m + s)
    };
    let (_, hz) = extent(axis);
    if hz <= 0.0 {
        return 0.0;
    }
    let nearest2 = |(l, h): (f32, f32)| {
        if l <= 0.0 && h >= 0.0 {
            0.0
        } else {
            (l * l).min(h * h)
        }
    };
    let d2 = nearest2(extent(t)) + nearest2(extent(b));
    if d2 <= 0.0 {
        return 1.0;
    }
    (hz / (d2 + hz * hz).sqrt()).min(1.0)
}

/// Squared distance from x to the box [lo, hi] (0 inside).
pub fn box_distance2(x: Vec3, lo: Vec3, hi: Vec3) -> f32 {
    let d = (lo - x).max(Vec3::ZERO).max(x - hi);
    d.dot(d)
}

/// Upper bound of the geometric term cos_x x cos_v / max(d^2, eps^2) of any VPL inside the
/// box [lo, hi] with its normal inside `cone`, at a receiver x with normal n. Twin:
/// `lc_geometry_bound`.
pub fn geometry_bound(x: Vec3, n: Vec3, lo: Vec3, hi: Vec3, cone: Cone, eps: f32) -> f32 {
    let Some((cx, cv)) = cosines(x, n, lo, hi, cone) else {
        return 0.0;
    };
    cx * cv / box_distance2(x, lo, hi).max(eps * eps)
}

/// The receiver's and the emitter's cosine bounds (cos_x, cos_v) of a cluster; None when the
/// cone is empty or the box lies behind the receiver (the bound is then 0). Twin: `lc_cosines`.
pub fn cosines(x: Vec3, n: Vec3, lo: Vec3, hi: Vec3, cone: Cone) -> Option<(f32, f32)> {
    if cone.is_empty() {
        return None;
    }
    let cx = cos_bound(n, x, lo, hi);
    if cx <= 0.0 {
        return None;
    }
    Some((cx, emitter_cos_bound(x, lo, hi, cone)))
}

/// Upper bound of the emitter's cosine over VPLs in the box with normals in the cone: the
/// angle between a normal m and x - p is at least the angle between the cone's axis and
/// x - p minus the cone's half-angle. Twin: `lc_emitter_cos_bound`.
pub fn emitter_cos_bound(x: Vec3, lo: Vec3, hi: Vec3, cone: Cone) -> f32 {
    let c_axis = cos_bound(-cone.axis, x, lo, hi);
    let phi = c_axis.clamp(0.0, 1.0).acos();
    let theta = cone.half_angle + CONE_MARGIN;
    if phi <= theta {
        1.0
    } else if phi - theta >= std::f32::consts::FRAC_PI_2 {
        0.0
    } else {
        (phi - theta).cos()
    }
}

pub use crate::reference::brdf::Shading;

/// Upper bound, per RGB channel, of f(v, l) x n.l over the directions l from x into the box, with
/// `cx` >= n.l (> 0) from [`cos_bound`]: Lightcuts' material bound (Walter et al. 4.1 bound
/// Lambert, Phong and Ward alike) for the GGX BRDF. Derivation in
/// `shaders/methods/lightcuts/lc_brdf_bound.wgsl` (its twin `lc_ggx_cos_bound`): the diffuse
/// part by (1 - metallic) lum(base) / pi x cx; D by its value at n.h = cos(theta_lr / 2), theta_lr
/// the least angle between the mirror direction and the box; Schlick's F at the least v.h;
/// Vis x n.l by min(0.5 / (n.v alpha) x cx, 0.5 / (A + n.v)).
pub fn ggx_cos_bound(x: Vec3, n: Vec3, lo: Vec3, hi: Vec3, cx: f32, sh: &Shading) -> Vec3 {
    let (v, s) = (sh.v, &sh.surface);
    let nv = n.dot(v);
    if nv.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Vec3::ZERO;
    }
    let pi = std::f32::consts::PI;
    let diffuse = (1.0 - s.metallic) * s.base / pi * cx;
    let a = brdf::alpha(s.roughness);
    let a2 = a * a;
    let r = 2.0 * nv * n - v;
    let t_lr = cos_bound(r, x, lo, hi).clamp(0.0, 1.0).acos();
    let d = brdf::ggx_d((0.5 * t_lr).cos(), a2);
    let t_back = cos_bound(-v, x, lo, hi).clamp(0.0, 1.0).acos();
    let vh = (0.5 * (pi - t_back)).cos();
    let f = brdf::schlick(brdf::f0(s.base, s.metallic), vh);
    let big_a = (nv * nv * (1.0 - a2) + a2).sqrt();
    let vis_cos = (0.5 / (nv * a) * cx).min(0.5 / (big_a + nv));
    diffuse + f * d * vis_cos
}

/// With the glossy BRDF: an upper bound of luminance(sum of flux_i x f(v, l_i) x cos_x x
/// cos_v / max(d^2, eps^2)) over VPLs in cluster `c`'s box (`bbox_min`, `bbox_max`) with
/// normals in `cone` whose fluxes sum to its `intensity`: luminance(intensity x
/// [`ggx_cos_bound`]) x the emitter cosine and distance bounds (per channel first: the flux
/// and the BRDF may share a colour). Twin: `lc_geometry_brdf_bound`.
pub fn geometry_brdf_bound(x: Vec3, n: Vec3, c: &SstNode, cone: Cone, eps: f32, sh: &Shading) -> f32 {
    let (lo, hi) = (c.bbox_min, c.bbox_max);
    let Some((cx, cv)) = cosines(x, n, lo, hi, cone) else {
        return 0.0;
    };
    let m = ggx_cos_bound(x, n, lo, hi, cx, sh);
    luminance(c.intensity * m) * cv / box_distance2(x, lo, hi).max(eps * eps)
}

/// The error bound of node `node` at (x, n): 0 for leaves (exact) and empty nodes.
/// Twin: `lc_error_bound`.
pub fn error_bound(nodes: &[SstNode], lc: &LcTree, node: u32, x: Vec3, n: Vec3, eps: f32) -> f32 {
    error_bound_shaded(nodes, lc, node, x, n, eps, None)
}

/// [`error_bound`], with the glossy BRDF's bound where `sh` is given. Twin: `error_bound` in
/// `lightcuts.wgsl`.
pub fn error_bound_shaded(
    nodes: &[SstNode],
    lc: &LcTree,
    node: u32,
    x: Vec3,
    n: Vec3,
    eps: f32,
    sh: Option<&Shading>,
) -> f32 {
    let leaves = (nodes.len() / 2) as u32;
    let c = &nodes[node as usize];
    if node >= leaves || c.is_empty() {
        return 0.0;
    }
    let cone = lc.cones[node as usize];
    match sh {
        Some(sh) => geometry_brdf_bound(x, n, c, cone, eps, sh) / std::f32::consts::PI,
        None => {
            luminance(c.intensity) / std::f32::consts::PI
                * geometry_bound(x, n, c.bbox_min, c.bbox_max, cone, eps)
        }
    }
}

/// The exact (unbounded) geometric term of `vpl_geometry` in `common/vpl.wgsl`.
pub fn vpl_geometry(pv: Vec3, nv: Vec3, x: Vec3, nx: Vec3, eps: f32) -> f32 {
    let d = pv - x;
    let dist2 = d.length_squared();
    let w = d / dist2.max(1e-30).sqrt();
    let (cx, cv) = (nx.dot(w), -nv.dot(w));
    if cx <= 0.0 || cv <= 0.0 {
        return 0.0;
    }
    cx * cv / dist2.max(eps * eps)
}

/// A cluster's unshadowed estimate at receiver (x, n): its representative's flux / pi x G
/// with the cluster's luminance (0 for an empty node). Twin: `estimate` in `lightcuts.wgsl`.
pub fn cluster_estimate(
    nodes: &[SstNode],
    lc: &LcTree,
    sorted: &[GpuVpl],
    node: u32,
    x: Vec3,
    n: Vec3,
    eps: f32,
) -> Vec3 {
    let rep = lc.reps[node as usize];
    if rep == VPL_NONE {
        return Vec3::ZERO;
    }
    let v = &sorted[rep as usize];
    let flux = Vec3::from_slice(&v.flux[..3]);
    let lf = luminance(flux);
    let g = vpl_geometry(
        Vec3::from_slice(&v.position[..3]),
        Vec3::from_array(v.normal),
        x,
        n,
        eps,
    );
    if g <= 0.0 || lf <= 0.0 {
        return Vec3::ZERO;
    }
    flux * (luminance(nodes[node as usize].intensity) / lf) / std::f32::consts::PI * g
}

/// [`cluster_estimate`] (with the inputs' `params.eps`) times the glossy BRDF f(v, l) towards
/// the representative where `sh` is given (radiance; Lambert leaves the albedo / pi to
/// [`PixelCut::radiance`]). Twin: `estimate` in `lightcuts.wgsl`.
pub fn cluster_estimate_shaded(c: &CutInputs<'_>, node: u32, x: Vec3, n: Vec3, sh: Option<&Shading>) -> Vec3 {
    let e = cluster_estimate(c.nodes, c.lc, c.sorted, node, x, n, c.params.eps);
    match sh {
        Some(sh) if e != Vec3::ZERO => {
            let v = &c.sorted[c.lc.reps[node as usize] as usize];
            let l = (Vec3::from_slice(&v.position[..3]) - x).normalize();
            e * brdf::eval(brdf::Brdf::Ggx, n, sh.v, l, &sh.surface)
        }
        _ => e,
    }
}

/// Whether the node's representative is visible from (x, n): one BVH shadow ray between the
/// end points offset along their normals. Twin: `vpl_visible` (common/vpl_visibility.wgsl).
pub fn representative_visible(
    bvh: &Bvh,
    lc: &LcTree,
    sorted: &[GpuVpl],
    node: u32,
    x: Vec3,
    n: Vec3,
    offset: f32,
) -> bool {
    let v = &sorted[lc.reps[node as usize] as usize];
    let o = x + n * offset;
    let end = Vec3::from_slice(&v.position[..3]) + Vec3::from_array(v.normal) * offset;
    !bvh.any_hit(&Ray {
        origin: o,
        dir: end - o,
        tmin: 1e-4,
        tmax: 1.0 - 1e-4,
    })
}

/// The refinement's settings (`LightcutsSettings` with the shading settings).
#[derive(Clone, Copy, Debug)]
pub struct CutParams {
    pub relative_error: f32,
    pub max_cut: u32,
    pub eps: f32,
    /// Shadow rays with this end-point offset; None: every VPL visible.
    pub shadow_rays: Option<f32>,
    /// Trace every node's representative, also where its estimate is 0 (Lightcut
    /// Interpolation's records: their visibility bits are interpolated to pixels where the
    /// node does contribute). Lightcuts itself skips those rays.
    pub trace_every_node: bool,
}

/// What a pixel's cut depends on besides the receiver: the frame's tree (`nodes`, 2 x leaves,
/// and its `topo`), its Lightcuts build, the sorted VPLs (one per leaf), the BVH of the
/// shadow rays and the refinement's settings.
#[derive(Clone, Copy)]
pub struct CutInputs<'a> {
    pub nodes: &'a [SstNode],
    pub topo: Topology<'a>,
    pub lc: &'a LcTree,
    pub sorted: &'a [GpuVpl],
    pub bvh: &'a Bvh,
    pub params: &'a CutParams,
}

impl<'a> CutInputs<'a> {
    /// The inputs on the perfect tree of `nodes`.
    pub fn perfect(
        nodes: &'a [SstNode],
        lc: &'a LcTree,
        sorted: &'a [GpuVpl],
        bvh: &'a Bvh,
        params: &'a CutParams,
    ) -> Self {
        let topo = Topology::perfect_of(nodes);
        CutInputs {
            nodes,
            topo,
            lc,
            sorted,
            bvh,
            params,
        }
    }
}

/// One node of a pixel's final cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutNode {
    pub node: u32,
    pub bound: f32,
    /// Its estimate: flux / pi x G x V of the representative with the cluster's luminance.
    pub estimate: Vec3,
    /// Its representative's visibility (false without a shadow ray when the estimate is 0).
    pub visible: bool,
}

/// A pixel's lightcut.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelCut {
    /// Sum of the cut's estimates (irradiance-like: multiply by rho / pi for radiance).
    pub sum: Vec3,
    pub cut: Vec<CutNode>,
    pub refinements: u32,
    /// The largest bound left in the cut over lum(sum) (0 when every node is exact).
    pub relative_bound: f32,
    pub shadow_rays: u32,
    /// Shaded with the glossy BRDF: `sum` is radiance already.
    pub glossy: bool,
}

impl PixelCut {
    /// Radiance at a receiver of albedo `albedo`.
    pub fn radiance(&self, albedo: Vec3) -> Vec3 {
        if self.glossy {
            return self.sum;
        }
        albedo / std::f32::consts::PI * self.sum
    }
    /// Whether refinement stopped at the size limit with a bound above the threshold.
    pub fn hit_max_cut(&self, p: &CutParams) -> bool {
        self.relative_bound > p.relative_error
    }
}

/// The lightcut of receiver (x, n): from the root, refine the node with the largest bound
/// until the largest bound is at most `relative_error` x lum(estimate) or the cut holds
/// `max_cut` nodes. Nodes of bound 0 (leaves, empty, facing away) are final at once. A child
/// with its parent's representative reuses the parent's shadow ray. Twin: `lightcuts.wgsl`.
pub fn lightcut(
    nodes: &[SstNode],
    lc: &LcTree,
    sorted: &[GpuVpl],
    bvh: &Bvh,
    x: Vec3,
    n: Vec3,
    p: &CutParams,
) -> PixelCut {
    lightcut_on(&CutInputs::perfect(nodes, lc, sorted, bvh, p), x, n)
}

/// [`lightcut`] on either tree (the inputs' `topo`).
pub fn lightcut_on(c: &CutInputs<'_>, x: Vec3, n: Vec3) -> PixelCut {
    lightcut_shaded_on(c, x, n, None)
}

/// [`lightcut_on`] with the glossy BRDF where `sh` is given: its bounds
/// ([`error_bound_shaded`]) and estimates ([`cluster_estimate_shaded`]; the sum is radiance).
pub fn lightcut_shaded_on(c: &CutInputs<'_>, x: Vec3, n: Vec3, sh: Option<&Shading>) -> PixelCut {
    let CutInputs {
        nodes,
        topo,
        lc,
        sorted,
        bvh,
        params: p,
    } = *c;
    let leaves = topo.leaves;
    let estimate = |node: u32| cluster_estimate_shaded(c, node, x, n, sh);
    let mut rays = 0u32;
    let mut visible = |node: u32, e: Vec3| -> bool {
        if e == Vec3::ZERO && !p.trace_every_node {
            return false;
        }
        let Some(offset) = p.shadow_rays else {
            return true;
        };
        rays += 1;
        representative_visible(bvh, lc, sorted, node, x, n, offset)
    };
    // Open nodes: (node, bound, estimate if visible, visible).
    let mut open: Vec<(CutNode, bool)> = Vec::new();
    let mut done: Vec<CutNode> = Vec::new();
    let mut sum = Vec3::ZERO;
    let mut refinements = 0;
    if !nodes[1].is_empty() {
        let bound = error_bound_shaded(nodes, lc, 1, x, n, p.eps, sh);
        if bound > 0.0 {
            let e = estimate(1);
            let vis = visible(1, e);
            let e = if vis { e } else { Vec3::ZERO };
            sum += e;
            open.push((
                CutNode {
                    node: 1,
                    bound,
                    estimate: e,
                    visible: vis,
                },
                vis,
            ));
        } else {
            let vis = p.trace_every_node && visible(1, estimate(1));
            done.push(CutNode {
                node: 1,
                bound,
                estimate: Vec3::ZERO,
                visible: vis,
            });
        }
    }
    // The open node with the largest bound (the first of equal ones).
    while let Some(k) = (0..open.len()).reduce(|a, b| if open[b].0.bound > open[a].0.bound { b } else { a }) {
        let (top, top_vis) = open[k];
        if top.bound <= p.relative_error * luminance(sum) {
            break;
        }
        if (open.len() + done.len()) as u32 >= p.max_cut {
            break;
        }
        open.swap_remove(k);
        sum -= top.estimate;
        refinements += 1;
        let (c0, c1) = topo.children(top.node);
        for child in [c0, c1] {
            if nodes[child as usize].is_empty() {
                continue;
            }
            let bound = error_bound_shaded(nodes, lc, child, x, n, p.eps, sh);
            let (e, vis) = if lc.reps[child as usize] == lc.reps[top.node as usize] {
                (estimate(child), top_vis)
            } else if bound > 0.0 || child >= leaves || p.trace_every_node {
                let e = estimate(child);
                (e, visible(child, e))
            } else {
                (Vec3::ZERO, false)
            };
            let e = if vis { e } else { Vec3::ZERO };
            sum += e;
            let c = CutNode {
                node: child,
                bound,
                estimate: e,
                visible: vis,
            };
            if bound > 0.0 {
                open.push((c, vis))
            } else {
                done.push(c)
            }
        }
    }
    let lmax = open.iter().map(|c| c.0.bound).fold(0.0f32, f32::max);
    let ls = luminance(sum);
    let relative_bound = if lmax <= 0.0 {
        0.0
    } else if ls > 0.0 {
        lmax / ls
    } else {
        3.0e38
    };
    done.extend(open.into_iter().map(|c| c.0));
    PixelCut {
        sum,
        cut: done,
        refinements,
        relative_bound,
        shadow_rays: rays,
        glossy: sh.is_some(),
    }
}

/// Checks that `cut` (node ids) covers every non-empty leaf exactly once and no empty one:
/// Ok, or the first problem found.
pub fn check_cut(nodes: &[SstNode], cut: &[u32]) -> Result<(), String> {
    check_cut_on(nodes, Topology::perfect_of(nodes), cut)
}

/// [`check_cut`] on either tree.
pub fn check_cut_on(nodes: &[SstNode], topo: Topology<'_>, cut: &[u32]) -> Result<(), String> {
    let leaves = topo.leaves;
    let mut covered = vec![0u32; leaves as usize];
    for &c in cut {
        if c == 0 || c >= 2 * leaves {
            return Err(format!("node {c} is not a node of a tree of {leaves} leaves"));
        }
        let (first, last) = topo.leaf_range(c);
        for l in first..=last {
            covered[l as usize] += 1;
        }
    }
    for (l, &k) in covered.iter().enumerate() {
        let empty = nodes[leaves as usize + l].is_empty();
        if !empty && k != 1 {
            return Err(format!("leaf {l} is covered {k} times"));
        }
        if empty && k > 1 {
            return Err(format!("empty leaf {l} is covered {k} times"));
        }
    }
    Ok(())
}
