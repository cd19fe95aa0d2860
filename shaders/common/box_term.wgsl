// The thesis's geometric term of a cluster (eq. 5.2) with the inverse squared distance to
// its box: for surface point x with normal n and the box [lo, hi],
//   G = (1/8 sum over the corners c of max(n . (c - x)/|c - x|, 0)) / max(d_min^2, eps^2),
// d_min = the distance from x to the box (0 inside). 0 exactly when every corner is on or
// behind x's tangent plane, i.e. when nothing inside the box can light x. Used by the tree
// converged reference's pyramid descent; the tree samplers' node weights (common/slc.wgsl)
// use its cosine part with the distance to the node's mean position instead.
// CPU twin: `box_term` in src/reference/slc.rs.
// The average clamped cosine of eq. 5.2 alone: 1/8 sum over the corners of the box of
// max(n . (c - x)/|c - x|, 0). CPU twin: `box_cos` in src/reference/slc.rs.
fn box_cos(lo: vec3<f32>, hi: vec3<f32>, x: vec3<f32>, n: vec3<f32>) -> f32 {
    var cos_sum = 0.0;
    for (var c = 0u; c < 8u; c++) {
        let p = select(lo, hi, vec3<bool>((c & 1u) != 0u, (c & 2u) != 0u, (c & 4u) != 0u));
        let d = p - x;
        cos_sum += max(dot(n, d) / sqrt(max(dot(d, d), 1e-30)), 0.0);
    }
    if !(cos_sum > 0.0) {
        return 0.0;
    }
    return cos_sum * 0.125;
}

fn box_term(lo: vec3<f32>, hi: vec3<f32>, x: vec3<f32>, n: vec3<f32>, eps: f32) -> f32 {
    let g = box_cos(lo, hi, x, n);
    if g == 0.0 {
        return 0.0;
    }
    let q = clamp(x, lo, hi);
    let d2 = dot(q - x, q - x);
    return g / max(d2, eps * eps);
}
