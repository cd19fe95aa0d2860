// Stage 11 (thesis 5.1): one shallow light cut per k x k pixel block, built at the block
// centre's G-buffer sample (pixel (bx k + k/2, by k + k/2), clamped to the image). Output:
// cut_size node ids per block in slot order, 0 for unused slots (and for every slot of a
// block whose centre sees no geometry). On the radix tree, block 0's thread also writes the
// mock cut after the last block's cut (the perfect tree's is a level, computed where used).
// CPU twins: `build_cut_on`, `mock_cut` in src/reference/slc.rs.
#include "common/color.wgsl"
#include "common/sst_node.wgsl"
#include "common/box_term.wgsl"
#include "common/tree_links.wgsl"
#include "common/slc.wgsl"
#include "common/slc_params.wgsl"

@group(0) @binding(0) var<uniform> sp: SlcParams;
@group(0) @binding(1) var<storage, read> tree: array<SstNode>;
@group(0) @binding(2) var gb_position: texture_2d<f32>;
@group(0) @binding(3) var gb_normal: texture_2d<f32>;
@group(0) @binding(4) var<storage, read_write> cuts: array<u32>;
@group(0) @binding(5) var<storage, read> tree_links: array<vec4<u32>>;

fn tree_radix() -> bool {
    return sp.radix != 0u;
}

@compute @workgroup_size(64, 1, 1)
fn build_cuts(@builtin(global_invocation_id) gid: vec3<u32>) {
    let b = gid.x;
    if b >= sp.grid_x * sp.grid_y {
        return;
    }
    let c = slc_block_centre(b);
    let g = textureLoad(gb_position, vec2<i32>(c), 0);
    var count = 0u;
    if g.w > 0.0 {
        let n = normalize(textureLoad(gb_normal, vec2<i32>(c), 0).xyz);
        count = slc_build_cut(g.xyz, n, sp.epsilon, sp.cut_size, sp.cull != 0u, sp.leaves);
    }
    for (var i = 0u; i < sp.cut_size; i++) {
        cuts[b * sp.cut_size + i] = select(0u, cut_ids[i], i < count);
    }
    if b == 0u && tree_radix() {
        let m = slc_mock_cut(1u << min(firstLeadingBit(max(sp.cut_size, 1u)), sp.levels - 1u), sp.leaves);
        let tail = sp.grid_x * sp.grid_y * sp.cut_size;
        for (var i = 0u; i < sp.cut_size; i++) {
            cuts[tail + i] = select(0u, cut_ids[i], i < m);
        }
    }
}
