//! Visualise: maps any non-radiance buffer (normals, albedo, positions, depth, ids, shadow-map
//! depth, integer buffers) to a viewable image in the `Rgba8Unorm` view texture.

use crate::renderer::{gpu_data::VisParams, shaders, timing::GpuTimer};

use super::{
    compute_pipeline, display::VIEW_FORMAT, float_texture_entry, groups_2d, storage_texture_entry,
    texture_entry, uniform_entry,
};

/// Twin of the mode table at the top of `shaders/visualise.wgsl`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VisMode {
    Normal = 0,
    Albedo = 1,
    Position = 2,
    Depth = 3,
    IdFromW = 4,
    DepthTexture = 5,
    UintIds = 6,
    UintHeat = 7,
    ArrayColor = 8,
    ArrayNormal = 9,
    ScalarLogHeat = 10,
    ArrayPosition = 11,
}

/// What to visualise.
pub enum VisSource<'a> {
    /// A float buffer with mode Normal/Albedo/Position/Depth/IdFromW.
    Float(&'a wgpu::TextureView),
    /// A layer of a depth texture array.
    Depth(&'a wgpu::TextureView, u32),
    /// An unsigned-integer buffer (mode UintIds or UintHeat).
    Uint(&'a wgpu::TextureView),
    /// A layer of a float array texture (mode ArrayColor / ArrayNormal).
    Array(&'a wgpu::TextureView, u32),
    /// A square map of f32 in a buffer (mode ScalarLogHeat) and the pyramid whose top holds
    /// its sum (index in the pyramid buffer given in range_min.y by the caller).
    Scalar(&'a wgpu::Buffer, &'a wgpu::Buffer),
}

pub struct VisualisePass {
    float_pipeline: wgpu::ComputePipeline,
    depth_pipeline: wgpu::ComputePipeline,
    uint_pipeline: wgpu::ComputePipeline,
    array_pipeline: wgpu::ComputePipeline,
    scalar_pipeline: wgpu::ComputePipeline,
    array_layout: wgpu::BindGroupLayout,
    scalar_layout: wgpu::BindGroupLayout,
    common_layout: wgpu::BindGroupLayout,
    float_layout: wgpu::BindGroupLayout,
    depth_layout: wgpu::BindGroupLayout,
    uint_layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
}

impl VisualisePass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let module = shaders::create_module(device, "visualise.wgsl")?;
        let c = wgpu::ShaderStages::COMPUTE;
        let bgl = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            crate::renderer::passes::bind_group_layout(
                device,
                &wgpu::BindGroupLayoutDescriptor {
                    label: Some(label),
                    entries,
                },
            )
        };
        let common_layout = bgl(
            "visualise::common_layout",
            &[uniform_entry(0, c), storage_texture_entry(1, VIEW_FORMAT)],
        );
        let float_layout = bgl("visualise::float_layout", &[float_texture_entry(0)]);
        let depth_layout = bgl(
            "visualise::depth_layout",
            &[texture_entry(
                0,
                c,
                wgpu::TextureSampleType::Depth,
                wgpu::TextureViewDimension::D2Array,
            )],
        );
        let uint_layout = bgl(
            "visualise::uint_layout",
            &[texture_entry(
                0,
                c,
                wgpu::TextureSampleType::Uint,
                wgpu::TextureViewDimension::D2,
            )],
        );
        let array_layout = bgl(
            "visualise::array_layout",
            &[texture_entry(
                2,
                c,
                wgpu::TextureSampleType::Float { filterable: false },
                wgpu::TextureViewDimension::D2Array,
            )],
        );
        let scalar_layout = bgl(
            "visualise::scalar_layout",
            &[super::storage_entry(3, c, true), super::storage_entry(4, c, true)],
        );
        let array_pipeline = compute_pipeline(
            device,
            "visualise::array_pipeline",
            &[Some(&common_layout), Some(&array_layout)],
            &module,
            "vis_array",
        );
        let scalar_pipeline = compute_pipeline(
            device,
            "visualise::scalar_pipeline",
            &[Some(&common_layout), Some(&scalar_layout)],
            &module,
            "vis_scalar",
        );
        let float_pipeline = compute_pipeline(
            device,
            "visualise::float_pipeline",
            &[Some(&common_layout), Some(&float_layout)],
            &module,
            "vis_float",
        );
        let depth_pipeline = compute_pipeline(
            device,
            "visualise::depth_pipeline",
            &[Some(&common_layout), None, Some(&depth_layout)],
            &module,
            "vis_depth",
        );
        let uint_pipeline = compute_pipeline(
            device,
            "visualise::uint_pipeline",
            &[Some(&common_layout), None, None, Some(&uint_layout)],
            &module,
            "vis_uint",
        );
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("visualise::params"),
            size: std::mem::size_of::<VisParams>() as u64,
            usage: crate::renderer::passes::PARAMS_USAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self {
            float_pipeline,
            depth_pipeline,
            uint_pipeline,
            array_pipeline,
            scalar_pipeline,
            array_layout,
            scalar_layout,
            common_layout,
            float_layout,
            depth_layout,
            uint_layout,
            params,
        })
    }

    /// Records the visualisation of `src` into `dst` (of `size`). `range_min`/`range_max`
    /// depend on the mode (see `shaders/visualise.wgsl`).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        mode: VisMode,
        src: VisSource<'_>,
        range_min: [f32; 4],
        range_max: [f32; 4],
        dst: &wgpu::TextureView,
        size: (u32, u32),
    ) {
        let layer = match src {
            VisSource::Depth(_, l) | VisSource::Array(_, l) => l,
            _ => 0,
        };
        let p = VisParams {
            mode: mode as u32,
            layer,
            _pad: [0; 2],
            range_min,
            range_max,
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let tv = wgpu::BindingResource::TextureView;
        let common = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("visualise::common"),
            layout: &self.common_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: tv(dst),
                },
            ],
        });
        let (pipeline, group, source) = match src {
            VisSource::Float(view) => (
                &self.float_pipeline,
                1,
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("visualise::float_source"),
                    layout: &self.float_layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: tv(view),
                    }],
                }),
            ),
            VisSource::Depth(view, _) => (
                &self.depth_pipeline,
                2,
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("visualise::depth_source"),
                    layout: &self.depth_layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: tv(view),
                    }],
                }),
            ),
            VisSource::Array(view, _) => (
                &self.array_pipeline,
                1,
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("visualise::array_source"),
                    layout: &self.array_layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 2,
                        resource: tv(view),
                    }],
                }),
            ),
            VisSource::Scalar(values, pyramid) => (
                &self.scalar_pipeline,
                1,
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("visualise::scalar_source"),
                    layout: &self.scalar_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: values.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 4,
                            resource: pyramid.as_entire_binding(),
                        },
                    ],
                }),
            ),
            VisSource::Uint(view) => (
                &self.uint_pipeline,
                3,
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("visualise::uint_source"),
                    layout: &self.uint_layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: tv(view),
                    }],
                }),
            ),
        };
        encoder.push_debug_group("visualise");
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("visualise::pass"),
                timestamp_writes: timer.compute_pass("visualise"),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &common, &[]);
            pass.set_bind_group(group, &source, &[]);
            let (gx, gy) = groups_2d(size.0, size.1);
            pass.dispatch_workgroups(gx, gy, 1);
        }
        encoder.pop_debug_group();
    }
}
