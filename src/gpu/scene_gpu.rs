//! The scene on the GPU: vertices, materials, the texture array (base colour and
//! metallic-roughness layers), the BVH.

use glam::Vec3;
use wgpu::util::DeviceExt;

use super::gpu_data::{GpuMaterial, GpuVertex};
use crate::scene::{Aabb, Bvh, Scene, TextureImage, bvh::WideBvh};

pub struct SceneGpu {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    /// The same triangles in reverse order: the G-buffer's shading pass after the depth
    /// pre-pass draws them so, so that among triangles at exactly the same depth the first in
    /// file order wins, as in a single pass with depth test Less.
    pub indices_reversed: wgpu::Buffer,
    pub index_count: u32,
    pub materials: wgpu::Buffer,
    pub textures: wgpu::Texture,
    pub textures_view: wgpu::TextureView,
    pub sampler: wgpu::Sampler,
    pub bvh_nodes: wgpu::Buffer,
    pub bvh_triangles: wgpu::Buffer,
    pub bounds: Aabb,
    pub triangle_count: usize,
    pub bvh: Bvh,
    /// Unique per scene upload: what a method derived from the scene (a point cloud) is
    /// rebuilt when it changes.
    pub generation: u64,
}

static GENERATION: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);

/// Builds the GPU vertex list: one material id per vertex, duplicating a vertex where
/// triangles of different materials share it.
pub fn build_vertices(scene: &Scene) -> (Vec<GpuVertex>, Vec<u32>) {
    let mut verts: Vec<GpuVertex> = scene
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| GpuVertex {
            position: p.to_array(),
            normal: scene.normals.get(i).copied().unwrap_or(Vec3::Y).to_array(),
            uv: scene.uvs.get(i).map(|u| u.to_array()).unwrap_or([0.0; 2]),
            material: u32::MAX,
        })
        .collect();
    let mut indices = scene.indices.clone();
    for t in 0..scene.triangle_count() {
        let m = scene.triangle_materials.get(t).copied().unwrap_or(0);
        for k in 0..3 {
            let vi = indices[3 * t + k] as usize;
            if verts[vi].material == u32::MAX {
                verts[vi].material = m;
            } else if verts[vi].material != m {
                let mut v = verts[vi];
                v.material = m;
                indices[3 * t + k] = verts.len() as u32;
                verts.push(v);
            }
        }
    }
    for v in &mut verts {
        if v.material == u32::MAX {
            v.material = 0;
        }
    }
    (verts, indices)
}

fn linear_to_srgb8(x: f32) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let s = if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

/// Resamples `tex` to `size` x `size` and builds its mip chain (box filter in linear space,
/// alpha linear). Returns one RGBA8 (sRGB) buffer per level.
pub fn texture_mips(tex: &TextureImage, size: u32) -> Vec<Vec<u8>> {
    let base = if tex.width == size && tex.height == size {
        tex.rgba8.clone()
    } else {
        match image::RgbaImage::from_raw(tex.width, tex.height, tex.rgba8.clone()) {
            Some(img) => {
                image::imageops::resize(&img, size, size, image::imageops::FilterType::Triangle).into_raw()
            }
            None => vec![255; (size * size * 4) as usize],
        }
    };
    let mut levels = vec![base];
    let mut s = size;
    let lut: Vec<f32> = (0..=255u8).map(crate::base::display::srgb8_to_linear).collect();
    while s > 1 {
        let prev = levels.last().map(|v| v.as_slice()).unwrap_or(&[]);
        let n = s / 2;
        let mut next = vec![0u8; (n * n * 4) as usize];
        for y in 0..n {
            for x in 0..n {
                let mut acc = [0f32; 4];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let i = (((2 * y + dy) * s + 2 * x + dx) * 4) as usize;
                    for c in 0..3 {
                        acc[c] += lut[prev[i + c] as usize];
                    }
                    acc[3] += prev[i + 3] as f32;
                }
                let o = ((y * n + x) * 4) as usize;
                for c in 0..3 {
                    next[o + c] = linear_to_srgb8(acc[c] * 0.25);
                }
                next[o + 3] = (acc[3] * 0.25 + 0.5) as u8;
            }
        }
        levels.push(next);
        s = n;
    }
    levels
}

