//! Copies textures back to the CPU (exports, tests, the pixel inspector).

use std::sync::{
    Arc,
    atomic::{AtomicU8, Ordering},
};

use super::context::{GpuContext, GpuError};

// States of an [`AsyncReadback`]: IDLE (unmapped, free) -> PENDING (copies recorded) ->
// MAPPING (map_async issued once) -> READY / FAILED (callback ran) -> IDLE (taken).
const IDLE: u8 = 0;
const PENDING: u8 = 1;
const MAPPING: u8 = 2;
const READY: u8 = 3;
const FAILED: u8 = 4;

/// A small GPU -> CPU copy that never blocks the frame: record copies into it when it is idle,
/// call `after_submit` once the commands are submitted, and `try_take` on later frames (after
/// a `device.poll`). At most one copy is in flight.
pub struct AsyncReadback {
    buffer: wgpu::Buffer,
    state: Arc<AtomicU8>,
    len: u64,
}

impl AsyncReadback {
    pub fn new(device: &wgpu::Device, label: &str, size: u64) -> Self {
        Self {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(4),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            state: Arc::new(AtomicU8::new(IDLE)),
            len: 0,
        }
    }

    pub fn is_idle(&self) -> bool {
        self.state.load(Ordering::Acquire) == IDLE
    }

    /// Records `(source, source offset, destination offset, bytes)` copies unless a copy is
    /// still in flight; returns whether it did. A finished result nobody took is dropped: the
    /// new copy supersedes it (else a reader that polls rarely would keep every later frame's
    /// copy from being recorded, and read a stale one).
    pub fn record(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        copies: &[(&wgpu::Buffer, u64, u64, u64)],
    ) -> bool {
        if copies.is_empty() {
            return false;
        }
        match self.state.load(Ordering::Acquire) {
            READY => self.buffer.unmap(),
            FAILED => {}
            IDLE => {}
            _ => return false,
        }
        self.state.store(IDLE, Ordering::Release);
        let mut len = 0;
        for &(src, src_offset, dst_offset, bytes) in copies {
            encoder.copy_buffer_to_buffer(src, src_offset, &self.buffer, dst_offset, bytes);
            len = len.max(dst_offset + bytes);
        }
        self.len = len;
        self.state.store(PENDING, Ordering::Release);
        true
    }

    /// Starts mapping after the recorded copies were submitted.
    pub fn after_submit(&self) {
        if self
            .state
            .compare_exchange(PENDING, MAPPING, Ordering::AcqRel, Ordering::Acquire)
            .is_err()
        {
            return;
        }
        let state = self.state.clone();
        self.buffer
            .slice(0..self.len)
            .map_async(wgpu::MapMode::Read, move |r| {
                state.store(if r.is_ok() { READY } else { FAILED }, Ordering::Release);
            });
    }

    /// The copied bytes once the map finished (poll the device first); frees the buffer.
    pub fn try_take(&mut self) -> Option<Vec<u8>> {
        match self.state.load(Ordering::Acquire) {
            READY => {
                let bytes = self
                    .buffer
                    .slice(0..self.len)
                    .get_mapped_range()
                    .ok()
                    .map(|v| v.to_vec());
                self.buffer.unmap();
                self.state.store(IDLE, Ordering::Release);
                bytes
            }
            FAILED => {
                self.state.store(IDLE, Ordering::Release);
                None
            }
            _ => None,
        }
    }
}

/// Frame counters of type `T` (parsed from u32 words) read back without blocking: record the
/// copies in diagnostic frames, `after_submit` after the submit, `poll` later; `last` keeps
/// the latest parsed ones.
pub struct CounterReadback<T> {
    readback: AsyncReadback,
    parse: fn(&[u32]) -> T,
    last: Option<T>,
}

impl<T: Copy> CounterReadback<T> {
    pub fn new(device: &wgpu::Device, label: &str, bytes: u64, parse: fn(&[u32]) -> T) -> Self {
        Self {
            readback: AsyncReadback::new(device, label, bytes),
            parse,
            last: None,
        }
    }
    /// Records `(source, source offset, destination offset, bytes)` copies (AsyncReadback).
    pub fn record(&mut self, encoder: &mut wgpu::CommandEncoder, copies: &[(&wgpu::Buffer, u64, u64, u64)]) {
        self.readback.record(encoder, copies);
    }
    pub fn after_submit(&self) {
        self.readback.after_submit();
    }
    /// The counters last read back (without polling).
    pub fn last(&self) -> Option<T> {
        self.last
    }
    /// The counters of the latest copy read back (non-blocking; poll the device first for
    /// the newest).
    pub fn poll(&mut self) -> Option<T> {
        if let Some(bytes) = self.readback.try_take() {
            self.last = Some((self.parse)(bytemuck::cast_slice(&bytes)));
        }
        self.last
    }
    /// Forgets the counters (they described other settings).
    pub fn clear(&mut self) {
        self.last = None;
    }
}

