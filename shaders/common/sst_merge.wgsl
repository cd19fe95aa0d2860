// The SST node in registers, its atomic load / store (16 words per node) and the merge of
// two children (eqs. 4.1-4.3, the child variance rotated into the parent's frame), shared by
// the perfect tree's build (sst_build.wgsl) and the radix tree's (lbvh.wgsl). CPU twin:
// base::sst_node::merge (documented in reference/sst_tree.rs).
//
// Contract: the including shader declares `nodes: array<atomic<u32>>` (storage, read_write)
// before this include, and includes common/color.wgsl and common/sst_node.wgsl.

// A node in registers: the stored normal both decoded and as its code.
struct Node {
    p: vec3<f32>,
    v: f32,
    intensity: vec3<f32>,
    n: vec3<f32>,
    code: u32,
    lo: vec3<f32>,
    hi: vec3<f32>,
    var_xyz: vec3<f32>,
    var_xy: u32,
};

fn empty_node() -> Node {
    let c = oct_encode(vec3<f32>(0.0, 0.0, 1.0));
    return Node(vec3<f32>(0.0), 1.0, vec3<f32>(0.0), oct_decode(c), c, vec3<f32>(SST_EMPTY_MIN),
        vec3<f32>(-SST_EMPTY_MIN), vec3<f32>(0.0), 0u);
}

fn is_empty(a: Node) -> bool {
    return a.lo.x > a.hi.x;
}

fn store_node(i: u32, a: Node) {
    let b = 16u * i;
    atomicStore(&nodes[b + 0u], bitcast<u32>(a.p.x));
    atomicStore(&nodes[b + 1u], bitcast<u32>(a.p.y));
    atomicStore(&nodes[b + 2u], bitcast<u32>(a.p.z));
    atomicStore(&nodes[b + 3u], bitcast<u32>(a.v));
    atomicStore(&nodes[b + 4u], bitcast<u32>(a.intensity.x));
    atomicStore(&nodes[b + 5u], bitcast<u32>(a.intensity.y));
    atomicStore(&nodes[b + 6u], bitcast<u32>(a.intensity.z));
    atomicStore(&nodes[b + 7u], a.code);
    atomicStore(&nodes[b + 8u], bitcast<u32>(a.lo.x));
    atomicStore(&nodes[b + 9u], bitcast<u32>(a.lo.y));
    atomicStore(&nodes[b + 10u], bitcast<u32>(a.lo.z));
    atomicStore(&nodes[b + 11u], bitcast<u32>(a.var_xyz.z));
    atomicStore(&nodes[b + 12u], bitcast<u32>(a.hi.x));
    atomicStore(&nodes[b + 13u], bitcast<u32>(a.hi.y));
    atomicStore(&nodes[b + 14u], bitcast<u32>(a.hi.z));
    atomicStore(&nodes[b + 15u], a.var_xy);
}

fn load_f(i: u32) -> f32 {
    return bitcast<f32>(atomicLoad(&nodes[i]));
}

fn load_node(i: u32) -> Node {
    let b = 16u * i;
    let code = atomicLoad(&nodes[b + 7u]);
    let var_xy = atomicLoad(&nodes[b + 15u]);
    return Node(
        vec3<f32>(load_f(b + 0u), load_f(b + 1u), load_f(b + 2u)),
        load_f(b + 3u),
        vec3<f32>(load_f(b + 4u), load_f(b + 5u), load_f(b + 6u)),
        oct_decode(code),
        code,
        vec3<f32>(load_f(b + 8u), load_f(b + 9u), load_f(b + 10u)),
        vec3<f32>(load_f(b + 12u), load_f(b + 13u), load_f(b + 14u)),
        vec3<f32>(unpack2x16float(var_xy), load_f(b + 11u)),
        var_xy,
    );
}

// A child's variance (diagonal in the frame of its normal n) along the parent's axes.
fn rotate_variance(var_c: vec3<f32>, n: vec3<f32>, t2: vec3<f32>, b2: vec3<f32>, n2: vec3<f32>) -> vec3<f32> {
    if all(var_c == vec3<f32>(0.0)) {
        return vec3<f32>(0.0);
    }
    let f = sst_basis(n);
    // Squared direction cosines of the child axes with each parent axis.
    let ct = vec3<f32>(dot(f[0], t2), dot(f[1], t2), dot(n, t2));
    let cb = vec3<f32>(dot(f[0], b2), dot(f[1], b2), dot(n, b2));
    let cn = vec3<f32>(dot(f[0], n2), dot(f[1], n2), dot(n, n2));
    return vec3<f32>(dot(var_c, ct * ct), dot(var_c, cb * cb), dot(var_c, cn * cn));
}

fn merge(a: Node, b: Node) -> Node {
    if is_empty(a) {
        return b;
    }
    if is_empty(b) {
        return a;
    }
    var wa = luminance(a.intensity);
    var wb = luminance(b.intensity);
    if wa + wb <= 0.0 {
        wa = 1.0;
        wb = 1.0;
    }
    let inv = 1.0 / (wa + wb);
    let ka = wa * inv;
    let kb = wb * inv;
    let p = ka * a.p + kb * b.p;
    let ns = ka * a.n + kb * b.n;
    let l2 = dot(ns, ns);
    var n = select(b.n, a.n, wa >= wb);
    if l2 > 1e-12 {
        n = ns / sqrt(l2);
    }
    let code = oct_encode(n);
    n = oct_decode(code);
    let f = sst_basis(n);
    let da_w = a.p - p;
    let db_w = b.p - p;
    let da = vec3<f32>(dot(da_w, f[0]), dot(da_w, f[1]), dot(da_w, n));
    let db = vec3<f32>(dot(db_w, f[0]), dot(db_w, f[1]), dot(db_w, n));
    let v = ka * (rotate_variance(a.var_xyz, a.n, f[0], f[1], n) + da * da)
        + kb * (rotate_variance(b.var_xyz, b.n, f[0], f[1], n) + db * db);
    let var_xy = pack2x16float(v.xy);
    return Node(
        p,
        a.v * b.v * clamp(dot(a.n, b.n), 0.0, 1.0),
        a.intensity + b.intensity,
        n,
        code,
        min(a.lo, b.lo),
        max(a.hi, b.hi),
        vec3<f32>(unpack2x16float(var_xy), v.z),
        var_xy,
    );
}