impl SceneGpu {
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        max_texture_size: u32,
        anisotropy: u16,
    ) -> Self {
        let (verts, indices) = build_vertices(scene);
        let verts = if verts.is_empty() {
            vec![bytemuck::Zeroable::zeroed()]
        } else {
            verts
        };
        let index_count = indices.len() as u32;
        let indices = if indices.is_empty() {
            vec![0u32; 3]
        } else {
            indices
        };
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene::vertices"),
            contents: bytemuck::cast_slice(&verts),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE,
        });
        let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene::indices"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::STORAGE,
        });
        let reversed: Vec<u32> = indices.chunks(3).rev().flatten().copied().collect();
        let indices_reversed = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene::indices_reversed"),
            contents: bytemuck::cast_slice(&reversed),
            usage: wgpu::BufferUsages::INDEX,
        });

        let (textures, textures_view) = upload_textures(device, queue, scene, max_texture_size);
        let sampler = texture_sampler(device, anisotropy);

        let materials = upload_materials(device, scene);

        let bvh = Bvh::build(&scene.positions, &scene.indices);
        let (bvh_nodes, bvh_triangles) = match frame_bvh_layout() {
            BvhLayout::Binary => upload_bvh(device, &bvh),
            BvhLayout::Wide => upload_wide_bvh(device, &WideBvh::from_binary(&bvh)),
        };
        SceneGpu {
            vertices,
            indices: index_buffer,
            indices_reversed,
            index_count,
            materials,
            textures,
            textures_view,
            sampler,
            bvh_nodes,
            bvh_triangles,
            bounds: scene.bounds,
            triangle_count: scene.triangle_count(),
            bvh,
            generation: GENERATION.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
        }
    }
}

/// Every base-colour texture resampled to one power-of-two size (at most `max_texture_size`
/// and the device's limit) with its mips, as one texture array, and its view.
fn upload_textures(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &Scene,
    max_texture_size: u32,
) -> (wgpu::Texture, wgpu::TextureView) {
    let limit = device
        .limits()
        .max_texture_dimension_2d
        .min(max_texture_size.max(1));
    let largest = scene
        .textures
        .iter()
        .map(|t| t.width.max(t.height))
        .max()
        .unwrap_or(1)
        .max(1);
    let size = largest
        .min(limit)
        .next_power_of_two()
        .min(limit.next_power_of_two());
    let size = if size > limit { size / 2 } else { size }.max(1);
    let layers = scene.textures.len().max(1) as u32;
    let mip_count = 32 - size.leading_zeros();
    let textures = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("scene::base_color_textures"),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: layers,
        },
        mip_level_count: mip_count,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let white = TextureImage {
        name: "white".into(),
        width: 1,
        height: 1,
        rgba8: vec![255; 4],
    };
    let sources: Vec<&TextureImage> = if scene.textures.is_empty() {
        vec![&white]
    } else {
        scene.textures.iter().collect()
    };
    // Resample/mip in parallel (2 threads are common here), upload in order.
    let all_mips: Vec<Vec<Vec<u8>>> = std::thread::scope(|s| {
        let threads = std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(2)
            .min(8);
        let chunk = sources.len().div_ceil(threads).max(1);
        let handles: Vec<_> = sources
            .chunks(chunk)
            .map(|c| s.spawn(move || c.iter().map(|t| texture_mips(t, size)).collect::<Vec<_>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_default())
            .collect()
    });
    for (layer, mips) in all_mips.iter().enumerate() {
        for (level, data) in mips.iter().enumerate() {
            let s = (size >> level).max(1);
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &textures,
                    mip_level: level as u32,
                    origin: wgpu::Origin3d {
                        x: 0,
                        y: 0,
                        z: layer as u32,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                data,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * s),
                    rows_per_image: Some(s),
                },
                wgpu::Extent3d {
                    width: s,
                    height: s,
                    depth_or_array_layers: 1,
                },
            );
        }
    }
    let textures_view = textures.create_view(&wgpu::TextureViewDescriptor {
        label: Some("scene::base_color_textures_view"),
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    (textures, textures_view)
}

/// The scene's materials (a grey one when it has none), texture indices into the array.
fn upload_materials(device: &wgpu::Device, scene: &Scene) -> wgpu::Buffer {
    let layer = |t: Option<usize>| {
        t.filter(|&t| t < scene.textures.len())
            .map(|t| t as i32)
            .unwrap_or(-1)
    };
    let mut mats: Vec<GpuMaterial> = scene
        .materials
        .iter()
        .map(|m| GpuMaterial {
            base_color: m.base_color_factor,
            texture: [
                layer(m.base_color_texture),
                layer(m.roughness_texture),
                layer(m.metallic_texture),
                0,
            ],
            // In [0, 1] whatever built the scene (the GGX bounds assume alpha <= 1).
            params: [m.metallic.clamp(0.0, 1.0), m.roughness.clamp(0.0, 1.0), 0.0, 0.0],
            mr_uv: m.metal_rough_uv.map(|[a, b, c]| [a, b, c, 0.0]),
        })
        .collect();
    if mats.is_empty() {
        mats.push(GpuMaterial {
            base_color: [0.8, 0.8, 0.8, 1.0],
            texture: [-1, -1, -1, 0],
            params: [0.0, 1.0, 0.0, 0.0],
            mr_uv: crate::scene::UV_IDENTITY.map(|[a, b, c]| [a, b, c, 0.0]),
        });
    }
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("scene::materials"),
        contents: bytemuck::cast_slice(&mats),
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// The base-colour sampler: repeat, trilinear, `anisotropy`x anisotropic (1..=16).
pub fn texture_sampler(device: &wgpu::Device, anisotropy: u16) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("scene::sampler"),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        address_mode_w: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        anisotropy_clamp: anisotropy.clamp(1, 16),
        ..Default::default()
    })
}

