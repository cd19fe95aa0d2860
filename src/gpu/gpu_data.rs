//! The shared passes' `#[repr(C)]` parameter structs shared with WGSL. Each has a twin in
//! `shaders/`, listed in [`TWINS`] (a method's structs are in its folder, listed in its
//! `Module::wgsl_twins`); [`check_twin`] compares sizes and member offsets with naga's
//! layout of the WGSL struct (`tests::layouts_match_wgsl` here, the registry test for the
//! methods'), so the two cannot drift apart silently.

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
    pub fn new(look: &crate::gpu::views::ViewLook) -> Self {
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

/// A `#[repr(C)]` struct and the WGSL struct it mirrors (`wgsl_twin!`): [`check_twin`]
/// compares its size and member offsets with naga's layout. The shared passes' are in
/// [`TWINS`], each method's in its `Module::wgsl_twins` beside its structs; one test walks
/// them all.
pub struct WgslTwin {
    /// The WGSL file (under `shaders/`) that declares it.
    pub file: &'static str,
    /// The WGSL struct's name.
    pub name: &'static str,
    pub size: usize,
    /// The Rust members' offsets in the WGSL members' order.
    pub offsets: fn() -> Vec<usize>,
}

/// `wgsl_twin!(RustType, "file.wgsl", "WgslName", [field, field, _pad, _pad + 4])`: a
/// [`WgslTwin`] (an array member's later elements as `field + byte offset`).
#[macro_export]
macro_rules! wgsl_twin {
    ($t:ty, $file:expr, $name:expr, [$($f:ident $(+ $k:literal)?),* $(,)?]) => {
        $crate::gpu::gpu_data::WgslTwin {
            file: $file,
            name: $name,
            size: std::mem::size_of::<$t>(),
            offsets: || vec![$(std::mem::offset_of!($t, $f) $(+ $k)?),*],
        }
    };
}

/// Whether `t`'s size and member offsets are naga's for its WGSL struct; the message names
/// the struct and file.
pub fn check_twin(t: &WgslTwin) -> Result<(), String> {
    use crate::gpu::shaders::{Embedded, preprocess, validate};
    let text = preprocess(&Embedded, t.file).map_err(|e| e.to_string())?;
    let module = validate(t.file, &text).map_err(|e| e.to_string())?;
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).map_err(|e| e.to_string())?;
    for (handle, ty) in module.types.iter() {
        if ty.name.as_deref() == Some(t.name)
            && let naga::TypeInner::Struct { members, span } = &ty.inner
        {
            if layouter[handle].size != *span {
                return Err(format!(
                    "{} ({}): naga's layout size {} differs from the struct's span {span}",
                    t.name, t.file, layouter[handle].size
                ));
            }
            let size = *span as usize;
            let offsets: Vec<usize> = members.iter().map(|m| m.offset as usize).collect();
            if size != t.size {
                return Err(format!(
                    "size of {} ({}): WGSL {size}, Rust {}",
                    t.name, t.file, t.size
                ));
            }
            let rust = (t.offsets)();
            if offsets != rust {
                return Err(format!(
                    "member offsets of {} ({}): WGSL {offsets:?}, Rust {rust:?}",
                    t.name, t.file
                ));
            }
            return Ok(());
        }
    }
    Err(format!("struct {} not found in {}", t.name, t.file))
}

