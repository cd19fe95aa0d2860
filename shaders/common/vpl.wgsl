// A virtual point light. Twin of `GpuVpl` in src/renderer/gpu_data.rs.
// It is a diffuse emitter of total flux `flux`: radiant intensity flux / pi x cos(angle to
// its normal), so a surface point x (albedo rho, normal n_x) at distance d receives radiance
// rho / pi x flux / pi x cos_x x cos_v / max(d^2, eps^2) from it (unoccluded).
const VPL_NONE: u32 = 0xffffffffu;
// Ids of light-path VPLs (bounce >= 2, light_paths.wgsl): PATH_BIT | bounce << 24 | path.
// An RSM VPL's id is layer << 24 | texel (layer < 4), so `id >> 24` names an RSM layer only
// for bounce-1 VPLs. Twin: `base::gpu_layout::{vpl_bounce, vpl_path_id}`.
const VPL_PATH_BIT: u32 = 0x80000000u;

fn vpl_path_id(bounce: u32, path: u32) -> u32 {
    return VPL_PATH_BIT | (bounce << 24u) | path;
}

// The diffuse bounce a VPL's light has made: 1 for RSM VPLs, 2.. for light-path VPLs, 0 none.
fn vpl_bounce(id: u32) -> u32 {
    if id == VPL_NONE {
        return 0u;
    }
    if (id & VPL_PATH_BIT) != 0u {
        return (id >> 24u) & 0x7fu;
    }
    return 1u;
}

struct Vpl {
    position: vec4<f32>, // xyz world position, w = pmf of the texel it was chosen from
    normal: vec3<f32>,   // unit normal (the side its surface was lit on)
    id: u32,             // light layer << 24 | RSM texel, a light-path id, or VPL_NONE
    flux: vec4<f32>,     // rgb flux in W (texel flux / (N_light x pmf)), w = 1 if valid
};

// Unoccluded geometric term of light from a VPL at pv (normal nv) to x (normal nx):
// cos_x x cos_v / max(d^2, eps^2), 0 when either side faces away.
fn vpl_geometry(pv: vec3<f32>, nv: vec3<f32>, x: vec3<f32>, nx: vec3<f32>, eps: f32) -> f32 {
    let d = pv - x;
    let dist2 = dot(d, d);
    let w = d * inverseSqrt(max(dist2, 1e-30));
    let cx = dot(nx, w);
    let cv = -dot(nv, w);
    if cx <= 0.0 || cv <= 0.0 {
        return 0.0;
    }
    return cx * cv / max(dist2, eps * eps);
}