/// The BVH layout that frames trace: the binned-SAH binary BVH (`common/bvh_binary.wgsl`, the
/// default: on an NVIDIA H200 its in-frame shadow rays ran 1.7x faster than the wide one's,
/// docs/measurements/h200-2026-11-27-wide-bvh) or the compressed 8-wide BVH collapsed from it
/// (`common/bvh_wide.wgsl`; `LIGHTCUT_BVH=wide`). `bench rays` measures both in one run.
/// Process-wide: it decides what `SceneGpu::new` uploads and which file
/// `#include "common/bvh.wgsl"` reads (`shaders::preprocess`), so set it before creating a
/// renderer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BvhLayout {
    Wide,
    Binary,
}

impl BvhLayout {
    /// `wide` / `binary` (the `LIGHTCUT_BVH` environment variable's values).
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "wide" => Some(Self::Wide),
            "binary" => Some(Self::Binary),
            _ => None,
        }
    }
}

static WIDE_FRAMES: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// See [`BvhLayout`].
pub fn set_frame_bvh_layout(layout: BvhLayout) {
    WIDE_FRAMES.store(layout == BvhLayout::Wide, std::sync::atomic::Ordering::Relaxed);
}

/// See [`BvhLayout`].
pub fn frame_bvh_layout() -> BvhLayout {
    if WIDE_FRAMES.load(std::sync::atomic::Ordering::Relaxed) {
        BvhLayout::Wide
    } else {
        BvhLayout::Binary
    }
}

/// Uploads the binary BVH's nodes and triangles (what `common/bvh_binary.wgsl` reads) as
/// storage buffers.
pub fn upload_bvh(device: &wgpu::Device, bvh: &Bvh) -> (wgpu::Buffer, wgpu::Buffer) {
    upload_bvh_bytes(device, bytemuck::cast_slice(&bvh.nodes), &bvh.triangles)
}

/// Uploads the wide BVH (what `common/bvh_wide.wgsl` reads).
pub fn upload_wide_bvh(device: &wgpu::Device, bvh: &WideBvh) -> (wgpu::Buffer, wgpu::Buffer) {
    upload_bvh_bytes(device, bytemuck::cast_slice(&bvh.nodes), &bvh.triangles)
}

/// Node and triangle buffers, never empty: wgpu forbids zero-sized bindings, so an empty BVH
/// gets one inert (all-zero) element each (a zero wide node has no children; a zero binary
/// node is never read past the root test of an empty box).
fn upload_bvh_bytes(
    device: &wgpu::Device,
    nodes: &[u8],
    triangles: &[crate::scene::bvh::GpuTriangle],
) -> (wgpu::Buffer, wgpu::Buffer) {
    let nodes: Vec<u8> = if nodes.is_empty() {
        vec![0; crate::scene::bvh::wide::WIDE_NODE_BYTES]
    } else {
        nodes.to_vec()
    };
    let tris: Vec<u8> = if triangles.is_empty() {
        vec![0; std::mem::size_of::<crate::scene::bvh::GpuTriangle>()]
    } else {
        bytemuck::cast_slice(triangles).to_vec()
    };
    let n = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("scene::bvh_nodes"),
        contents: &nodes,
        usage: wgpu::BufferUsages::STORAGE,
    });
    let t = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("scene::bvh_triangles"),
        contents: &tris,
        usage: wgpu::BufferUsages::STORAGE,
    });
    (n, t)
}