pub use crate::base::image::ImageF32;

/// IEEE half -> f32.
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = ((h >> 15) as u32) << 31;
    let exp = ((h >> 10) & 0x1f) as u32;
    let mant = (h & 0x3ff) as u32;
    let bits = match exp {
        0 if mant == 0 => sign,
        0 => {
            // Subnormal: normalise.
            let mut e = 127 - 15 + 1;
            let mut m = mant;
            while m & 0x400 == 0 {
                m <<= 1;
                e -= 1;
            }
            sign | (e << 23) | ((m & 0x3ff) << 13)
        }
        31 => sign | 0x7f80_0000 | (mant << 13),
        _ => sign | ((exp + 127 - 15) << 23) | (mant << 13),
    };
    f32::from_bits(bits)
}

/// Reads layer `layer` of mip 0 of `texture` as tightly packed bytes.
pub fn read_texture_bytes(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    layer: u32,
) -> Result<Vec<u8>, GpuError> {
    let format = texture.format();
    let aspect = if format.is_depth_stencil_format() {
        wgpu::TextureAspect::DepthOnly
    } else {
        wgpu::TextureAspect::All
    };
    let bpp = format
        .block_copy_size(Some(aspect))
        .ok_or_else(|| GpuError::Readback(format!("cannot read back {format:?}")))?;
    let (w, h) = (texture.width(), texture.height());
    let row = w * bpp;
    let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback::buffer"),
        size: padded as u64 * h as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("readback::encoder"),
        });
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
            aspect,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    ctx.queue.submit([enc.finish()]);
    read_buffer_bytes(ctx, &buffer).map(|data| {
        let mut out = Vec::with_capacity((row * h) as usize);
        for y in 0..h as usize {
            out.extend_from_slice(&data[y * padded as usize..y * padded as usize + row as usize]);
        }
        out
    })
}

/// Maps a MAP_READ buffer and returns its bytes (blocks until the GPU is done).
pub fn read_buffer_bytes(ctx: &GpuContext, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.wait_idle()?;
    rx.recv()
        .map_err(|e| GpuError::Readback(e.to_string()))?
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    let data = slice
        .get_mapped_range()
        .map_err(|e| GpuError::Readback(format!("{e:?}")))?
        .to_vec();
    buffer.unmap();
    Ok(data)
}

/// Copies a whole storage buffer into a fresh MAP_READ buffer and reads it.
pub fn read_storage_buffer(ctx: &GpuContext, src: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    read_buffer_range(ctx, src, 0, src.size())
}

/// A `size`-pixel image stored as one vec4<f32> per pixel, row-major (the methods'
/// per-pixel diagnostics): None when the image has at most one pixel (not yet sized).
pub fn read_vec4_image(
    ctx: &GpuContext,
    src: &wgpu::Buffer,
    size: (u32, u32),
) -> Result<Option<ImageF32>, GpuError> {
    let n = size.0 as u64 * size.1 as u64;
    if n <= 1 {
        return Ok(None);
    }
    let bytes = read_buffer_range(ctx, src, 0, 16 * n)?;
    Ok(Some(ImageF32 {
        width: size.0,
        height: size.1,
        pixels: bytemuck::pod_collect_to_vec(&bytes),
    }))
}

/// Pixel (x, y) of such an image (of width `width`).
pub fn read_vec4_pixel(
    ctx: &GpuContext,
    src: &wgpu::Buffer,
    width: u32,
    x: u32,
    y: u32,
) -> Result<[f32; 4], GpuError> {
    let off = (y as u64 * width as u64 + x as u64) * 16;
    let bytes = read_buffer_range(ctx, src, off, 16)?;
    Ok(bytemuck::pod_read_unaligned(&bytes[..16]))
}

