//! `#[repr(C)]` parameter structs shared with WGSL. Each has a twin of the same name in
//! `shaders/`; `tests::layouts_match_wgsl` checks sizes and member offsets against naga's
//! layout of the WGSL struct, so the two cannot drift apart silently.

use bytemuck::{Pod, Zeroable};

pub use crate::base::gpu_layout::{GpuSstNode, GpuVpl, VPL_NONE};
use glam::{Mat4, Vec3};

use crate::scene::{Aabb, Camera, DirectionalLight};

/// Most directional lights a frame shades (one shadow-map layer each).
pub const MAX_LIGHTS: usize = 4;

/// Twin: `Camera` in `shaders/common/camera.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuCamera {
    pub view_proj: [[f32; 4]; 4],
    /// xyz = eye position, w = near plane.
    pub position: [f32; 4],
    /// xyz = unit forward, w = far plane.
    pub forward: [f32; 4],
    /// xyz = right * tan(yfov/2) * aspect (pixel ray spans).
    pub right: [f32; 4],
    /// xyz = up * tan(yfov/2).
    pub up: [f32; 4],
    /// width, height, 1/width, 1/height.
    pub resolution: [f32; 4],
}

impl GpuCamera {
    pub fn new(cam: &Camera, width: u32, height: u32) -> Self {
        let aspect = width as f32 / height.max(1) as f32;
        let t = (0.5 * cam.yfov).tan();
        Self {
            view_proj: cam.view_projection(aspect).to_cols_array_2d(),
            position: cam.position.extend(cam.znear).to_array(),
            forward: cam.forward.extend(cam.zfar).to_array(),
            right: (cam.right() * t * aspect).extend(0.0).to_array(),
            up: (cam.up * t).extend(0.0).to_array(),
            resolution: [
                width as f32,
                height as f32,
                1.0 / width as f32,
                1.0 / height as f32,
            ],
        }
    }
}

/// Twin: `DirectionalLight` in `shaders/common/lights.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuDirectionalLight {
    /// World -> light clip space (orthographic, covering the scene bounds), depth in [0, 1].
    pub view_proj: [[f32; 4]; 4],
    /// xyz = unit direction the light travels; w = shadow-map layer.
    pub direction: [f32; 4],
    /// rgb = irradiance E (W/m^2) on a perpendicular surface; w unused.
    pub irradiance: [f32; 4],
    /// x = world size of one shadow-map texel, y = depth range of the light frustum (m),
    /// z = constant depth bias (texels), w = normal offset (texels).
    pub shadow: [f32; 4],
}

/// Twin: `Lights` in `shaders/common/lights.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLights {
    /// x = light count, y = shadow-map resolution, z = PCF radius in texels (0 = one tap),
    /// w = slope-scaled bias factor (f32 bits).
    pub count: [u32; 4],
    pub lights: [GpuDirectionalLight; MAX_LIGHTS],
}

/// The orthographic light frustum of a directional light that tightly covers `bounds`.
/// Returns (view_proj, texel world size, depth range).
pub fn light_frustum(direction: Vec3, bounds: &Aabb, resolution: u32) -> (Mat4, f32, f32) {
    let dir = direction.normalize_or(Vec3::NEG_Y);
    let (c, r) = if bounds.is_empty() {
        (Vec3::ZERO, 1.0)
    } else {
        (bounds.center(), bounds.radius().max(1e-30))
    };
    let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let eye = c - dir * (2.0 * r);
    let view = Mat4::look_to_rh(eye, dir, up);
    // Tight box of the 8 corners in light space.
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for i in 0..8 {
        let p = Vec3::new(
            if i & 1 == 0 { bounds.min.x } else { bounds.max.x },
            if i & 2 == 0 { bounds.min.y } else { bounds.max.y },
            if i & 4 == 0 { bounds.min.z } else { bounds.max.z },
        );
        let p = if bounds.is_empty() { c } else { p };
        let q = view.transform_point3(p);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    // Square texels: use the larger extent for both axes; pad half a texel each side.
    let ext = (hi.x - lo.x).max(hi.y - lo.y).max(1e-6 * r);
    let pad = ext / resolution as f32;
    let cx = 0.5 * (lo.x + hi.x);
    let cy = 0.5 * (lo.y + hi.y);
    let half = 0.5 * ext + pad;
    // Right-handed view looks down -Z: near = -hi.z, far = -lo.z.
    let near = -hi.z - pad;
    let far = -lo.z + pad;
    let proj = Mat4::orthographic_rh(cx - half, cx + half, cy - half, cy + half, near, far);
    (proj * view, 2.0 * half / resolution as f32, far - near)
}

/// Light 0's reflective shadow map raster, as the frame drew it (the VAL clustering reads it):
/// its `view_proj`, the direction its light travels, the texel edge in metres perpendicular
/// to it, the RSM resolution and the frame's light count (RSM layers).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RsmRaster {
    pub view_proj: Mat4,
    pub direction: Vec3,
    pub texel: f32,
    pub res: u32,
    pub lights: u32,
}

