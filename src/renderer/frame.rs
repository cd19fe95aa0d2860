//! Frame resources: every texture the passes read and write, sized to the frame, plus the
//! shadow maps (sized by the shadow settings) and the view texture the UI shows.

use super::passes::{
    direct::RADIANCE_FORMAT,
    display::VIEW_FORMAT,
    gbuffer::{ALBEDO_FORMAT, DEPTH_FORMAT, NORMAL_FORMAT, POSITION_FORMAT},
};

fn texture(
    device: &wgpu::Device,
    label: &str,
    size: (u32, u32),
    layers: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size.0.max(1),
            height: size.1.max(1),
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

const READABLE: wgpu::TextureUsages =
    wgpu::TextureUsages::TEXTURE_BINDING.union(wgpu::TextureUsages::COPY_SRC);

/// The G-buffer (see `shaders/gbuffer.wgsl` for the channel layout).
pub struct GbufferTargets {
    pub position: wgpu::Texture,
    pub position_view: wgpu::TextureView,
    pub normal: wgpu::Texture,
    pub normal_view: wgpu::TextureView,
    pub albedo: wgpu::Texture,
    pub albedo_view: wgpu::TextureView,
    pub depth: wgpu::Texture,
    pub depth_view: wgpu::TextureView,
}

impl GbufferTargets {
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> Self {
        let rt = wgpu::TextureUsages::RENDER_ATTACHMENT | READABLE;
        let position = texture(device, "gbuffer::position", size, 1, POSITION_FORMAT, rt);
        let normal = texture(device, "gbuffer::normal", size, 1, NORMAL_FORMAT, rt);
        let albedo = texture(device, "gbuffer::albedo", size, 1, ALBEDO_FORMAT, rt);
        let depth = texture(device, "gbuffer::depth", size, 1, DEPTH_FORMAT, rt);
        Self {
            position_view: position.create_view(&Default::default()),
            normal_view: normal.create_view(&Default::default()),
            albedo_view: albedo.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            position,
            normal,
            albedo,
            depth,
        }
    }
}

/// Shadow maps: a depth texture array, one layer per light.
pub struct ShadowTargets {
    pub texture: wgpu::Texture,
    pub array_view: wgpu::TextureView,
    pub layer_views: Vec<wgpu::TextureView>,
    pub resolution: u32,
}

impl ShadowTargets {
    pub fn new(device: &wgpu::Device, resolution: u32, layers: u32) -> Self {
        let layers = layers.max(1);
        let tex = texture(
            device,
            "shadow_map::depth",
            (resolution, resolution),
            layers,
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | READABLE,
        );
        let layer_views = (0..layers)
            .map(|l| {
                tex.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("shadow_map::layer"),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: l,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        Self {
            array_view: tex.create_view(&wgpu::TextureViewDescriptor {
                label: Some("shadow_map::array"),
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            }),
            texture: tex,
            layer_views,
            resolution,
        }
    }
    pub fn layers(&self) -> u32 {
        self.layer_views.len() as u32
    }
}

/// Lighting buffers (linear radiance, W/(m^2 sr)).
pub struct LightingTargets {
    pub direct: wgpu::Texture,
    pub direct_view: wgpu::TextureView,
}

impl LightingTargets {
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> Self {
        let usage = wgpu::TextureUsages::STORAGE_BINDING | READABLE;
        let direct = texture(device, "direct::radiance", size, 1, RADIANCE_FORMAT, usage);
        Self {
            direct_view: direct.create_view(&Default::default()),
            direct,
        }
    }
}

/// The `Rgba8Unorm` image the UI shows (sized to the buffer being viewed).
pub struct ViewTarget {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    pub size: (u32, u32),
    /// Bumped whenever the texture is recreated (the UI re-registers it then).
    pub generation: u64,
}

impl ViewTarget {
    pub fn new(device: &wgpu::Device, size: (u32, u32), generation: u64) -> Self {
        let tex = texture(
            device,
            "view::rgba8",
            size,
            1,
            VIEW_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING | READABLE,
        );
        Self {
            view: tex.create_view(&Default::default()),
            texture: tex,
            size,
            generation,
        }
    }
}

/// Every per-frame resource.
pub struct FrameTargets {
    pub size: (u32, u32),
    pub gbuffer: GbufferTargets,
    pub shadow: ShadowTargets,
    pub lighting: LightingTargets,
    pub view: ViewTarget,
}

impl FrameTargets {
    pub fn new(device: &wgpu::Device, size: (u32, u32), shadow_res: u32, lights: u32) -> Self {
        Self {
            size,
            gbuffer: GbufferTargets::new(device, size),
            shadow: ShadowTargets::new(device, shadow_res, lights),
            lighting: LightingTargets::new(device, size),
            view: ViewTarget::new(device, size, 0),
        }
    }
}