/// Copies `size` bytes at `offset` (both multiples of 4) of a storage buffer and reads them.
pub fn read_buffer_range(
    ctx: &GpuContext,
    src: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> Result<Vec<u8>, GpuError> {
    Ok(read_buffer_ranges(ctx, src, &[(offset, size)])?
        .pop()
        .unwrap_or_default())
}

/// Reads several (offset, size) ranges (multiples of 4) of a storage buffer with one
/// submission, in order.
pub fn read_buffer_ranges(
    ctx: &GpuContext,
    src: &wgpu::Buffer,
    ranges: &[(u64, u64)],
) -> Result<Vec<Vec<u8>>, GpuError> {
    let total: u64 = ranges.iter().map(|r| r.1).sum();
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback::range"),
        size: total.max(4),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("readback::encoder"),
        });
    let mut at = 0;
    for &(offset, size) in ranges {
        enc.copy_buffer_to_buffer(src, offset, &staging, at, size);
        at += size;
    }
    ctx.queue.submit([enc.finish()]);
    let bytes = read_buffer_bytes(ctx, &staging)?;
    let mut at = 0usize;
    Ok(ranges
        .iter()
        .map(|&(_, size)| {
            let v = bytes[at..at + size as usize].to_vec();
            at += size as usize;
            v
        })
        .collect())
}

/// Reads a float colour or depth texture as RGBA f32 (depth goes to all of rgb, a = 1;
/// Rgba8 formats are returned as their stored 0..1 values, not decoded).
pub fn read_texture_f32(ctx: &GpuContext, texture: &wgpu::Texture, layer: u32) -> Result<ImageF32, GpuError> {
    let bytes = read_texture_bytes(ctx, texture, layer)?;
    let (w, h) = (texture.width(), texture.height());
    let n = (w * h) as usize;
    let pixels = decode_texels(texture.format(), &bytes)?;
    if pixels.len() != n {
        return Err(GpuError::Readback("unexpected readback size".into()));
    }
    Ok(ImageF32 {
        width: w,
        height: h,
        pixels,
    })
}

/// Reads single texels (layer 0, mip 0) of several textures with one submission: for each
/// (texture, x, y) its value as RGBA f32 (see [`read_texture_f32`] for the conversions).
pub fn read_texels(
    ctx: &GpuContext,
    texels: &[(&wgpu::Texture, u32, u32)],
) -> Result<Vec<[f32; 4]>, GpuError> {
    const SLOT: u64 = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64;
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback::texels"),
        size: SLOT * texels.len().max(1) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("readback::texels_encoder"),
        });
    for (i, (t, x, y)) in texels.iter().enumerate() {
        if *x >= t.width() || *y >= t.height() {
            return Err(GpuError::Readback(format!(
                "texel ({x}, {y}) outside a {}x{} texture",
                t.width(),
                t.height()
            )));
        }
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: t,
                mip_level: 0,
                origin: wgpu::Origin3d { x: *x, y: *y, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: i as u64 * SLOT,
                    bytes_per_row: Some(SLOT as u32),
                    rows_per_image: Some(1),
                },
            },
            wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
    }
    ctx.queue.submit([enc.finish()]);
    let data = read_buffer_bytes(ctx, &staging)?;
    texels
        .iter()
        .enumerate()
        .map(|(i, (t, _, _))| {
            let f = t.format();
            let size = f.block_copy_size(None).unwrap_or(16) as usize;
            let start = i * SLOT as usize;
            decode_texels(f, &data[start..start + size]).and_then(|v| {
                v.first()
                    .copied()
                    .ok_or_else(|| GpuError::Readback("empty texel".into()))
            })
        })
        .collect()
}

/// RGBA f32 of tightly packed texels of `format`.
fn decode_texels(format: wgpu::TextureFormat, bytes: &[u8]) -> Result<Vec<[f32; 4]>, GpuError> {
    Ok(match format {
        wgpu::TextureFormat::Rgba32Float => bytemuck::cast_slice::<u8, [f32; 4]>(bytes).to_vec(),
        wgpu::TextureFormat::Rgba16Float => bytes
            .chunks_exact(8)
            .map(|c| {
                let h = |i: usize| f16_to_f32(u16::from_le_bytes([c[2 * i], c[2 * i + 1]]));
                [h(0), h(1), h(2), h(3)]
            })
            .collect(),
        wgpu::TextureFormat::R32Float | wgpu::TextureFormat::Depth32Float => bytes
            .chunks_exact(4)
            .map(|c| {
                let v = f32::from_le_bytes([c[0], c[1], c[2], c[3]]);
                [v, v, v, 1.0]
            })
            .collect(),
        wgpu::TextureFormat::Rgba8Unorm | wgpu::TextureFormat::Rgba8UnormSrgb => bytes
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]].map(|v| v as f32 / 255.0))
            .collect(),
        f => return Err(GpuError::Readback(format!("no float conversion for {f:?}"))),
    })
}

#[cfg(test)]
mod tests {
    use super::f16_to_f32;

    #[test]
    fn half_conversion() {
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x3555), 0.33325195);
        assert_eq!(f16_to_f32(0x0001), 5.9604645e-8);
        assert!(f16_to_f32(0x7c00).is_infinite());
        assert!(f16_to_f32(0x7e00).is_nan());
    }
}