impl GpuLights {
    pub fn new(
        lights: &[DirectionalLight],
        bounds: &Aabb,
        resolution: u32,
        depth_bias_texels: f32,
        normal_offset_texels: f32,
        slope_bias: f32,
        pcf_radius: u32,
    ) -> Self {
        let mut out = GpuLights::zeroed();
        let n = lights.len().min(MAX_LIGHTS);
        out.count = [n as u32, resolution, pcf_radius, slope_bias.to_bits()];
        for (i, l) in lights.iter().take(n).enumerate() {
            let (vp, texel, range) = light_frustum(l.direction, bounds, resolution);
            out.lights[i] = GpuDirectionalLight {
                view_proj: vp.to_cols_array_2d(),
                direction: l.direction.normalize_or(Vec3::NEG_Y).extend(i as f32).to_array(),
                irradiance: l.irradiance.extend(0.0).to_array(),
                shadow: [texel, range, depth_bias_texels, normal_offset_texels],
            };
        }
        out
    }
}

/// Twin: `DisplayParams` in `shaders/display.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct DisplayParams {
    /// Linear scale 2^EV applied before the tonemap.
    pub exposure: f32,
    /// 0 = clamp, 1 = Reinhard (luminance), 2 = ACES (Narkowicz fit).
    pub tonemap: u32,
    /// 0 = rgb, 1/2/3 = r/g/b, 4 = luminance (`views::Channel`).
    pub channel: u32,
    /// Bit 0: log10 false colour over [lo, hi] instead of the tonemap; bit 1: NaN/Inf magenta.
    pub flags: u32,
    pub lo: f32,
    pub hi: f32,
    pub _pad: [u32; 2],
}

impl DisplayParams {
    pub fn new(look: &crate::renderer::views::ViewLook) -> Self {
        Self {
            exposure: look.exposure_ev.exp2(),
            tonemap: look.tonemap.gpu_id(),
            channel: look.channel.gpu_id(),
            flags: look.false_color as u32 | (look.nan_highlight as u32) << 1,
            lo: look.range_log10[0],
            hi: look.range_log10[1],
            _pad: [0; 2],
        }
    }
}

/// Twin: `VisParams` in `shaders/visualise.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct VisParams {
    /// See `VisMode` in `visualise.rs`.
    pub mode: u32,
    /// Which channel/layer (shadow-map layer).
    pub layer: u32,
    pub _pad: [u32; 2],
    /// Value range mapped to [0, 1] (depth, position).
    pub range_min: [f32; 4],
    pub range_max: [f32; 4],
}

/// Twin: `MaterialGpu` in `shaders/gbuffer.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    /// Linear RGBA base colour factor.
    pub base_color: [f32; 4],
    /// Texture layers or -1: x base colour, y roughness (its G), z metallic (its B); w unused.
    pub texture: [i32; 4],
    /// x = metallic, y = roughness (glTF factors), zw unused.
    pub params: [f32; 4],
    /// `Material::metal_rough_uv`'s rows (w unused): the metallic-roughness textures' UVs.
    pub mr_uv: [[f32; 4]; 2],
}

/// Twin: `Vertex` inputs of `shaders/gbuffer.wgsl` (vertex buffer, not a uniform).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
    pub material: u32,
}

/// Twin: `RayIn` in `shaders/bvh_rays.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuRay {
    /// xyz = origin, w = tmin.
    pub origin: [f32; 4],
    /// xyz = direction (unnormalised is fine), w = tmax.
    pub dir: [f32; 4],
}

/// Twin: `HitOut` in `shaders/bvh_rays.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuHit {
    pub t: f32,
    /// Original triangle id, or 0xffff_ffff for a miss.
    pub triangle: u32,
    pub u: f32,
    pub v: f32,
}

