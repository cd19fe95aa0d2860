//! CPU twin of interleaved sampling (Keller & Heidrich 2001; Stochastic Light Culling,
//! Tokuyoshi & Harada 2016, section 4.2) as the workbench's methods use it: the pattern's
//! subsets (light culling: of the VPLs, `lcull_common.wgsl`; the tree samplers: of a cut's
//! slots, `slc_sample.wgsl`) and the geometry-aware filter that undoes the pattern
//! (`shaders/interleave_filter.wgsl`).

use glam::Vec3;

use super::vpl::pcg_hash;

/// Interleaved sampling (section 4.2): an n x n pattern, pixel (x, y) takes subset
/// (x mod n) + n (y mod n). VPL i belongs to subset ((i / stride) mod n^2 + offset) mod n^2:
/// runs of `stride` consecutive VPLs share a subset. Our VPLs come in Hammersley order (the
/// warp's first coordinate i / N, the second the bit-reversed i), so with a stride near
/// sqrt(N / n^2) (a power of two) each subset is a stratified sample of the whole RSM (of one
/// light's: with several lights, each light's VPL range need not start on a block boundary
/// and the stratification weakens; the subsets still partition the VPLs); a stride of 1 would
/// give each subset one strip of it (the low bits of i fix the top bits of the second
/// coordinate). `offset` is drawn per frame, so that every pixel sees every VPL with
/// probability 1 / n^2 over frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Interleave {
    pub n: u32,
    pub offset: u32,
    pub stride: u32,
}

impl Interleave {
    /// The frame's interleaving for `count` VPLs and seed `seed`.
    pub fn new(n: u32, count: u32, seed: u32) -> Self {
        Self {
            n,
            offset: Self::offset_of(n, seed),
            stride: Self::stride_for(count, n),
        }
    }
    pub fn cells(self) -> u32 {
        self.n * self.n
    }
    pub fn pixel_subset(self, x: u32, y: u32) -> u32 {
        x % self.n + self.n * (y % self.n)
    }
    pub fn vpl_subset(self, i: u32) -> u32 {
        let c = self.cells();
        ((i / self.stride) % c + self.offset % c) % c
    }
    /// The k-th VPL of subset `s` (increasing in k). Twin: `lcull_member`.
    pub fn member(self, s: u32, k: u32) -> u32 {
        let c = self.cells();
        let j = (s + c - self.offset % c) % c;
        (k / self.stride) * self.stride * c + j * self.stride + k % self.stride
    }
    /// How many of `count` VPLs subset `s` holds. Twin: `lcull_members`.
    pub fn members(self, s: u32, count: u32) -> u32 {
        let c = self.cells();
        let j = (s + c - self.offset % c) % c;
        let block = self.stride * c;
        let full = count / block;
        let rem = count - full * block;
        full * self.stride + rem.saturating_sub(j * self.stride).min(self.stride)
    }
    /// The VPLs of subset `s`, in increasing order.
    pub fn subset(self, s: u32, count: u32) -> impl Iterator<Item = u32> {
        (0..self.members(s, count)).map(move |k| self.member(s, k))
    }
    /// The frame's offset (the uniforms carry it to the kernels).
    pub fn offset_of(n: u32, seed: u32) -> u32 {
        pcg_hash(seed ^ 0x2545_f491) % (n * n).max(1)
    }
    /// The largest power of two at most sqrt(count / n^2) (at least 1).
    pub fn stride_for(count: u32, n: u32) -> u32 {
        let per = (count / (n * n).max(1)).max(1) as f64;
        let s = per.sqrt().floor().max(1.0) as u32;
        1 << (31 - s.leading_zeros())
    }
}

/// The tree samplers' interleaving (twin: the slot loop of `slc_sample.wgsl`): the cut's
/// slots (runs of one: `stride` 1) split into n^2 subsets; the slots pixel (x, y) takes this
/// frame, in increasing order. `from_root` (SST, the root fallback: every sample estimates
/// the whole sum) takes the subset's first slot even past the cut size, so that a pixel
/// always has a sample.
pub fn slot_subset(n: u32, seed: u32, cut_size: u32, x: u32, y: u32, from_root: bool) -> Vec<u32> {
    let il = Interleave {
        n,
        offset: Interleave::offset_of(n, seed),
        stride: 1,
    };
    let s = il.pixel_subset(x, y);
    let slots: Vec<u32> = il.subset(s, cut_size).collect();
    if slots.is_empty() && from_root {
        return vec![il.member(s, 0)];
    }
    slots
}

/// The image the geometry-aware filter reads: its size, the camera (`eye`, `forward`: view
/// depth = (p - eye) . forward), each pixel's surface (position, unit normal; None: nothing)
/// and each pixel's demodulated estimate.
#[derive(Clone, Copy, Debug)]
pub struct FilterImage<'a> {
    pub width: u32,
    pub height: u32,
    pub eye: Vec3,
    pub forward: Vec3,
    pub surf: &'a [Option<(Vec3, Vec3)>],
    pub raw: &'a [Vec3],
}

