//! The linear data behind a view (EXR export) and the snapshots A/B views compare against:
//! [`super::Renderer`]'s side of `gpu::views`.

use crate::gpu::views::*;
use crate::settings::ViewBuffer;

impl super::Renderer {
    /// The linear data behind a view, for EXR export: radiance and G-buffer views as they are,
    /// RSM views as layer 0, BRSM importance as one channel, the tree samplers' views as their
    /// per-pixel diagnostics (steps, fallback, samples, 1 + block). None for the views without
    /// a single image (PDF pyramid level, A/B views: export A and B instead).
    pub fn read_view_buffer(
        &self,
        view: ViewBuffer,
    ) -> Result<Option<super::readback::ImageF32>, super::context::GpuError> {
        use super::{Buffer, readback};
        let buffer = match view {
            ViewBuffer::Final => Buffer::Final,
            ViewBuffer::Direct => Buffer::Direct,
            ViewBuffer::Indirect => Buffer::Indirect,
            ViewBuffer::Albedo => Buffer::Albedo,
            ViewBuffer::Normal => Buffer::Normal,
            ViewBuffer::Position | ViewBuffer::MaterialId => Buffer::Position,
            ViewBuffer::Depth => Buffer::Depth,
            ViewBuffer::ShadowMap => Buffer::ShadowMap(0),
            ViewBuffer::RsmFlux => Buffer::RsmFlux(0),
            ViewBuffer::RsmNormal => Buffer::RsmNormal(0),
            ViewBuffer::RsmPosition => Buffer::RsmPosition(0),
            ViewBuffer::GroundTruthIndirect => return self.read_ab_source(AbSource::GroundTruthIndirect),
            ViewBuffer::GroundTruthFinal => return self.read_ab_source(AbSource::GroundTruthFinal),
            ViewBuffer::ImportanceRaw | ViewBuffer::ImportanceFiltered => {
                let vb = &self.vpl_buffers;
                let src = if view == ViewBuffer::ImportanceRaw {
                    &vb.importance_raw
                } else {
                    &vb.importance_pyramid
                };
                let n = vb.res as u64 * vb.res as u64;
                let bytes = readback::read_buffer_range(&self.ctx, src, 0, 4 * n)?;
                let v: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
                return Ok(Some(readback::ImageF32 {
                    width: vb.res,
                    height: vb.res,
                    pixels: v.iter().map(|&x| [x, x, x, 1.0]).collect(),
                }));
            }
            ViewBuffer::Method(v) => return self.read_method_view(v),
            _ => return Ok(None),
        };
        self.read(buffer).map(Some)
    }
}
