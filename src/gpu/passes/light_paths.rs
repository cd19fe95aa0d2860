//! Multi-bounce VPLs (issue 23; the SST paper's VPL generation after Keller's instant
//! radiosity): light paths that start at RSM texels drawn by reflected flux and are traced
//! through the BVH, one VPL at each diffuse bounce 2..=N (`shaders/light_paths.wgsl`).
//! Reads: the VPL stage's uniform and pyramids, the RSMs, the scene (BVH, vertices,
//! materials, textures). Writes: VPL slots `[first, first + (N - 1) x paths)` of a VPL array.
//! CPU twin: `reference::light_paths`.

use bytemuck::{Pod, Zeroable};

use crate::{
    gpu::{
        context::{GpuContext, GpuError},
        frame::ShadowTargets,
        gpu_data::GpuVpl,
        kernel::{Kernel, KernelOptions, buf, tex},
        readback,
        scene_gpu::SceneGpu,
        shaders,
        timing::GpuTimer,
    },
    scene::DirectionalLight,
};

use super::{
    WG_1D, storage_buffer,
    vpl_gen::{VplBuffers, split_budget},
};

/// Deepest bounce `vpl.bounces` may ask for.
pub const MAX_BOUNCES: u32 = 8;

/// How a budget of `count` VPLs splits between the RSM's bounce-1 VPLs and the light paths
/// for `bounces` bounces: every bounce gets `count / bounces` slots (one per path), bounce 1
/// the rest. Returns (bounce-1 VPLs, paths).
pub fn split_bounces(count: u32, bounces: u32) -> (u32, u32) {
    if bounces <= 1 {
        return (count, 0);
    }
    let paths = count / bounces;
    (count - (bounces - 1) * paths, paths)
}

/// Twin: `PathParams` in `shaders/light_paths.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuPathParams {
    pub paths: u32,
    pub first: u32,
    pub bounces: u32,
    pub roulette: u32,
    pub seed: u32,
    pub ray_offset: f32,
    pub lod: u32,
    pub flux_scale: f32,
    pub light_count: u32,
    pub flux_mix: f32,
    pub _pad: [u32; 2],
    pub ranges: [[u32; 4]; 4],
}

/// What the paths start from, trace through and write: the lights, the VPL stage's
/// parameters, RSM and pyramids (the starts are drawn from them), the scene, and the VPL
/// buffer `out`.
#[derive(Clone, Copy)]
pub struct PathInputs<'a> {
    pub lights: &'a [DirectionalLight],
    pub vpl_params: &'a wgpu::Buffer,
    pub rsm: &'a ShadowTargets,
    pub pyramids: &'a VplBuffers,
    pub scene: &'a SceneGpu,
    pub out: &'a wgpu::Buffer,
}

/// One dispatch's paths: where they go and how they run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathJob {
    pub paths: u32,
    /// VPL slot of bounce 2's first path.
    pub first: u32,
    pub bounces: u32,
    pub roulette: bool,
    pub seed: u32,
    /// Metres along the vertex's geometric normal.
    pub ray_offset: f32,
    /// Mip level of the hit surfaces' albedo.
    pub lod: u32,
    /// Every VPL's flux x this.
    pub flux_scale: f32,
    /// Share of the start PDF that follows flux (1: flux only; else mixed with the BRSM
    /// importance of bounce 1).
    pub flux_mix: f32,
}

impl PathJob {
    /// The uniform for `lights` (paths split by brightness as the bounce-1 VPLs are).
    pub fn params(&self, lights: &[DirectionalLight]) -> GpuPathParams {
        let lights = &lights[..lights.len().min(4)];
        let mut p = GpuPathParams {
            paths: self.paths,
            first: self.first,
            bounces: self.bounces,
            roulette: self.roulette as u32,
            seed: self.seed,
            ray_offset: self.ray_offset,
            lod: self.lod,
            flux_scale: self.flux_scale,
            light_count: lights.len() as u32,
            flux_mix: self.flux_mix,
            _pad: [0; 2],
            ranges: [[0; 4]; 4],
        };
        for (i, (first, n)) in split_budget(lights, self.paths).iter().enumerate() {
            p.ranges[i] = [*first, *n, 0, 0];
        }
        p
    }
}

pub struct LightPathPass {
    starts_pipeline: wgpu::ComputePipeline,
    trace_pipeline: wgpu::ComputePipeline,
    /// Group 0: the VPL stage's uniform, the RSMs and pyramids (the starts); group 1: the
    /// paths' uniform, starts, output and the scene.
    kernel: Kernel,
    params: wgpu::Buffer,
    /// Each path's start (bounce-1 vertex) as a VPL record.
    starts: wgpu::Buffer,
    starts_capacity: u32,
}

impl LightPathPass {
    pub fn new(device: &wgpu::Device) -> Result<Self, shaders::ShaderError> {
        let kernel = Kernel::new(
            device,
            "light_paths.wgsl",
            &["path_starts", "trace_paths"],
            KernelOptions::default(),
        )?;
        Ok(Self {
            starts_pipeline: kernel.compute(device, "light_paths::starts", "path_starts"),
            trace_pipeline: kernel.compute(device, "light_paths::trace", "trace_paths"),
            kernel,
            params: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("light_paths::params"),
                size: std::mem::size_of::<GpuPathParams>() as u64,
                usage: wgpu::BufferUsages::UNIFORM
                    | wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            starts: storage_buffer(device, "light_paths::starts", 16),
            starts_capacity: 0,
        })
    }

