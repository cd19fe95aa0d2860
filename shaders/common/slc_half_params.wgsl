// Parameters of half-resolution GI (shaders/methods/tree_samplers/slc_half.wgsl, slc_upsample.wgsl).
// Twin of `GpuHalfParams` in src/methods/tree_samplers/half.rs.
struct HalfParams {
    full_w: u32,
    full_h: u32,
    half_w: u32,
    half_h: u32,
    n_min: f32,
    d_max: f32,   // metres
    _pad0: u32,
    _pad1: u32,
};