/// The shared passes' structs shared with WGSL.
pub static TWINS: &[WgslTwin] = &[
    crate::wgsl_twin!(
        crate::gpu::passes::compare::GpuCmpParams,
        "compare_views.wgsl",
        "CmpParams",
        [
            mode,
            split_x,
            exposure,
            tonemap,
            diff_scale,
            _pad,
            _pad + 4,
            _pad + 8
        ]
    ),
    crate::wgsl_twin!(
        GpuCamera,
        "direct.wgsl",
        "Camera",
        [view_proj, position, forward, right, up, resolution]
    ),
    crate::wgsl_twin!(
        GpuDirectionalLight,
        "direct.wgsl",
        "DirectionalLight",
        [view_proj, direction, irradiance, shadow]
    ),
    crate::wgsl_twin!(GpuLights, "direct.wgsl", "Lights", [count, lights]),
    crate::wgsl_twin!(
        DisplayParams,
        "display.wgsl",
        "DisplayParams",
        [exposure, tonemap, channel, flags, lo, hi, _pad]
    ),
    crate::wgsl_twin!(
        VisParams,
        "visualise.wgsl",
        "VisParams",
        [mode, layer, _pad, range_min, range_max]
    ),
    crate::wgsl_twin!(
        GpuMaterial,
        "gbuffer.wgsl",
        "MaterialGpu",
        [base_color, texture, params, mr_uv]
    ),
    crate::wgsl_twin!(
        GpuVplParams,
        "vpl_gen.wgsl",
        "VplParams",
        [
            res,
            levels,
            light_count,
            vpl_count,
            samples,
            filter_radius,
            mode,
            seed,
            sample_radius,
            n_min,
            d_max,
            flux_mix,
            epsilon,
            per_layer,
            _pad,
            _pad + 4,
            ranges,
            level_offsets
        ]
    ),
    crate::wgsl_twin!(
        crate::gpu::passes::light_paths::GpuPathParams,
        "light_paths.wgsl",
        "PathParams",
        [
            paths,
            first,
            bounces,
            roulette,
            seed,
            ray_offset,
            lod,
            flux_scale,
            light_count,
            flux_mix,
            _pad,
            _pad + 4,
            ranges
        ]
    ),
    crate::wgsl_twin!(GpuVpl, "vpl_gen.wgsl", "Vpl", [position, normal, id, flux]),
    crate::wgsl_twin!(
        crate::gpu::passes::ism::GpuIsmParams,
        "ism.wgsl",
        "IsmParams",
        [
            atlas,
            tile,
            per_row,
            lights,
            points,
            level,
            bias,
            level_base,
            per_light,
            threads,
            front_cull,
            point_radius
        ]
    ),
    crate::wgsl_twin!(
        crate::gpu::passes::val_cluster::GpuValParams,
        "val_cluster.wgsl",
        "ValParams",
        [
            view_proj,
            light_dir,
            texel_area,
            res,
            clusters,
            splat,
            layer,
            w_p,
            w_n,
            w_f,
            extent,
            area_mode,
            _pad,
            _pad + 4,
            _pad + 8
        ]
    ),
    crate::wgsl_twin!(
        crate::gpu::passes::val_cluster::GpuVal,
        "val_cluster.wgsl",
        "Val",
        [position, area, normal, pixels, flux, texel]
    ),
    crate::wgsl_twin!(
        crate::gpu::passes::ism::GpuIsmViewParams,
        "ism_view.wgsl",
        "IsmViewParams",
        [atlas, tile, per_row, maps, lo, hi, scale, cols]
    ),
    crate::wgsl_twin!(
        crate::gpu::passes::interleave_filter::GpuFilterParams,
        "interleave_filter.wgsl",
        "FilterParams",
        [
            width,
            height,
            radius,
            accumulate,
            normal_cos,
            plane_tolerance,
            scale,
            modulate,
            period,
            _pad,
            _pad + 4,
            _pad + 8
        ]
    ),
    crate::wgsl_twin!(
        crate::gpu::passes::sst_overlay::GpuOverlayParams,
        "sst_overlay.wgsl",
        "OverlayParams",
        [
            level,
            color_mode,
            min_radius,
            radix,
            leaves,
            _pad,
            _pad + 4,
            _pad + 8
        ]
    ),
    crate::wgsl_twin!(
        GpuSstNode,
        "sst_build.wgsl",
        "SstNode",
        [position, v, intensity, normal, bbox_min, var_z, bbox_max, var_xy]
    ),
    crate::wgsl_twin!(GpuRay, "bvh_rays.wgsl", "RayIn", [origin, dir]),
    crate::wgsl_twin!(GpuHit, "bvh_rays.wgsl", "HitOut", [t, triangle, u, v]),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_match_wgsl() {
        for t in TWINS {
            if let Err(e) = check_twin(t) {
                panic!("{e}");
            }
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
