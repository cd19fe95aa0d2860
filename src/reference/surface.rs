//! CPU twin of `shaders/common/surface.wgsl`: the surface a ray hit, from the triangle and the
//! hit's barycentrics (u, v: weights 1 - u - v, u, v of the triangle's corners, as
//! `scene::bvh::intersect_triangle` returns them). The groundwork of issue 23's light paths,
//! where each bounce's VPL sits on such a surface with its albedo.
//!
//! - position: the barycentric mix of the corners;
//! - geometric normal: the triangle's, turned to face the ray's origin;
//! - normal: the interpolated vertex normal, normalised, on the geometric normal's side;
//! - uv: interpolated; material: the triangle's;
//! - albedo: base colour factor x the base-colour texture at mip level `lod` (clamped to the
//!   chain), nearest texel, uv wrapped (repeat), sRGB decoded: compute shaders have no
//!   derivatives to pick a level, and a VPL is a point sample whose level says how much
//!   texture detail it averages.

use glam::{Vec2, Vec3};

use crate::base::display::srgb8_to_linear;
use crate::scene::{Scene, bvh::Hit};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    pub position: Vec3,
    pub normal: Vec3,
    pub geometric_normal: Vec3,
    pub uv: Vec2,
    pub material: u32,
    pub albedo: Vec3,
}

/// Texel (nearest, repeat) of mip level `lod` of a chain whose level 0 is `size` x `size`
/// (RGBA8 sRGB per level, as `renderer::scene_gpu::texture_mips` builds them), linear RGB.
pub fn texel(mips: &[Vec<u8>], size: u32, uv: Vec2, lod: u32) -> Vec3 {
    let level = (lod as usize).min(mips.len().saturating_sub(1));
    let s = (size >> level).max(1);
    let f = uv - uv.floor();
    let x = ((f.x * s as f32) as u32).min(s - 1);
    let y = ((f.y * s as f32) as u32).min(s - 1);
    let i = ((y * s + x) * 4) as usize;
    let m = &mips[level];
    if i + 2 >= m.len() {
        return Vec3::ONE;
    }
    Vec3::new(
        srgb8_to_linear(m[i]),
        srgb8_to_linear(m[i + 1]),
        srgb8_to_linear(m[i + 2]),
    )
}

/// The surface `hit` found (its triangle at its barycentrics (u, v)) along `dir`. `mips[t]`:
/// texture t's mip chain at `size` (the GPU's texture array).
pub fn surface_at(
    scene: &Scene,
    mips: &[Vec<Vec<u8>>],
    size: u32,
    hit: &Hit,
    dir: Vec3,
    lod: u32,
) -> Surface {
    let (tri, u, v) = (hit.triangle as usize, hit.u, hit.v);
    let idx = &scene.indices[3 * tri..3 * tri + 3];
    let w = 1.0 - u - v;
    let [p0, p1, p2] = scene.triangle(tri);
    let position = w * p0 + u * p1 + v * p2;
    let mut ng = (p1 - p0).cross(p2 - p0);
    ng = if ng.length() > 0.0 {
        ng / ng.length()
    } else {
        Vec3::Z
    };
    if ng.dot(dir) > 0.0 {
        ng = -ng;
    }
    let n = |k: usize| scene.normals.get(idx[k] as usize).copied().unwrap_or(Vec3::Y);
    let uvk = |k: usize| scene.uvs.get(idx[k] as usize).copied().unwrap_or(Vec2::ZERO);
    let mut ns = w * n(0) + u * n(1) + v * n(2);
    ns = if ns.length() > 0.0 { ns / ns.length() } else { ng };
    if ns.dot(ng) < 0.0 {
        ns = -ns;
    }
    let uv = w * uvk(0) + u * uvk(1) + v * uvk(2);
    let material = scene.triangle_materials.get(tri).copied().unwrap_or(0);
    let mat = scene.materials.get(material as usize);
    let factor = mat.map_or(Vec3::splat(0.8), |m| Vec3::from_slice(&m.base_color_factor[..3]));
    let tex = mat
        .and_then(|m| m.base_color_texture)
        .filter(|&t| t < scene.textures.len())
        .and_then(|t| mips.get(t));
    let albedo = match tex {
        Some(chain) => factor * texel(chain, size, uv, lod),
        None => factor,
    };
    Surface {
        position,
        normal: ns,
        geometric_normal: ng,
        uv,
        material,
        albedo,
    }
}
