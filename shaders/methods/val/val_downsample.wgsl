// The VAL method's clustering RSM: layer `layer` of light 0's RSM summed down by `factor`
// (each coarse texel: its block's lit texels' summed flux and summed surface area in the
// flux's alpha, and the mean position and normalised summed normal of the block's dominant
// surface; position.w 1 when any is lit, else all zero). Twin: reference::val::downsample.
//
// Dominant surface (issue 37): a block that straddles two surfaces (a blind slat and the floor
// seen past it, a wall's outer face and the floor inside) would otherwise put its light at
// the mean of both, in mid-air, with a blended normal: a light that shines onto the very
// floor whose flux it carries (cos = 0 on the floor itself). That made the VALs 1.3-1.9x
// too bright (docs/val.md, *Brightness*). The block's texels on the surface holding most
// of its flux give the position and normal; the whole block's flux and area stay.

struct DownParams {
    res: u32,          // the coarse resolution
    factor: u32,       // fine texels per coarse texel edge
    layer: u32,
    _pad0: u32,
    light_dir: vec3<f32>,
    texel_area: f32,   // a fine texel's area perpendicular to the light
};

@group(0) @binding(0) var<uniform> dp: DownParams;
@group(0) @binding(1) var rsm_position: texture_2d_array<f32>;
@group(0) @binding(2) var rsm_normal: texture_2d_array<f32>;
@group(0) @binding(3) var rsm_flux: texture_2d_array<f32>;
@group(0) @binding(4) var out_position: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var out_normal: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var out_flux: texture_storage_2d<rgba32float, write>;

// Texels on one surface: normals within SAME_NORMAL, within `tol` of the reference's plane.
const SAME_NORMAL: f32 = 0.9;
// Reference texels tried per block (twin: DOMINANT_CANDIDATES).
const CANDIDATES: u32 = 16u;

fn fine_texel(b: vec2<u32>, k: u32) -> vec2<i32> {
    return vec2<i32>(b * dp.factor + vec2<u32>(k % dp.factor, k / dp.factor));
}

fn lit(c: vec2<i32>) -> bool {
    let f = textureLoad(rsm_flux, c, i32(dp.layer), 0).rgb;
    return textureLoad(rsm_position, c, i32(dp.layer), 0).w > 0.0 && max(f.r, max(f.g, f.b)) > 0.0;
}

fn same_surface(pr: vec3<f32>, nr: vec3<f32>, p: vec3<f32>, n: vec3<f32>, tol: f32) -> bool {
    return dot(n, nr) >= SAME_NORMAL && abs(dot(p - pr, nr)) <= tol;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= dp.res || gid.y >= dp.res {
        return;
    }
    let l = i32(dp.layer);
    let f2 = dp.factor * dp.factor;
    // A fine texel's edge times the block's edge: the plane tolerance of one surface.
    let tol = sqrt(dp.texel_area) * f32(dp.factor);
    var flux = vec3<f32>(0.0);
    var area = 0.0;
    var first = f2;
    var best = f2;
    var best_on = -1.0;
    // At most CANDIDATES texels of the block are tried as the dominant surface's reference
    // (every `stride`-th; all of a 4 x 4 block): the search costs CANDIDATES x factor^2.
    let stride = max(f2 / CANDIDATES, 1u);
    for (var r = 0u; r < f2; r++) {
        let cr = fine_texel(gid.xy, r);
        if !lit(cr) {
            continue;
        }
        let pr = textureLoad(rsm_position, cr, l, 0).xyz;
        let nr = textureLoad(rsm_normal, cr, l, 0).xyz;
        let fr = textureLoad(rsm_flux, cr, l, 0).rgb;
        flux += fr;
        // Twin: Rsm::surface_area.
        area += dp.texel_area / max(dot(nr, -dp.light_dir), 0.05);
        if first == f2 {
            first = r;
        }
        if r % stride != 0u {
            continue;
        }
        // The flux on r's surface.
        var on = 0.0;
        for (var k = 0u; k < f2; k++) {
            let ck = fine_texel(gid.xy, k);
            if lit(ck) && same_surface(
                pr,
                nr,
                textureLoad(rsm_position, ck, l, 0).xyz,
                textureLoad(rsm_normal, ck, l, 0).xyz,
                tol,
            ) {
                let fk = textureLoad(rsm_flux, ck, l, 0).rgb;
                on += fk.r + fk.g + fk.b;
            }
        }
        if on > best_on {
            best_on = on;
            best = r;
        }
    }
    let t = vec2<i32>(gid.xy);
    if first == f2 {
        textureStore(out_position, t, vec4<f32>(0.0));
        textureStore(out_normal, t, vec4<f32>(0.0));
        textureStore(out_flux, t, vec4<f32>(0.0));
        return;
    }
    if best == f2 {
        // No candidate lit: the block's first lit texel.
        best = first;
    }
    let cb = fine_texel(gid.xy, best);
    let pb = textureLoad(rsm_position, cb, l, 0).xyz;
    let nb = textureLoad(rsm_normal, cb, l, 0).xyz;
    var n = 0u;
    var pos = vec3<f32>(0.0);
    var nrm = vec3<f32>(0.0);
    for (var k = 0u; k < f2; k++) {
        let ck = fine_texel(gid.xy, k);
        let pk = textureLoad(rsm_position, ck, l, 0).xyz;
        let nk = textureLoad(rsm_normal, ck, l, 0).xyz;
        if lit(ck) && same_surface(pb, nb, pk, nk, tol) {
            n += 1u;
            pos += pk;
            nrm += nk;
        }
    }
    var normal = vec3<f32>(0.0, 0.0, 1.0);
    if dot(nrm, nrm) > 0.0 {
        normal = normalize(nrm);
    }
    textureStore(out_position, t, vec4<f32>(pos / f32(max(n, 1u)), 1.0));
    textureStore(out_normal, t, vec4<f32>(normal, 0.0));
    textureStore(out_flux, t, vec4<f32>(flux, area));
}
