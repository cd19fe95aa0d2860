//! The binned-SAH build (Wald 2007 binning; median splits for the top levels of huge inputs,
//! `median_levels`): primitives to a flat array of 32-byte nodes, leaves of at most
//! `MAX_LEAF_TRIS` triangles.

use super::*;

#[derive(Clone, Copy)]
pub(super) struct PrimRef {
    pub(super) min: Vec3A,
    pub(super) max: Vec3A,
    pub(super) id: u32,
}

#[derive(Clone, Copy)]
pub(super) struct Bin {
    pub(super) min: Vec3A,
    pub(super) max: Vec3A,
    pub(super) count: u32,
}

impl Bin {
    const EMPTY: Bin = Bin {
        min: Vec3A::splat(f32::INFINITY),
        max: Vec3A::splat(f32::NEG_INFINITY),
        count: 0,
    };
}

/// Half the surface area of a (non-empty) box.
#[inline(always)]
pub(super) fn half_area(min: Vec3A, max: Vec3A) -> f32 {
    let e = (max - min).max(Vec3A::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

/// Number of object-median levels needed to bring `count` triangles down to leaves.
pub(super) fn median_levels(count: usize) -> usize {
    let mut c = count;
    let mut l = 0;
    while c > MAX_LEAF_TRIS {
        c = c.div_ceil(2);
        l += 1;
    }
    l
}

#[inline(always)]
pub(super) fn bin_index(p: &PrimRef, cmin: Vec3A, scale: Vec3A) -> UVec3 {
    let c = (p.min + p.max) * 0.5;
    // Float-to-int casts saturate, so negative rounding noise maps to bin 0.
    ((c - cmin) * scale)
        .as_uvec3()
        .min(UVec3::splat(SAH_BINS as u32 - 1))
}

pub(super) struct Split {
    pub(super) axis: usize,
    /// Primitives in bins `0..=bin` go left.
    pub(super) bin: u32,
    /// `area_l * n_l + area_r * n_r` (half areas).
    pub(super) cost: f32,
}

pub(super) struct Builder {
    pub(super) prims: Vec<PrimRef>,
    pub(super) nodes: Vec<GpuBvhNode>,
    pub(super) leaves: usize,
    pub(super) depth: usize,
    pub(super) max_leaf: usize,
}

impl Builder {
    pub(super) fn find_split(prims: &[PrimRef], cmin: Vec3A, cmax: Vec3A) -> Option<Split> {
        let ext = cmax - cmin;
        let scale = Vec3A::select(
            ext.cmpgt(Vec3A::ZERO),
            Vec3A::splat(SAH_BINS as f32) / ext,
            Vec3A::ZERO,
        );
        let mut bins = [[Bin::EMPTY; SAH_BINS]; 3];
        for p in prims {
            let b = bin_index(p, cmin, scale);
            for axis in 0..3 {
                let bin = &mut bins[axis][b[axis] as usize];
                bin.min = bin.min.min(p.min);
                bin.max = bin.max.max(p.max);
                bin.count += 1;
            }
        }
        let mut best: Option<Split> = None;
        for (axis, bins) in bins.iter().enumerate() {
            if !(ext[axis] > 0.0) {
                continue;
            }
            // Prefix (left) areas and counts for splits after bin i.
            let mut left_area = [0.0f32; SAH_BINS];
            let mut left_count = [0u32; SAH_BINS];
            let (mut lmin, mut lmax, mut lc) = (Bin::EMPTY.min, Bin::EMPTY.max, 0u32);
            for i in 0..SAH_BINS - 1 {
                lmin = lmin.min(bins[i].min);
                lmax = lmax.max(bins[i].max);
                lc += bins[i].count;
                left_area[i] = if lc > 0 { half_area(lmin, lmax) } else { 0.0 };
                left_count[i] = lc;
            }
            let (mut rmin, mut rmax, mut rc) = (Bin::EMPTY.min, Bin::EMPTY.max, 0u32);
            for i in (1..SAH_BINS).rev() {
                rmin = rmin.min(bins[i].min);
                rmax = rmax.max(bins[i].max);
                rc += bins[i].count;
                let lc = left_count[i - 1];
                if lc == 0 || rc == 0 {
                    continue;
                }
                let cost = left_area[i - 1] * lc as f32 + half_area(rmin, rmax) * rc as f32;
                if best.as_ref().is_none_or(|b| cost < b.cost) {
                    best = Some(Split {
                        axis,
                        bin: (i - 1) as u32,
                        cost,
                    });
                }
            }
        }
        best
    }

    /// Builds the subtree over `prims[start..end]` at `depth`; returns nothing (the node index
    /// is `self.nodes.len()` on entry).
    pub(super) fn build_node(&mut self, start: usize, end: usize, depth: usize) {
        let index = self.nodes.len();
        self.nodes.push(GpuBvhNode::zeroed_node());
        let count = end - start;
        let prims = &mut self.prims[start..end];

        let (mut bmin, mut bmax) = (Bin::EMPTY.min, Bin::EMPTY.max);
        let (mut cmin, mut cmax) = (Bin::EMPTY.min, Bin::EMPTY.max);
        for p in prims.iter() {
            bmin = bmin.min(p.min);
            bmax = bmax.max(p.max);
            let c = (p.min + p.max) * 0.5;
            cmin = cmin.min(c);
            cmax = cmax.max(c);
        }
        let bounds = Aabb {
            min: bmin.into(),
            max: bmax.into(),
        };

        let make_leaf = |b: &mut Builder| {
            b.nodes[index] = GpuBvhNode::leaf(&bounds, start as u32, count as u32);
            b.leaves += 1;
            b.depth = b.depth.max(depth);
            b.max_leaf = b.max_leaf.max(count);
        };
        if count <= 1 {
            make_leaf(self);
            return;
        }

        // SAH is allowed only while even its most unbalanced outcome (a child with count - 1
        // triangles, finished by median splits) keeps every leaf within BVH_STACK_SIZE.
        let sah_allowed = depth + 1 + median_levels(count - 1) <= BVH_STACK_SIZE;
        let area = half_area(bmin, bmax);
        let split = if sah_allowed && area > 0.0 {
            Self::find_split(prims, cmin, cmax)
        } else {
            None
        };
        if count <= MAX_LEAF_TRIS {
            let leaf_cost = count as f32 * SAH_TRIANGLE_COST;
            let keep = match &split {
                Some(s) => SAH_TRAVERSAL_COST + s.cost / area * SAH_TRIANGLE_COST >= leaf_cost,
                None => true,
            };
            if keep {
                make_leaf(self);
                return;
            }
        }

        let (axis, mid) = match split {
            Some(s) => {
                let ext = cmax - cmin;
                let scale = Vec3A::select(
                    ext.cmpgt(Vec3A::ZERO),
                    Vec3A::splat(SAH_BINS as f32) / ext,
                    Vec3A::ZERO,
                );
                // In-place partition: bins 0..=s.bin to the front.
                let (mut i, mut j) = (0usize, prims.len());
                while i < j {
                    if bin_index(&prims[i], cmin, scale)[s.axis] <= s.bin {
                        i += 1;
                    } else {
                        j -= 1;
                        prims.swap(i, j);
                    }
                }
                (s.axis, i)
            }
            None => {
                // Object median along the largest centroid extent.
                let ext = cmax - cmin;
                let axis = if ext.x >= ext.y && ext.x >= ext.z {
                    0
                } else if ext.y >= ext.z {
                    1
                } else {
                    2
                };
                let mid = count / 2;
                if ext[axis] > 0.0 {
                    prims.select_nth_unstable_by(mid, |a, b| {
                        (a.min[axis] + a.max[axis]).total_cmp(&(b.min[axis] + b.max[axis]))
                    });
                }
                (axis, mid)
            }
        };
        debug_assert!(mid > 0 && mid < count);

        self.build_node(start, start + mid, depth + 1);
        let right = self.nodes.len() as u32;
        self.build_node(start + mid, end, depth + 1);
        self.nodes[index] = GpuBvhNode::interior(&bounds, right, axis as u32);
    }
}
