// Views of the tree sampling (thesis figs. 7.2, 7.4, 7.6), over the GI resolution:
//   mode 0: traversal steps per traversal as a heat map (false colour, 0 .. max_steps);
//   mode 1: the final image in grey with the pixels that had no similar cut (mock cut or
//           other fallback) in red;
//   mode 2: each block tinted by its cut (a colour per set of node ids), block borders dark,
//           the selected block outlined in white;
//   mode 3: each block tinted by its cut's mean node depth (false colour, root .. leaves).
// CPU twin of the colour maps: src/reference/visualise.rs.
#include "common/color.wgsl"
#include "common/tree_links.wgsl"

struct ViewParams {
    mode: u32,
    grid_x: u32,
    block: u32,
    cut_size: u32,
    exposure: f32,   // linear multiplier
    tonemap: u32,
    max_steps: f32,
    levels: u32,
    selected: u32,   // 1 + selected block, 0 = none
    final_scale: u32, // full-resolution pixels per GI pixel (final image, G-buffer)
    radix: u32,       // 1: the radix tree (depths walked along tree_links), 0: the perfect tree
    leaves: u32,
};

@group(0) @binding(0) var<uniform> vp: ViewParams;
@group(0) @binding(1) var final_image: texture_2d<f32>;
@group(0) @binding(2) var gb_position: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> diag: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> cuts: array<u32>;
@group(0) @binding(5) var dst: texture_storage_2d<rgba8unorm, write>;
// The radix tree's links (a dummy on the perfect tree): common/tree_links.wgsl.
@group(0) @binding(6) var<storage, read> tree_links: array<vec4<u32>>;

fn tree_radix() -> bool {
    return vp.radix != 0u;
}


fn grey_final(px: vec2<i32>) -> vec3<f32> {
    return vec3<f32>(display_grey(textureLoad(final_image, px, 0).rgb, vp.exposure, vp.tonemap));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(dst);
    if gid.x >= size.x || gid.y >= size.y {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let fp = px * i32(vp.final_scale);
    let k = gid.y * size.x + gid.x;
    let d = diag[k];
    let geometry = textureLoad(gb_position, fp, 0).w > 0.0;
    var c = vec3<f32>(0.0);
    switch vp.mode {
        case 0u: {
            if geometry {
                c = false_color(d.x / max(vp.max_steps, 1e-6));
            }
        }
        case 1u: {
            c = grey_final(fp) * 0.8;
            if d.y > 0.5 {
                c = vec3<f32>(0.95, 0.1, 0.1);
            }
        }
        default: {
            let b = (gid.y / vp.block) * vp.grid_x + gid.x / vp.block;
            var h = 0x9e3779b9u;
            var depth = 0.0;
            var count = 0u;
            for (var i = 0u; i < vp.cut_size; i++) {
                let n = cuts[b * vp.cut_size + i];
                if n == 0u {
                    break;
                }
                h = (h ^ n) * 16777619u;
                depth += f32(tree_depth(n, vp.leaves));
                count += 1u;
            }
            var tint = vec3<f32>(0.0);
            if count > 0u {
                if vp.mode == 2u {
                    tint = id_color(h);
                } else {
                    tint = false_color(depth / f32(count) / f32(max(vp.levels - 1u, 1u)));
                }
            }
            c = mix(grey_final(fp), tint, 0.6);
            let in_block = gid.xy % vec2<u32>(vp.block);
            if vp.block >= 4u && (in_block.x == 0u || in_block.y == 0u) {
                c *= 0.5;
            }
            if vp.selected == b + 1u && (in_block.x == 0u || in_block.y == 0u
                || in_block.x == vp.block - 1u || in_block.y == vp.block - 1u) {
                c = vec3<f32>(1.0);
            }
        }
    }
    textureStore(dst, px, vec4<f32>(c, 1.0));
}