/// The geometry-aware filter of interleaved sampling (section 4.2; Segovia et al. 2006) at
/// pixel (x, y) of `img`: the mean of the demodulated estimates in a (2 radius + 1)^2 window
/// over the pixels on the same surface: normals within `normal_cos` and the neighbour within
/// `plane_tolerance` x view depth of the pixel's tangent plane. Twin:
/// `shaders/interleave_filter.wgsl`.
pub fn filter_pixel(
    img: &FilterImage<'_>,
    x: u32,
    y: u32,
    radius: u32,
    normal_cos: f32,
    plane_tolerance: f32,
) -> Vec3 {
    let r = radius as i32;
    filter_pixel_window(img, x, y, (-r, r), normal_cos, plane_tolerance)
}

/// [`filter_pixel`] over the window of offsets `lo ..= hi` along each axis
/// (`interleave_filter::window`: the VAL method's p x p window).
pub fn filter_pixel_window(
    img: &FilterImage<'_>,
    x: u32,
    y: u32,
    (lo, hi): (i32, i32),
    normal_cos: f32,
    plane_tolerance: f32,
) -> Vec3 {
    let FilterImage {
        width,
        height,
        eye,
        forward,
        surf,
        raw,
    } = *img;
    let k = (y * width + x) as usize;
    let Some((p, n)) = surf[k] else { return Vec3::ZERO };
    let tol = plane_tolerance * (p - eye).dot(forward).max(1e-6);
    let (mut sum, mut w) = (Vec3::ZERO, 0.0f32);
    for dy in lo..=hi {
        for dx in lo..=hi {
            let (qx, qy) = (x as i32 + dx, y as i32 + dy);
            if qx < 0 || qy < 0 || qx >= width as i32 || qy >= height as i32 {
                continue;
            }
            let q = (qy as u32 * width + qx as u32) as usize;
            let Some((pq, nq)) = surf[q] else { continue };
            if n.dot(nq) >= normal_cos && (pq - p).dot(n).abs() <= tol {
                sum += raw[q];
                w += 1.0;
            }
        }
    }
    sum / w.max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pattern_pixels_take_every_cut_slot_exactly_once() {
        // The tree samplers: each n x n block of pixels shares a cut's slots out between its
        // pixels, whatever the frame's offset; a slot's pixel changes with the seed.
        for n in [1u32, 2, 3, 4, 8] {
            for cut_size in [1u32, 3, 16, 32, 64] {
                for seed in [0u32, 1, 77, 0xdead_beef] {
                    let mut seen = vec![0u32; cut_size as usize];
                    for y in 0..n {
                        for x in 0..n {
                            // Any n x n block: offset by whole patterns.
                            for i in slot_subset(n, seed, cut_size, x + 5 * n, y + 3 * n, false) {
                                seen[i as usize] += 1;
                            }
                        }
                    }
                    assert!(seen.iter().all(|&c| c == 1), "n {n}, cut {cut_size}: {seen:?}");
                }
            }
        }
        // From the root a pixel always samples: with 4 slots and 8 x 8 subsets, 60 of the 64
        // subsets hold none, and take one sample anyway (not a slot of the cut: the samples
        // from the root are alike).
        for y in 0..8 {
            for x in 0..8 {
                let cut = slot_subset(8, 3, 4, x, y, false);
                let root = slot_subset(8, 3, 4, x, y, true);
                assert!(cut.len() <= 1 && root.len() == 1);
                if !cut.is_empty() {
                    assert_eq!(cut, root);
                }
            }
        }
        // Over frames every pixel takes every slot: the offsets cover all n^2 subsets.
        let offsets: std::collections::HashSet<u32> =
            (0..200).map(|seed| Interleave::offset_of(4, seed)).collect();
        assert_eq!(offsets.len(), 16);
    }

    #[test]
    fn the_filter_averages_the_same_surface_only() {
        // A 5 x 1 strip: two pixels on a plane facing the camera, one tilted, one behind,
        // one empty; radius 2 around the middle pixel.
        let (eye, fwd) = (Vec3::ZERO, Vec3::Z);
        let n = Vec3::NEG_Z;
        let surf = vec![
            Some((Vec3::new(-0.2, 0.0, 5.0), n)),
            Some((Vec3::new(-0.1, 0.0, 5.0), Vec3::new(0.0, 0.8, -0.6))),
            Some((Vec3::new(0.0, 0.0, 5.0), n)),
            Some((Vec3::new(0.1, 0.0, 6.0), n)),
            None,
        ];
        let raw: Vec<Vec3> = (1..=5).map(|i| Vec3::splat(i as f32)).collect();
        let img = FilterImage {
            width: 5,
            height: 1,
            eye,
            forward: fwd,
            surf: &surf,
            raw: &raw,
        };
        let f = filter_pixel(&img, 2, 0, 2, 0.9, 0.02);
        // Pixels 0 and 2 (the tilted normal, the one 1 m behind and the empty one are out).
        assert_eq!(f, Vec3::splat(2.0));
        // Radius 0: the pixel itself; no surface: 0.
        assert_eq!(filter_pixel(&img, 2, 0, 0, 0.9, 0.02), Vec3::splat(3.0));
        assert_eq!(filter_pixel(&img, 4, 0, 2, 0.9, 0.02), Vec3::ZERO);
    }
}
