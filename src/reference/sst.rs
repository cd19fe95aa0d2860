//! References of the SST sort keys and the GPU bitonic sort (SST paper 3.3, thesis 4.2.1).
//!
//! Key (64 bits) = 30-bit Morton code of the position normalised to the VPL bounds
//! (10 bits per axis, x highest) | 9-bit normal code | 25-bit VPL id. The normal code is
//! the octant (sign bits of x, y, z) followed by 3 levels of triangle subdivision of that
//! octant (2 bits each: child 0/1/2 = the corner at the x/y/z axis, 3 = the centre triangle),
//! per Fig. 3 of the SST paper (after Taubin and Rossignac 1998).

use glam::Vec3;

use crate::scene::Aabb;

/// Bits of the id field: at most 2^25 VPLs.
pub const ID_BITS: u32 = 25;

/// Spreads the low 10 bits of `v` to every third bit.
pub fn expand_bits_10(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | (x << 16)) & 0x030000ff;
    x = (x | (x << 8)) & 0x0300f00f;
    x = (x | (x << 4)) & 0x030c30c3;
    x = (x | (x << 2)) & 0x09249249;
    x
}

/// 30-bit Morton code of integer coordinates in 0..1024 (x in the highest bit of each triple).
pub fn morton3(x: u32, y: u32, z: u32) -> u32 {
    (expand_bits_10(x) << 2) | (expand_bits_10(y) << 1) | expand_bits_10(z)
}

/// Quantises `p` inside `bounds` to 0..=1023 per axis (degenerate axes map to 0).
pub fn quantise(p: Vec3, bounds: &Aabb) -> [u32; 3] {
    let ext = bounds.max - bounds.min;
    let q = |v: f32, lo: f32, e: f32| {
        if e > 0.0 {
            (((v - lo) / e).clamp(0.0, 1.0) * 1023.0) as u32
        } else {
            0
        }
    };
    [
        q(p.x, bounds.min.x, ext.x),
        q(p.y, bounds.min.y, ext.y),
        q(p.z, bounds.min.z, ext.z),
    ]
}

/// 9-bit normal code: octant (3 bits: x < 0, y < 0, z < 0 from high to low) then 3 levels of
/// triangle subdivision of the octant (2 bits each).
pub fn normal_code(n: Vec3) -> u32 {
    let octant = ((n.x < 0.0) as u32) << 2 | ((n.y < 0.0) as u32) << 1 | (n.z < 0.0) as u32;
    let a = n.abs();
    let s = a.x + a.y + a.z;
    // Barycentric coordinates in the octant's triangle (e_x, e_y, e_z).
    let mut b = if s > 0.0 { a / s } else { Vec3::new(1.0, 0.0, 0.0) };
    let mut code = octant;
    for _ in 0..3 {
        let child = if b.x > 0.5 {
            b = Vec3::new(2.0 * b.x - 1.0, 2.0 * b.y, 2.0 * b.z);
            0
        } else if b.y > 0.5 {
            b = Vec3::new(2.0 * b.x, 2.0 * b.y - 1.0, 2.0 * b.z);
            1
        } else if b.z > 0.5 {
            b = Vec3::new(2.0 * b.x, 2.0 * b.y, 2.0 * b.z - 1.0);
            2
        } else {
            // Centre triangle (vertices at the edge midpoints opposite x, y, z).
            b = Vec3::new(1.0 - 2.0 * b.x, 1.0 - 2.0 * b.y, 1.0 - 2.0 * b.z);
            3
        };
        code = (code << 2) | child;
    }
    code
}

/// The 64-bit sort key of a VPL.
pub fn sort_key(p: Vec3, n: Vec3, id: u32, bounds: &Aabb) -> u64 {
    let [x, y, z] = quantise(p, bounds);
    ((morton3(x, y, z) as u64) << 34)
        | ((normal_code(n) as u64) << ID_BITS)
        | (id as u64 & ((1 << ID_BITS) - 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_codes_by_hand() {
        assert_eq!(morton3(0, 0, 0), 0);
        assert_eq!(morton3(1, 0, 0), 0b100);
        assert_eq!(morton3(0, 1, 0), 0b010);
        assert_eq!(morton3(0, 0, 1), 0b001);
        assert_eq!(morton3(3, 0, 0), 0b100_100);
        assert_eq!(morton3(2, 1, 3), 0b101_011);
        assert_eq!(morton3(1023, 1023, 1023), (1 << 30) - 1);
        assert_eq!(morton3(512, 0, 0), 1 << 29);
    }

    // Literals grouped as octant_level1_level2_level3.
    #[allow(clippy::unusual_byte_groupings)]
    #[test]
    fn normal_codes_by_hand() {
        // +x axis: octant 000, corner x three times.
        assert_eq!(normal_code(Vec3::X), 0b000_00_00_00);
        // -y axis: octant 010 (y < 0), corner y three times.
        assert_eq!(normal_code(Vec3::NEG_Y), 0b010_01_01_01);
        // +z: corner z.
        assert_eq!(normal_code(Vec3::Z), 0b000_10_10_10);
        // (1,1,1)/sqrt3: barycentric (1/3,1/3,1/3) -> centre, then (1/3,1/3,1/3) again.
        assert_eq!(normal_code(Vec3::ONE.normalize()), 0b000_11_11_11);
        // (-1,-1,-1): octant 111, centre.
        assert_eq!(normal_code(-Vec3::ONE), 0b111_11_11_11);
        // Barycentric (0.6, 0.4, 0): corner x -> (0.2, 0.8, 0) -> corner y -> (0.4, 0.6, 0)
        // -> corner y.
        assert_eq!(normal_code(Vec3::new(0.6, 0.4, 0.0)), 0b000_00_01_01);
        // Every code fits 9 bits and the 64 directions of one octant are all reachable.
        let mut seen = std::collections::HashSet::new();
        for i in 0..200 {
            for j in 0..200 {
                let (u, v) = (i as f32 / 199.0, j as f32 / 199.0);
                if u + v <= 1.0 {
                    let c = normal_code(Vec3::new(u, v, (1.0 - u - v).max(0.0)));
                    assert!(c < 512);
                    seen.insert(c);
                }
            }
        }
        assert_eq!(seen.len(), 64);
    }

    #[test]
    fn keys_order_by_position_then_normal_then_id_and_are_unique() {
        let b = Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        };
        let k0 = sort_key(Vec3::splat(0.1), Vec3::Y, 7, &b);
        let k1 = sort_key(Vec3::splat(0.9), Vec3::Y, 3, &b);
        assert!(k0 < k1, "position dominates");
        let k2 = sort_key(Vec3::splat(0.1), Vec3::NEG_Y, 1, &b);
        assert!(k0 < k2, "then the normal");
        let k3 = sort_key(Vec3::splat(0.1), Vec3::Y, 8, &b);
        assert!(k0 < k3 && k3 >> ID_BITS == k0 >> ID_BITS, "then the id");
        let keys: std::collections::HashSet<u64> = (0..1000)
            .map(|i| sort_key(Vec3::splat(0.5), Vec3::Y, i, &b))
            .collect();
        assert_eq!(keys.len(), 1000);
    }
}
