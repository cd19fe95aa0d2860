//! Copies textures back to the CPU (exports, tests, the pixel inspector).

use super::context::{GpuContext, GpuError};

/// A linear RGBA float image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageF32 {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
}

impl ImageF32 {
    pub fn get(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[(y * self.width + x) as usize]
    }
    /// Mean of the RGB channels over all pixels.
    pub fn mean_rgb(&self) -> [f64; 3] {
        let mut s = [0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                s[c] += p[c] as f64;
            }
        }
        let n = self.pixels.len().max(1) as f64;
        s.map(|v| v / n)
    }
}

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

/// Copies a storage buffer into a fresh MAP_READ buffer and reads it.
pub fn read_storage_buffer(ctx: &GpuContext, src: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback::staging"),
        size: src.size(),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("readback::encoder"),
        });
    enc.copy_buffer_to_buffer(src, 0, &staging, 0, src.size());
    ctx.queue.submit([enc.finish()]);
    read_buffer_bytes(ctx, &staging)
}

/// Copies `size` bytes at `offset` (both multiples of 4) of a storage buffer and reads them.
pub fn read_buffer_range(
    ctx: &GpuContext,
    src: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> Result<Vec<u8>, GpuError> {
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback::range"),
        size: size.max(4),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("readback::encoder"),
        });
    enc.copy_buffer_to_buffer(src, offset, &staging, 0, size);
    ctx.queue.submit([enc.finish()]);
    read_buffer_bytes(ctx, &staging)
}

/// Reads a float colour or depth texture as RGBA f32 (depth goes to all of rgb, a = 1;
/// Rgba8 formats are returned as their stored 0..1 values, not decoded).
pub fn read_texture_f32(ctx: &GpuContext, texture: &wgpu::Texture, layer: u32) -> Result<ImageF32, GpuError> {
    let bytes = read_texture_bytes(ctx, texture, layer)?;
    let (w, h) = (texture.width(), texture.height());
    let n = (w * h) as usize;
    let pixels: Vec<[f32; 4]> = match texture.format() {
        wgpu::TextureFormat::Rgba32Float => bytemuck::cast_slice::<u8, [f32; 4]>(&bytes).to_vec(),
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
    };
    if pixels.len() != n {
        return Err(GpuError::Readback("unexpected readback size".into()));
    }
    Ok(ImageF32 {
        width: w,
        height: h,
        pixels,
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