/// Twin: `VplParams` in `shaders/vpl_gen.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuVplParams {
    pub res: u32,
    pub levels: u32,
    pub light_count: u32,
    pub vpl_count: u32,
    pub samples: u32,
    pub filter_radius: u32,
    /// 0 = BRSM, 1 = RSM (uniform).
    pub mode: u32,
    pub seed: u32,
    /// Metres.
    pub sample_radius: f32,
    pub n_min: f32,
    /// Metres.
    pub d_max: f32,
    pub flux_mix: f32,
    pub epsilon: f32,
    pub per_layer: u32,
    pub _pad: [u32; 2],
    /// Per light: x = first VPL, y = VPL count.
    pub ranges: [[u32; 4]; 4],
    /// Offset of pyramid level l within a layer at [l / 4][l % 4].
    pub level_offsets: [[u32; 4]; 4],
}

/// Twin: `SlcParams` in `shaders/common/slc_params.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuSlcParams {
    pub width: u32,
    pub height: u32,
    pub block: u32,
    pub grid_x: u32,
    pub grid_y: u32,
    pub cut_size: u32,
    pub leaves: u32,
    pub levels: u32,
    /// 0 SLC, 1 SST, 2 RTSLC.
    pub method: u32,
    /// 0 stochastic, 1 off.
    pub blending: u32,
    /// 0 mock cut, 1 average, 2 root, 3 recompute.
    pub fallback: u32,
    pub cull: u32,
    pub seed: u32,
    pub accumulate: u32,
    pub epsilon: f32,
    pub ray_offset: f32,
    pub n_min: f32,
    pub d_max: f32,
    /// 1: the estimate without the albedo (half-resolution GI, upsampled at full resolution;
    /// interleaving, whose filter applies it).
    pub demodulate: u32,
    /// x | y << 16 of the pixel whose samples are recorded (`methods::tree_samplers::pass::PixelTrace`);
    /// `u32::MAX` = none.
    pub trace_pixel: u32,
    /// Near-field refinement factor (`SamplingSettings::near_field`; 0 = off).
    pub near_field: f32,
    /// 1: shadow rays, 0: every sample visible (`GiSettings::shadow_rays`).
    pub shadow_rays: u32,
    /// Metres by which substitute samples' shadow rays stop short of the drawn point
    /// (`SamplingSettings::substitute_offset`).
    pub substitute_offset: f32,
    /// 0 mean position (eq. 5.5), 1 min-max box distance, 2 defensive (`ChildProbability`).
    pub child_probability: u32,
    /// Interleaving pattern edge n (1 = off) and the frame's subset offset
    /// (`reference::interleave::Interleave::offset_of`).
    pub interleave: u32,
    pub interleave_offset: u32,
    /// 1: the radix tree (children from its links; `TreeKind::Lbvh`), 0: the perfect tree.
    pub radix: u32,
    /// The BRDF model (`Brdf::gpu`).
    pub brdf: u32,
    /// How glossy walks weigh the children: 0 geometric, 1 the SST paper's material term,
    /// 2 defensive (`GlossyWeights::gpu`).
    pub glossy_material: u32,
    pub _pad: [u32; 3],
    /// xyz the camera's position.
    pub eye: [f32; 4],
}

