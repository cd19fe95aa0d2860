//! CPU twin of `shaders/light_paths.wgsl`: multi-bounce VPLs by light paths (instant
//! radiosity, Keller 1997; the SST paper's VPL generation, section 5).
//!
//! - [`path_start`]: path p of a light's n paths picks an RSM texel through the flux pyramid
//!   (hierarchical warping of a rotated Hammersley point), flux = texel flux / (n x pmf);
//! - [`trace_path`]: from a start, bounces 2..=N: a cosine-weighted direction about the
//!   vertex's normal, the closest hit through the BVH, the hit's surface
//!   (`reference::surface`), flux x albedo, Russian roulette with q = min(1, max(albedo)),
//!   one VPL per bounce (`vpl_path_id(b, p)`), empty slots after the path ends.

use glam::Vec3;

use crate::base::gpu_layout::{GpuVpl, VPL_NONE, vpl_path_id};
use crate::reference::vpl::{hammersley, pcg_hash, u01, warp};
use crate::scene::{
    Scene,
    bvh::{Bvh, Ray},
};

/// The shader's small generator (`Rng` in `shaders/common/random.wgsl`).
#[derive(Clone, Copy, Debug)]
pub struct Rng(u32);

impl Rng {
    pub fn new(a: u32, b: u32, c: u32) -> Self {
        Self(pcg_hash(a ^ pcg_hash(b ^ pcg_hash(c))))
    }
    pub fn next_f32(&mut self) -> f32 {
        self.0 = pcg_hash(self.0);
        u01(self.0)
    }
}

/// How the paths run (the shader's `PathParams` without the slot layout).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathRules {
    pub bounces: u32,
    pub roulette: bool,
    pub seed: u32,
    pub ray_offset: f32,
    pub lod: u32,
    pub flux_scale: f32,
}

/// Rotation of light `layer`'s Hammersley set of path starts.
pub fn path_rotation(seed: u32, layer: u32) -> [f32; 2] {
    let s = seed.wrapping_mul(2).wrapping_add(layer.wrapping_mul(0x51ed27));
    [
        u01(pcg_hash(s ^ 0x68e3_1da4)),
        u01(pcg_hash(s.wrapping_add(1) ^ 0x68e3_1da4)),
    ]
}

/// One RSM texel of a light's layer: position (None where nothing was hit), normal, flux.
#[derive(Clone, Copy, Debug)]
pub struct RsmTexel {
    pub position: Option<Vec3>,
    pub normal: Vec3,
    pub flux: Vec3,
}

/// Path `j` of `n` paths of light `layer` (RSM `res` x `res`, `texels` row-major, `flux_pyr`
/// the layer's flux-luminance pyramid, `reference::vpl::pyramid`): its start as a VPL record.
pub fn path_start(
    layer: u32,
    j: u32,
    n: u32,
    seed: u32,
    res: u32,
    texels: &[RsmTexel],
    flux_pyr: &[Vec<f32>],
) -> GpuVpl {
    let empty = GpuVpl {
        position: [0.0; 4],
        normal: [0.0, 0.0, 1.0],
        id: VPL_NONE,
        flux: [0.0; 4],
    };
    let total = flux_pyr.last().and_then(|l| l.first()).copied().unwrap_or(0.0);
    if total <= 0.0 {
        return empty;
    }
    let (x, y, pmf) = warp(flux_pyr, res, hammersley(j, n.max(1), path_rotation(seed, layer)));
    let t = texels[(y * res + x) as usize];
    match t.position {
        Some(p) if pmf > 0.0 => GpuVpl {
            position: p.extend(pmf).to_array(),
            normal: t.normal.normalize().to_array(),
            id: (layer << 24) | (y * res + x),
            flux: (t.flux / (n.max(1) as f32 * pmf)).extend(1.0).to_array(),
        },
        _ => empty,
    }
}

/// An orthonormal basis (t, b) around unit `n` (Duff et al. 2017).
pub fn onb(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        Vec3::new(b, s + n.y * n.y * a, -n.y),
    )
}

/// Cosine-weighted direction about `n` from (u1, u2) (pdf cos / pi).
pub fn cosine_direction(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let (t, b) = onb(n);
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// Path `p`'s VPLs at bounces 2..=`rules.bounces` (empty records after it ends) from `start`.
/// `mips` / `size`: the base-colour textures as `reference::surface::surface_at` takes them.
pub fn trace_path(
    scene: &Scene,
    bvh: &Bvh,
    mips: &[Vec<Vec<u8>>],
    size: u32,
    start: &GpuVpl,
    p: u32,
    rules: &PathRules,
) -> Vec<GpuVpl> {
    let empty = GpuVpl {
        position: [0.0; 4],
        normal: [0.0, 0.0, 1.0],
        id: VPL_NONE,
        flux: [0.0; 4],
    };
    let mut out = Vec::new();
    let mut alive = start.id != VPL_NONE;
    let mut x = Vec3::from_slice(&start.position[..3]);
    let mut n = Vec3::from_array(start.normal);
    let mut ng = n;
    let mut flux = Vec3::from_slice(&start.flux[..3]) * rules.flux_scale;
    let mut rng = Rng::new(p, rules.seed, 0x2545_f491);
    for b in 2..=rules.bounces {
        if !alive {
            out.push(empty);
            continue;
        }
        let (u1, u2, u3) = (rng.next_f32(), rng.next_f32(), rng.next_f32());
        let dir = cosine_direction(n, u1, u2);
        alive = dir.dot(ng) > 0.0;
        let mut hit = None;
        if alive {
            let ray = Ray {
                origin: x + ng * rules.ray_offset,
                dir,
                tmin: 0.0,
                tmax: 3.0e38,
            };
            hit = bvh
                .closest_hit(&ray)
                .map(|h| crate::reference::surface::surface_at(scene, mips, size, &h, dir, rules.lod));
        }
        let Some(s) = hit else {
            alive = false;
            out.push(empty);
            continue;
        };
        flux *= s.albedo;
        if rules.roulette {
            let q = s.albedo.max_element().min(1.0);
            alive = u3 < q;
            flux /= q.max(1e-30);
        }
        alive = alive && flux.max_element() > 0.0;
        if !alive {
            out.push(empty);
            continue;
        }
        out.push(GpuVpl {
            position: s.position.extend(start.position[3]).to_array(),
            normal: s.normal.to_array(),
            id: vpl_path_id(b, p),
            flux: flux.extend(1.0).to_array(),
        });
        x = s.position;
        n = s.normal;
        ng = s.geometric_normal;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_directions_have_the_cosine_density() {
        // Mean of cos over the cosine density is 2/3; every direction in the hemisphere.
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let mut rng = Rng::new(1, 2, 3);
        let k = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..k {
            let d = cosine_direction(n, rng.next_f32(), rng.next_f32());
            let c = d.dot(n);
            assert!(c >= -1e-6 && (d.length() - 1.0).abs() < 1e-5);
            sum += c as f64;
        }
        let mean = sum / k as f64;
        // Var(cos) = 1/2 - 4/9 = 1/18; 5 standard errors.
        assert!(
            (mean - 2.0 / 3.0).abs() < 5.0 * (1.0f64 / 18.0 / k as f64).sqrt(),
            "{mean}"
        );
    }

    #[test]
    fn the_basis_is_orthonormal() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(1.0, 2.0, -3.0).normalize()] {
            let (t, b) = onb(n);
            assert!(t.dot(b).abs() < 1e-6 && t.dot(n).abs() < 1e-6 && b.dot(n).abs() < 1e-6);
            assert!((t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
        }
    }
}