    /// The last dispatch's path starts (tests read them).
    pub fn starts(&self) -> &wgpu::Buffer {
        &self.starts
    }

    fn ensure_starts(&mut self, device: &wgpu::Device, paths: u32) {
        if self.starts_capacity < paths {
            self.starts = storage_buffer(
                device,
                "light_paths::starts",
                paths as u64 * std::mem::size_of::<GpuVpl>() as u64,
            );
            self.starts_capacity = paths;
        }
    }

    fn path_bind(&self, device: &wgpu::Device, scene: &SceneGpu, out: &wgpu::Buffer) -> wgpu::BindGroup {
        self.kernel.bind(
            device,
            1,
            &[
                ("pp", buf(&self.params)),
                ("starts", buf(&self.starts)),
                ("vpls", buf(out)),
                ("bvh_nodes", buf(&scene.bvh_nodes)),
                ("bvh_triangles", buf(&scene.bvh_triangles)),
                ("scene_vertices", buf(&scene.vertices)),
                ("scene_indices", buf(&scene.indices)),
                ("materials", buf(&scene.materials)),
                ("textures", tex(&scene.textures_view)),
            ],
        )
    }

    /// Records the starts and the paths of `job` into `i.out` (timer names
    /// `light_path_starts`, `light_paths`).
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        timer: &mut GpuTimer,
        job: &PathJob,
        i: &PathInputs<'_>,
    ) {
        let PathInputs {
            lights,
            vpl_params,
            rsm,
            pyramids,
            scene,
            out,
        } = *i;
        if job.paths == 0 || job.bounces < 2 || lights.is_empty() {
            return;
        }
        self.ensure_starts(device, job.paths);
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&job.params(lights)));
        let rsm_bind = self.kernel.bind(
            device,
            0,
            &[
                ("params", buf(vpl_params)),
                ("rsm_position", tex(&rsm.position_array)),
                ("rsm_normal", tex(&rsm.normal_array)),
                ("rsm_flux", tex(&rsm.flux_array)),
                ("importance_pyramid", buf(&pyramids.importance_pyramid)),
                ("flux_pyramid", buf(&pyramids.flux_pyramid)),
            ],
        );
        let path_bind = self.path_bind(device, scene, out);
        let groups = job.paths.div_ceil(WG_1D);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("light_path_starts"),
                timestamp_writes: timer.compute_pass("light_path_starts"),
            });
            pass.set_pipeline(&self.starts_pipeline);
            pass.set_bind_group(0, &rsm_bind, &[]);
            pass.set_bind_group(1, &path_bind, &[]);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("light_paths"),
            timestamp_writes: timer.compute_pass("light_paths"),
        });
        pass.set_pipeline(&self.trace_pipeline);
        pass.set_bind_group(1, &path_bind, &[]);
        pass.dispatch_workgroups(groups, 1, 1);
    }

    /// Traces `job` from the given `starts` (one per path; `job.paths` is their number) and
    /// returns the `(bounces - 1) x paths` VPLs, bounce by bounce (`job.first` is ignored):
    /// the tests' entry to the trace kernel alone.
    pub fn trace_starts(
        &mut self,
        ctx: &GpuContext,
        scene: &SceneGpu,
        starts: &[GpuVpl],
        job: &PathJob,
    ) -> Result<Vec<GpuVpl>, GpuError> {
        let device = &ctx.device;
        let paths = starts.len() as u32;
        if paths == 0 || job.bounces < 2 {
            return Ok(Vec::new());
        }
        if paths.div_ceil(WG_1D) > 65535 {
            return Err(GpuError::Limit(format!("{paths} paths exceed one dispatch")));
        }
        self.ensure_starts(device, paths);
        ctx.queue
            .write_buffer(&self.starts, 0, bytemuck::cast_slice(starts));
        let job = PathJob {
            paths,
            first: 0,
            ..*job
        };
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&job.params(&[])));
        let count = (job.bounces - 1) as usize * paths as usize;
        let out = storage_buffer(
            device,
            "light_paths::test_out",
            (count * std::mem::size_of::<GpuVpl>()) as u64,
        );
        let bind = self.path_bind(device, scene, &out);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("light_paths::trace_starts"),
        });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("light_paths_trace"),
                timestamp_writes: None,
            });
            pass.set_bind_group(1, &bind, &[]);
            pass.set_pipeline(&self.trace_pipeline);
            pass.dispatch_workgroups(paths.div_ceil(WG_1D), 1, 1);
        }
        ctx.queue.submit([enc.finish()]);
        let bytes = readback::read_storage_buffer(ctx, &out)?;
        Ok(bytemuck::pod_collect_to_vec(
            &bytes[..count * std::mem::size_of::<GpuVpl>()],
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bounce_gets_a_share_and_bounce_one_the_rest() {
        assert_eq!(split_bounces(4096, 1), (4096, 0));
        assert_eq!(split_bounces(4096, 2), (2048, 2048));
        assert_eq!(split_bounces(4096, 3), (1366, 1365));
        assert_eq!(split_bounces(10, 4), (4, 2));
        for (n, b) in [(1, 3), (7, 8), (1 << 20, 8)] {
            let (first, paths) = split_bounces(n, b);
            assert_eq!(first + (b - 1) * paths, n);
        }
    }
}
