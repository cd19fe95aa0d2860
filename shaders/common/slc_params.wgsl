// Parameters of the tree sampling passes. Twin of `GpuSlcParams` in
// src/renderer/gpu_data.rs.
struct SlcParams {
    width: u32,      // GI resolution
    height: u32,
    block: u32,      // k: cut block edge in GI pixels
    grid_x: u32,     // blocks per row
    grid_y: u32,
    cut_size: u32,   // nodes per cut = samples per pixel
    leaves: u32,
    levels: u32,
    method: u32,     // 0 SLC (thesis), 1 SST (from the root), 2 RTSLC (to the leaves)
    blending: u32,   // 0 stochastic (Algorithm 1), 1 off (own block only)
    fallback: u32,   // 0 mock cut, 1 average the cuts, 2 traverse from the root, 3 recompute
    cull: u32,       // drop children wholly behind the block centre's surface
    seed: u32,
    accumulate: u32, // 0: write the frame's estimate, 1: add it
    epsilon: f32,    // distance bound (m)
    ray_offset: f32,
    n_min: f32,      // eq. 5.3
    d_max: f32,      // eq. 5.3, metres
    demodulate: u32, // 1: write the estimate without the albedo (half-resolution GI, interleaving)
    trace_pixel: u32, // x | y << 16: the pixel whose samples slc_sample records (pixel story); ~0 none
    near_field: f32, // near-field refinement factor (0 = off): see slc_far_enough
    shadow_rays: u32, // 1 trace shadow rays, 0 every sample visible, 2 the leaves' imperfect shadow maps
    substitute_offset: f32, // m: substitute samples' shadow rays end this far short (slc_substitute_end)
    child_probability: u32, // 0 mean position (eq. 5.5), 1 min-max box distance (RTSLC's), 2 defensive: slc_child_prob
    interleave: u32,        // n of the n x n slot interleaving (1 = off)
    interleave_offset: u32, // the frame's subset offset
    radix: u32,             // 1: the radix tree (children from tree_links), 0: the perfect tree
    brdf: u32,              // BRDF_LAMBERT / BRDF_GGX (common/brdf.wgsl)
    glossy_material: u32,   // glossy walks: 0 geometric, 1 x slc_glossy_term (SST paper 4.1), 2 defensive mix
    pad0: u32,
    pad1: u32,
    pad2: u32,
    eye: vec4<f32>,         // xyz camera position (glossy shading's view direction)
};

// The pixel whose G-buffer sample builds block b's cut.
fn slc_block_centre(b: u32) -> vec2<u32> {
    let bx = b % sp.grid_x;
    let by = b / sp.grid_x;
    return min(vec2<u32>(bx * sp.block + sp.block / 2u, by * sp.block + sp.block / 2u),
        vec2<u32>(sp.width - 1u, sp.height - 1u));
}