/// Twin: `GtParams` in `shaders/methods/ground_truth/ground_truth.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuGtParams {
    pub begin: u32,
    pub end: u32,
    pub width: u32,
    pub height: u32,
    pub epsilon: f32,
    pub ray_offset: f32,
    /// 1: shadow rays, 0: every VPL visible (`GiSettings::shadow_rays`).
    pub shadow_rays: u32,
    /// The BRDF model (`Brdf::gpu`).
    pub brdf: u32,
    /// xyz the camera's position (the view direction of glossy shading).
    pub eye: [f32; 4],
    /// The order the VPLs are summed in: step i evaluates VPL (i x order[0]) mod order[1]
    /// (a stride coprime with the count, [`crate::methods::ground_truth::visit_stride`]), so
    /// that every partial sum is spread over the whole set.
    pub order: [u32; 4],
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::renderer::shaders::{Embedded, preprocess, validate};

    /// (size, member offsets) of WGSL struct `name` in shader `file`, from naga's layouter.
    fn wgsl_layout(file: &str, name: &str) -> (u32, Vec<u32>) {
        let text = preprocess(&Embedded, file).unwrap();
        let module = validate(file, &text).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        for (handle, ty) in module.types.iter() {
            if ty.name.as_deref() == Some(name)
                && let naga::TypeInner::Struct { members, span } = &ty.inner
            {
                assert_eq!(layouter[handle].size, *span);
                return (*span, members.iter().map(|m| m.offset).collect());
            }
        }
        panic!("struct {name} not found in {file}");
    }

    #[test]
    fn layouts_match_wgsl() {
        use std::mem::{offset_of, size_of};
        let cases: Vec<(&str, &str, usize, Vec<usize>)> = vec![
            (
                "compare_views.wgsl",
                "CmpParams",
                size_of::<crate::renderer::passes::compare::GpuCmpParams>(),
                {
                    use crate::renderer::passes::compare::GpuCmpParams as P;
                    vec![
                        offset_of!(P, mode),
                        offset_of!(P, split_x),
                        offset_of!(P, exposure),
                        offset_of!(P, tonemap),
                        offset_of!(P, diff_scale),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                        offset_of!(P, _pad) + 8,
                    ]
                },
            ),
            (
                "direct.wgsl",
                "Camera",
                size_of::<GpuCamera>(),
                vec![
                    offset_of!(GpuCamera, view_proj),
                    offset_of!(GpuCamera, position),
                    offset_of!(GpuCamera, forward),
                    offset_of!(GpuCamera, right),
                    offset_of!(GpuCamera, up),
                    offset_of!(GpuCamera, resolution),
                ],
            ),
            (
                "direct.wgsl",
                "DirectionalLight",
                size_of::<GpuDirectionalLight>(),
                vec![
                    offset_of!(GpuDirectionalLight, view_proj),
                    offset_of!(GpuDirectionalLight, direction),
                    offset_of!(GpuDirectionalLight, irradiance),
                    offset_of!(GpuDirectionalLight, shadow),
                ],
            ),
            (
                "direct.wgsl",
                "Lights",
                size_of::<GpuLights>(),
                vec![offset_of!(GpuLights, count), offset_of!(GpuLights, lights)],
            ),
            (
                "display.wgsl",
                "DisplayParams",
                size_of::<DisplayParams>(),
                vec![
                    offset_of!(DisplayParams, exposure),
                    offset_of!(DisplayParams, tonemap),
                    offset_of!(DisplayParams, channel),
                    offset_of!(DisplayParams, flags),
                    offset_of!(DisplayParams, lo),
                    offset_of!(DisplayParams, hi),
                    offset_of!(DisplayParams, _pad),
                ],
            ),
            (
                "visualise.wgsl",
                "VisParams",
                size_of::<VisParams>(),
                vec![
                    offset_of!(VisParams, mode),
                    offset_of!(VisParams, layer),
                    offset_of!(VisParams, _pad),
                    offset_of!(VisParams, range_min),
                    offset_of!(VisParams, range_max),
                ],
            ),
            (
                "gbuffer.wgsl",
                "MaterialGpu",
                size_of::<GpuMaterial>(),
                vec![
                    offset_of!(GpuMaterial, base_color),
                    offset_of!(GpuMaterial, texture),
                    offset_of!(GpuMaterial, params),
                    offset_of!(GpuMaterial, mr_uv),
                ],
            ),
            (
                "vpl_gen.wgsl",
                "VplParams",
                size_of::<GpuVplParams>(),
                vec![
                    offset_of!(GpuVplParams, res),
                    offset_of!(GpuVplParams, levels),
                    offset_of!(GpuVplParams, light_count),
                    offset_of!(GpuVplParams, vpl_count),
                    offset_of!(GpuVplParams, samples),
                    offset_of!(GpuVplParams, filter_radius),
                    offset_of!(GpuVplParams, mode),
                    offset_of!(GpuVplParams, seed),
                    offset_of!(GpuVplParams, sample_radius),
                    offset_of!(GpuVplParams, n_min),
                    offset_of!(GpuVplParams, d_max),
                    offset_of!(GpuVplParams, flux_mix),
                    offset_of!(GpuVplParams, epsilon),
                    offset_of!(GpuVplParams, per_layer),
                    offset_of!(GpuVplParams, _pad),
                    offset_of!(GpuVplParams, _pad) + 4,
                    offset_of!(GpuVplParams, ranges),
                    offset_of!(GpuVplParams, level_offsets),
                ],
            ),
            (
                "light_paths.wgsl",
                "PathParams",
                size_of::<crate::renderer::passes::light_paths::GpuPathParams>(),
                {
                    use crate::renderer::passes::light_paths::GpuPathParams as P;
                    vec![
                        offset_of!(P, paths),
                        offset_of!(P, first),
                        offset_of!(P, bounces),
                        offset_of!(P, roulette),
                        offset_of!(P, seed),
                        offset_of!(P, ray_offset),
                        offset_of!(P, lod),
                        offset_of!(P, flux_scale),
                        offset_of!(P, light_count),
                        offset_of!(P, flux_mix),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                        offset_of!(P, ranges),
                    ]
                },
            ),
            (
                "vpl_gen.wgsl",
                "Vpl",
                size_of::<GpuVpl>(),
                vec![
                    offset_of!(GpuVpl, position),
                    offset_of!(GpuVpl, normal),
                    offset_of!(GpuVpl, id),
                    offset_of!(GpuVpl, flux),
                ],
            ),
            (
                "methods/lightcuts/lc_build.wgsl",
                "LcBuildParams",
                size_of::<crate::methods::lightcuts::pass::GpuLcBuildParams>(),
                {
                    use crate::methods::lightcuts::pass::GpuLcBuildParams as P;
                    vec![
                        offset_of!(P, first),
                        offset_of!(P, count),
                        offset_of!(P, leaves),
                        offset_of!(P, seed),
                    ]
                },
            ),
            (
                "methods/lightcuts/lightcuts.wgsl",
                "LcParams",
                size_of::<crate::methods::lightcuts::pass::GpuLcParams>(),
                {
                    use crate::methods::lightcuts::pass::GpuLcParams as P;
                    vec![
                        offset_of!(P, width),
                        offset_of!(P, height),
                        offset_of!(P, leaves),
                        offset_of!(P, max_cut),
                        offset_of!(P, relative_error),
                        offset_of!(P, epsilon),
                        offset_of!(P, ray_offset),
                        offset_of!(P, shadow_rays),
                        offset_of!(P, accumulate),
                        offset_of!(P, trace_pixel),
                        offset_of!(P, first_pixel),
                        offset_of!(P, slice),
                        offset_of!(P, first),
                        offset_of!(P, last),
                        offset_of!(P, steps),
                        offset_of!(P, radix),
                        offset_of!(P, brdf),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                        offset_of!(P, _pad) + 8,
                        offset_of!(P, eye),
                    ]
                },
            ),
            (
                "methods/lightcuts/lc_views.wgsl",
                "LcViewParams",
                size_of::<crate::methods::lightcuts::pass::GpuLcViewParams>(),
                {
                    use crate::methods::lightcuts::pass::GpuLcViewParams as P;
                    vec![
                        offset_of!(P, mode),
                        offset_of!(P, scale_top),
                        offset_of!(P, relative_error),
                        offset_of!(P, exposure),
                        offset_of!(P, tonemap),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                        offset_of!(P, _pad) + 8,
                    ]
                },
            ),
            (
                "methods/lightcut_interpolation/li_interp.wgsl",
                "LiParams",
                size_of::<crate::methods::lightcut_interpolation::pass::GpuLiParams>(),
                {
                    use crate::methods::lightcut_interpolation::pass::GpuLiParams as P;
                    vec![
                        offset_of!(P, width),
                        offset_of!(P, height),
                        offset_of!(P, tiles_x),
                        offset_of!(P, tiles_y),
                        offset_of!(P, leaves),
                        offset_of!(P, levels),
                        offset_of!(P, max_cut),
                        offset_of!(P, capacity),
                        offset_of!(P, r_min_px),
                        offset_of!(P, r_max_px),
                        offset_of!(P, one_minus_cos_max),
                        offset_of!(P, epsilon),
                        offset_of!(P, coverage),
                        offset_of!(P, radius_rays),
                        offset_of!(P, ray_offset),
                        offset_of!(P, shadow_rays),
                        offset_of!(P, interp_visibility),
                        offset_of!(P, accumulate),
                        offset_of!(P, trace_pixel),
                        offset_of!(P, steps),
                        offset_of!(P, first),
                        offset_of!(P, last),
                        offset_of!(P, distance_epsilon),
                        offset_of!(P, _pad),
                    ]
                },
            ),
            (
                "methods/lightcut_interpolation/li_views.wgsl",
                "LiViewParams",
                size_of::<crate::methods::lightcut_interpolation::pass::GpuLiViewParams>(),
                {
                    use crate::methods::lightcut_interpolation::pass::GpuLiViewParams as P;
                    vec![
                        offset_of!(P, mode),
                        offset_of!(P, scale_top),
                        offset_of!(P, r_min_px),
                        offset_of!(P, r_max_px),
                        offset_of!(P, exposure),
                        offset_of!(P, tonemap),
                        offset_of!(P, tiles_x),
                        offset_of!(P, tiles_y),
                        offset_of!(P, pinned),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                        offset_of!(P, _pad) + 8,
                    ]
                },
            ),
            (
                "methods/light_culling/lcull_ranges.wgsl",
                "LcullParams",
                size_of::<crate::methods::light_culling::pass::GpuLcullParams>(),
                {
                    use crate::methods::light_culling::pass::GpuLcullParams as P;
                    vec![
                        offset_of!(P, width),
                        offset_of!(P, height),
                        offset_of!(P, tile),
                        offset_of!(P, n),
                        offset_of!(P, tiles_x),
                        offset_of!(P, tiles_y),
                        offset_of!(P, tiles),
                        offset_of!(P, cap),
                        offset_of!(P, count),
                        offset_of!(P, offset),
                        offset_of!(P, seed),
                        offset_of!(P, mode),
                        offset_of!(P, epsilon_max),
                        offset_of!(P, exposure),
                        offset_of!(P, eps),
                        offset_of!(P, ray_offset),
                        offset_of!(P, shadow_rays),
                        offset_of!(P, stride),
                        offset_of!(P, leaves),
                        offset_of!(P, ism_flags),
                        offset_of!(P, brdf),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                        offset_of!(P, _pad) + 8,
                        offset_of!(P, eye),
                    ]
                },
            ),
            (
                "ism.wgsl",
                "IsmParams",
                size_of::<crate::renderer::passes::ism::GpuIsmParams>(),
                {
                    use crate::renderer::passes::ism::GpuIsmParams as P;
                    vec![
                        offset_of!(P, atlas),
                        offset_of!(P, tile),
                        offset_of!(P, per_row),
                        offset_of!(P, lights),
                        offset_of!(P, points),
                        offset_of!(P, level),
                        offset_of!(P, bias),
                        offset_of!(P, level_base),
                        offset_of!(P, per_light),
                        offset_of!(P, threads),
                        offset_of!(P, front_cull),
                        offset_of!(P, point_radius),
                    ]
                },
            ),
            (
                "val_cluster.wgsl",
                "ValParams",
                size_of::<crate::renderer::passes::val_cluster::GpuValParams>(),
                {
                    use crate::renderer::passes::val_cluster::GpuValParams as P;
                    vec![
                        offset_of!(P, view_proj),
                        offset_of!(P, light_dir),
                        offset_of!(P, texel_area),
                        offset_of!(P, res),
                        offset_of!(P, clusters),
                        offset_of!(P, splat),
                        offset_of!(P, layer),
                        offset_of!(P, w_p),
                        offset_of!(P, w_n),
                        offset_of!(P, w_f),
                        offset_of!(P, extent),
                        offset_of!(P, area_mode),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                        offset_of!(P, _pad) + 8,
                    ]
                },
            ),
            (
                "methods/val/val_shade.wgsl",
                "ValShadeParams",
                size_of::<crate::methods::val::pass::GpuValShadeParams>(),
                {
                    use crate::methods::val::pass::GpuValShadeParams as P;
                    vec![
                        offset_of!(P, width),
                        offset_of!(P, height),
                        offset_of!(P, n),
                        offset_of!(P, offset),
                        offset_of!(P, clusters),
                        offset_of!(P, as_point),
                        offset_of!(P, visibility),
                        offset_of!(P, count),
                        offset_of!(P, eps),
                        offset_of!(P, ray_offset),
                        offset_of!(P, blocker_samples),
                        offset_of!(P, pcf_samples),
                        offset_of!(P, max_radius),
                        offset_of!(P, res),
                        offset_of!(P, layer),
                        offset_of!(P, inspect),
                        offset_of!(P, factor),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                        offset_of!(P, _pad) + 8,
                    ]
                },
            ),
            (
                "methods/val/val_shade.wgsl",
                "Val",
                size_of::<crate::renderer::passes::val_cluster::GpuVal>(),
                {
                    use crate::renderer::passes::val_cluster::GpuVal as P;
                    vec![
                        offset_of!(P, position),
                        offset_of!(P, area),
                        offset_of!(P, normal),
                        offset_of!(P, pixels),
                        offset_of!(P, flux),
                        offset_of!(P, texel),
                    ]
                },
            ),
            (
                "methods/val/val_views.wgsl",
                "ValViewParams",
                size_of::<crate::methods::val::pass::GpuValViewParams>(),
                {
                    use crate::methods::val::pass::GpuValViewParams as P;
                    vec![
                        offset_of!(P, mode),
                        offset_of!(P, clusters),
                        offset_of!(P, exposure),
                        offset_of!(P, tonemap),
                        offset_of!(P, lo),
                        offset_of!(P, hi),
                        offset_of!(P, inspect),
                        offset_of!(P, gap),
                        offset_of!(P, ray_offset),
                        offset_of!(P, res),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                    ]
                },
            ),
            (
                "methods/val/val_downsample.wgsl",
                "DownParams",
                size_of::<crate::methods::val::pass::GpuDownParams>(),
                {
                    use crate::methods::val::pass::GpuDownParams as P;
                    vec![
                        offset_of!(P, res),
                        offset_of!(P, factor),
                        offset_of!(P, layer),
                        offset_of!(P, _pad),
                        offset_of!(P, light_dir),
                        offset_of!(P, texel_area),
                    ]
                },
            ),
            (
                "val_cluster.wgsl",
                "Val",
                size_of::<crate::renderer::passes::val_cluster::GpuVal>(),
                {
                    use crate::renderer::passes::val_cluster::GpuVal as P;
                    vec![
                        offset_of!(P, position),
                        offset_of!(P, area),
                        offset_of!(P, normal),
                        offset_of!(P, pixels),
                        offset_of!(P, flux),
                        offset_of!(P, texel),
                    ]
                },
            ),
            (
                "ism_view.wgsl",
                "IsmViewParams",
                size_of::<crate::renderer::passes::ism::GpuIsmViewParams>(),
                {
                    use crate::renderer::passes::ism::GpuIsmViewParams as P;
                    vec![
                        offset_of!(P, atlas),
                        offset_of!(P, tile),
                        offset_of!(P, per_row),
                        offset_of!(P, maps),
                        offset_of!(P, lo),
                        offset_of!(P, hi),
                        offset_of!(P, scale),
                        offset_of!(P, cols),
                    ]
                },
            ),
            (
                "interleave_filter.wgsl",
                "FilterParams",
                size_of::<crate::renderer::passes::interleave_filter::GpuFilterParams>(),
                {
                    use crate::renderer::passes::interleave_filter::GpuFilterParams as P;
                    vec![
                        offset_of!(P, width),
                        offset_of!(P, height),
                        offset_of!(P, radius),
                        offset_of!(P, accumulate),
                        offset_of!(P, normal_cos),
                        offset_of!(P, plane_tolerance),
                        offset_of!(P, scale),
                        offset_of!(P, modulate),
                        offset_of!(P, period),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                        offset_of!(P, _pad) + 8,
                    ]
                },
            ),
            (
                "methods/light_culling/lcull_views.wgsl",
                "LcullViewParams",
                size_of::<crate::methods::light_culling::pass::GpuLcullViewParams>(),
                {
                    use crate::methods::light_culling::pass::GpuLcullViewParams as P;
                    vec![
                        offset_of!(P, mode),
                        offset_of!(P, scale_top),
                        offset_of!(P, exposure),
                        offset_of!(P, tonemap),
                        offset_of!(P, n),
                        offset_of!(P, cap),
                        offset_of!(P, own_scale),
                        offset_of!(P, companion_scale),
                        offset_of!(P, own_is_clamped),
                        offset_of!(P, range),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                    ]
                },
            ),
            (
                "methods/ground_truth/ground_truth.wgsl",
                "GtParams",
                size_of::<GpuGtParams>(),
                vec![
                    offset_of!(GpuGtParams, begin),
                    offset_of!(GpuGtParams, end),
                    offset_of!(GpuGtParams, width),
                    offset_of!(GpuGtParams, height),
                    offset_of!(GpuGtParams, epsilon),
                    offset_of!(GpuGtParams, ray_offset),
                    offset_of!(GpuGtParams, shadow_rays),
                    offset_of!(GpuGtParams, brdf),
                    offset_of!(GpuGtParams, eye),
                    offset_of!(GpuGtParams, order),
                ],
            ),
            (
                "methods/tree_samplers/slc_sample.wgsl",
                "SlcParams",
                size_of::<GpuSlcParams>(),
                vec![
                    offset_of!(GpuSlcParams, width),
                    offset_of!(GpuSlcParams, height),
                    offset_of!(GpuSlcParams, block),
                    offset_of!(GpuSlcParams, grid_x),
                    offset_of!(GpuSlcParams, grid_y),
                    offset_of!(GpuSlcParams, cut_size),
                    offset_of!(GpuSlcParams, leaves),
                    offset_of!(GpuSlcParams, levels),
                    offset_of!(GpuSlcParams, method),
                    offset_of!(GpuSlcParams, blending),
                    offset_of!(GpuSlcParams, fallback),
                    offset_of!(GpuSlcParams, cull),
                    offset_of!(GpuSlcParams, seed),
                    offset_of!(GpuSlcParams, accumulate),
                    offset_of!(GpuSlcParams, epsilon),
                    offset_of!(GpuSlcParams, ray_offset),
                    offset_of!(GpuSlcParams, n_min),
                    offset_of!(GpuSlcParams, d_max),
                    offset_of!(GpuSlcParams, demodulate),
                    offset_of!(GpuSlcParams, trace_pixel),
                    offset_of!(GpuSlcParams, near_field),
                    offset_of!(GpuSlcParams, shadow_rays),
                    offset_of!(GpuSlcParams, substitute_offset),
                    offset_of!(GpuSlcParams, child_probability),
                    offset_of!(GpuSlcParams, interleave),
                    offset_of!(GpuSlcParams, interleave_offset),
                    offset_of!(GpuSlcParams, radix),
                    offset_of!(GpuSlcParams, brdf),
                    offset_of!(GpuSlcParams, glossy_material),
                    offset_of!(GpuSlcParams, _pad),
                    offset_of!(GpuSlcParams, _pad) + 4,
                    offset_of!(GpuSlcParams, _pad) + 8,
                    offset_of!(GpuSlcParams, eye),
                ],
            ),
            (
                "sst_overlay.wgsl",
                "OverlayParams",
                size_of::<crate::renderer::passes::sst_overlay::GpuOverlayParams>(),
                {
                    use crate::renderer::passes::sst_overlay::GpuOverlayParams as P;
                    vec![
                        offset_of!(P, level),
                        offset_of!(P, color_mode),
                        offset_of!(P, min_radius),
                        offset_of!(P, radix),
                        offset_of!(P, leaves),
                        offset_of!(P, _pad),
                        offset_of!(P, _pad) + 4,
                        offset_of!(P, _pad) + 8,
                    ]
                },
            ),
            (
                "sst_build.wgsl",
                "SstNode",
                size_of::<GpuSstNode>(),
                vec![
                    offset_of!(GpuSstNode, position),
                    offset_of!(GpuSstNode, v),
                    offset_of!(GpuSstNode, intensity),
                    offset_of!(GpuSstNode, normal),
                    offset_of!(GpuSstNode, bbox_min),
                    offset_of!(GpuSstNode, var_z),
                    offset_of!(GpuSstNode, bbox_max),
                    offset_of!(GpuSstNode, var_xy),
                ],
            ),
            (
                "bvh_rays.wgsl",
                "RayIn",
                size_of::<GpuRay>(),
                vec![offset_of!(GpuRay, origin), offset_of!(GpuRay, dir)],
            ),
            (
                "bvh_rays.wgsl",
                "HitOut",
                size_of::<GpuHit>(),
                vec![
                    offset_of!(GpuHit, t),
                    offset_of!(GpuHit, triangle),
                    offset_of!(GpuHit, u),
                    offset_of!(GpuHit, v),
                ],
            ),
        ];
        for (file, name, size, offsets) in cases {
            let (wsize, woffsets) = wgsl_layout(file, name);
            assert_eq!(wsize as usize, size, "size of {name} ({file})");
            let woffsets: Vec<usize> = woffsets.into_iter().map(|o| o as usize).collect();
            assert_eq!(woffsets, offsets, "member offsets of {name} ({file})");
        }
    }

    #[test]
    fn light_frustum_contains_bounds() {
        let b = Aabb {
            min: Vec3::new(-1.0, 0.0, -2.0),
            max: Vec3::new(3.0, 2.0, 1.0),
        };
        let dir = Vec3::new(0.3, -1.0, 0.2).normalize();
        let (vp, texel, range) = light_frustum(dir, &b, 512);
        assert!(texel > 0.0 && range > 0.0);
        for i in 0..8 {
            let p = Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            let q = vp.project_point3(p);
            assert!(q.x.abs() < 1.0 && q.y.abs() < 1.0, "{q}");
            assert!(q.z > 0.0 && q.z < 1.0, "{q}");
        }
        // Points further along the light direction are deeper.
        let a = vp.project_point3(b.center());
        let c = vp.project_point3(b.center() + 0.1 * dir);
        assert!(c.z > a.z);
    }
}
