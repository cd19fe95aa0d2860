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
    /// A G-buffer written by compute (the half-resolution copy for half-resolution GI): the
    /// same formats, storage-writable; its depth texture is unused.
    pub fn new_compute(device: &wgpu::Device, size: (u32, u32)) -> Self {
        let st = wgpu::TextureUsages::STORAGE_BINDING | READABLE;
        let position = texture(device, "gbuffer_half::position", size, 1, POSITION_FORMAT, st);
        let normal = texture(device, "gbuffer_half::normal", size, 1, NORMAL_FORMAT, st);
        let albedo = texture(device, "gbuffer_half::albedo", size, 1, ALBEDO_FORMAT, st);
        let depth = texture(
            device,
            "gbuffer_half::depth",
            (1, 1),
            1,
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
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

/// Reflective shadow maps: one array layer per light of depth (the shadow map), world
/// position, normal and reflected flux (see `shaders/rsm.wgsl`).
pub struct ShadowTargets {
    pub texture: wgpu::Texture,
    pub array_view: wgpu::TextureView,
    pub layer_views: Vec<wgpu::TextureView>,
    pub position: wgpu::Texture,
    pub position_array: wgpu::TextureView,
    pub position_layers: Vec<wgpu::TextureView>,
    pub normal: wgpu::Texture,
    pub normal_array: wgpu::TextureView,
    pub normal_layers: Vec<wgpu::TextureView>,
    pub flux: wgpu::Texture,
    pub flux_array: wgpu::TextureView,
    pub flux_layers: Vec<wgpu::TextureView>,
    pub resolution: u32,
}

pub const RSM_POSITION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub const RSM_NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Flux in watts (albedo x E x texel area), in half floats: 6e-8..65504 W a texel, which a scene
/// of metres holds (`Scene::scale_warnings` names the scales that it does not).
pub const RSM_FLUX_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

fn array_and_layers(
    tex: &wgpu::Texture,
    label: &str,
    layers: u32,
) -> (wgpu::TextureView, Vec<wgpu::TextureView>) {
    let array = tex.create_view(&wgpu::TextureViewDescriptor {
        label: Some(label),
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let per_layer = (0..layers)
        .map(|l| {
            tex.create_view(&wgpu::TextureViewDescriptor {
                label: Some(label),
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: l,
                array_layer_count: Some(1),
                ..Default::default()
            })
        })
        .collect();
    (array, per_layer)
}

impl ShadowTargets {
    pub fn new(device: &wgpu::Device, resolution: u32, layers: u32) -> Self {
        let layers = layers.max(1);
        let size = (resolution, resolution);
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | READABLE;
        let depth = texture(device, "rsm::depth", size, layers, DEPTH_FORMAT, usage);
        let position = texture(device, "rsm::position", size, layers, RSM_POSITION_FORMAT, usage);
        let normal = texture(device, "rsm::normal", size, layers, RSM_NORMAL_FORMAT, usage);
        let flux = texture(device, "rsm::flux", size, layers, RSM_FLUX_FORMAT, usage);
        let (array_view, layer_views) = array_and_layers(&depth, "rsm::depth_view", layers);
        let (position_array, position_layers) = array_and_layers(&position, "rsm::position_view", layers);
        let (normal_array, normal_layers) = array_and_layers(&normal, "rsm::normal_view", layers);
        let (flux_array, flux_layers) = array_and_layers(&flux, "rsm::flux_view", layers);
        Self {
            texture: depth,
            array_view,
            layer_views,
            position,
            position_array,
            position_layers,
            normal,
            normal_array,
            normal_layers,
            flux,
            flux_array,
            flux_layers,
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
    /// Indirect (one-bounce) radiance of the selected GI method.
    pub indirect: wgpu::Texture,
    pub indirect_view: wgpu::TextureView,
    /// direct + indirect.
    pub final_: wgpu::Texture,
    pub final_view: wgpu::TextureView,
    /// Per-pixel rgb sums the GI method accumulates (vec4 per pixel).
    pub gi_accum: wgpu::Buffer,
}

impl LightingTargets {
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> Self {
        let usage = wgpu::TextureUsages::STORAGE_BINDING | READABLE;
        let direct = texture(device, "direct::radiance", size, 1, RADIANCE_FORMAT, usage);
        let indirect = texture(device, "composite::indirect", size, 1, RADIANCE_FORMAT, usage);
        let final_ = texture(device, "composite::final", size, 1, RADIANCE_FORMAT, usage);
        Self {
            direct_view: direct.create_view(&Default::default()),
            direct,
            indirect_view: indirect.create_view(&Default::default()),
            indirect,
            final_view: final_.create_view(&Default::default()),
            final_,
            gi_accum: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gi::accum"),
                size: 16 * (size.0.max(1) as u64) * (size.1.max(1) as u64),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
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
            // Render attachment: overlays (the light tree) are drawn into it with blending.
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT | READABLE,
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
