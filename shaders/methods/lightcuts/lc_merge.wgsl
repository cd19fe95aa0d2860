// Lightcuts' per-node merge, shared by the perfect tree's level-by-level build (lc_build.wgsl)
// and the radix tree's bottom-up build (lc_build_radix.wgsl): the smallest cone around two
// cones and the representative pick. Contract: the includer includes common/math.wgsl,
// common/random.wgsl, common/sst_node.wgsl and methods/lightcuts/lc_common.wgsl.

// Both builds' uniform. Twin: `GpuLcBuildParams` (the radix build uses leaves and seed).
struct LcBuildParams {
    first: u32,  // the perfect tree's build: first node id of the level
    count: u32,  // nodes of the level
    leaves: u32,
    seed: u32,
};

fn angle_between(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return acos(clamp(dot(a, b), -1.0, 1.0));
}

// Twin: `merge_cones`.
fn merge_cones(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    if a.w < 0.0 {
        return b;
    }
    if b.w < 0.0 {
        return a;
    }
    var w = a;
    var n = b;
    if a.w < b.w {
        w = b;
        n = a;
    }
    let d = angle_between(w.xyz, n.xyz);
    if min(d + n.w, PI) <= w.w {
        return w;
    }
    let half = 0.5 * (w.w + d + n.w);
    if half >= PI {
        return vec4<f32>(w.xyz, PI);
    }
    let rot = half - w.w;
    let perp = n.xyz - w.xyz * dot(w.xyz, n.xyz);
    var dir = vec3<f32>(0.0);
    if dot(perp, perp) > 1e-12 {
        dir = normalize(perp);
    } else {
        dir = sst_basis(w.xyz)[0];
    }
    return vec4<f32>(normalize(w.xyz * cos(rot) + dir * sin(rot)), half);
}

fn rep_random(node: u32, seed: u32) -> f32 {
    return u01(pcg_hash(node ^ pcg_hash(seed)));
}

// Twin: `pick_rep`.
fn pick_rep(ra: u32, rb: u32, la: f32, lb: f32, u: f32) -> u32 {
    if ra == LC_NONE {
        return rb;
    }
    if rb == LC_NONE {
        return ra;
    }
    if la + lb <= 0.0 || u * (la + lb) < la {
        return ra;
    }
    return rb;
}

