// Stages 12-15 (thesis 5.1.3-5.3) and the baselines: per pixel, choose a cut per slot from
// the 4 surrounding blocks (bilinear weight x similarity S, Algorithm 1) or fall back (mock
// cut by default), traverse from each chosen node with p_left = w_left / (w_left + w_right)
// until a usable node far enough from x (SLC; slc_far_enough), a leaf (RTSLC), or from the
// root (SST, same stop rule as SLC), and evaluate the cluster:
// a point drawn from its substitute distribution (Gaussian in the node's frame, clamped to its
// box; the VPL itself at a leaf) shaded as a VPL of the node's total flux, one shadow ray
// (a substitute's ending sampling.substitute_offset short of it: slc_substitute_end),
// divided by the probability of the path. Sum over slots (SST: mean over its samples); with
// interleaving (sampling.interleave) over the pixel's subset of the slots, x n^2.
// Writes the estimate (or adds it; demodulated for the half-resolution upsampler or the
// interleaving's filter), and, in diagnostic frames only (DIAGNOSTICS), the
// per-pixel diagnostics, the frame counters and the pixel story: a timed frame compiles this
// shader with DIAGNOSTICS = false and computes the same estimate without that work.
// CPU twin: src/reference/slc.rs (cuts, weights, blending); tests check the estimator
// statistically against the ground truth.
#include "common/math.wgsl"
#include "common/color.wgsl"
#include "common/random.wgsl"
#include "common/vpl.wgsl"
#include "common/vpl_visibility.wgsl"
#include "common/sst_node.wgsl"
#include "common/box_term.wgsl"
#include "common/tree_links.wgsl"
#include "common/slc.wgsl"
#include "common/slc_params.wgsl"
#include "common/stats64.wgsl"
#include "common/ism.wgsl"
#include "common/brdf.wgsl"

@group(0) @binding(0) var<uniform> sp: SlcParams;
@group(0) @binding(1) var<storage, read> tree: array<SstNode>;
@group(0) @binding(2) var<storage, read> flags: array<u32>;
@group(0) @binding(3) var<storage, read> sorted_vpls: array<Vpl>;
@group(0) @binding(4) var<storage, read> cuts: array<u32>;
@group(0) @binding(5) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(6) var<storage, read> bvh_triangles: array<BvhTriangle>;
@group(0) @binding(7) var gb_position: texture_2d<f32>;
@group(0) @binding(8) var gb_normal: texture_2d<f32>;
@group(0) @binding(9) var gb_albedo: texture_2d<f32>;
@group(0) @binding(10) var<storage, read_write> accum: array<vec4<f32>>;
// Per pixel: x = traversal steps per traversal, y = 1 if the pixel fell back (no
// similar cut), z = samples evaluated (not dead), w = 1 + the block whose cut its first
// sample used (0: none).
@group(0) @binding(11) var<storage, read_write> diag: array<vec4<f32>>;
// [0] pixels with geometry, [1] fallback pixels, then 64-bit counters as (low, high) word
// pairs: [2..3] traversal steps, [4..5] traversals, [6..7] dead branches, [8..9] shadow rays
// traced (twin: `methods::tree_samplers::pass::SamplingStats::from_words`).
@group(0) @binding(12) var<storage, read_write> stats: array<atomic<u32>>;

// Pipeline-overridable: false in timed frames (no diagnostics, no counters, no story).
override DIAGNOSTICS: bool = true;

// The pixel story (`trace_pixel`): what its samples did this frame. Layout (u32 words, f32
// bitcast) in `methods::tree_samplers::pass::PixelTrace`: a 32-word header, then per sample (the first
// TRACE_SAMPLES) a 64-word record: block slot, start node, end node, steps, stop reason,
// path probability, sampled point xyz, visible, contribution rgb (flux/pi x G x V / prob),
// the cut slot (word 13), 1 + the leaf map looked up (word 14; 0: none), then from word 16 the path as (child taken, its probability)
// pairs. Header words 16-18 (written after the samples): samples taken, the interleaving's
// n^2, the pixel's subset.
@group(0) @binding(13) var<storage, read_write> trace: array<u32>;
// The leaves' imperfect shadow maps (shadow_rays == 2; dummies otherwise): the lookups'
// parameters, the atlas, and per leaf its map's light (written by ism_leaves_main).
@group(0) @binding(14) var<uniform> ism: IsmParams;
@group(0) @binding(15) var<storage, read> ism_depth: array<f32>;
@group(0) @binding(16) var<storage, read_write> ism_lights: array<vec4<f32>>;
// The radix tree's links (a dummy on the perfect tree): common/tree_links.wgsl.
@group(0) @binding(17) var<storage, read> tree_links: array<vec4<u32>>;

fn tree_radix() -> bool {
    return sp.radix != 0u;
}
const TRACE_HEADER: u32 = 32u;
const TRACE_RECORD: u32 = 64u;
const TRACE_SAMPLES: u32 = 64u;
const TRACE_PATH: u32 = 24u;
const NO_TRACE: u32 = 0xffffffffu;

// Per workgroup: pixels, fallback pixels, steps, traversals, dead branches, shadow rays.
const WG_STATS: u32 = 6u;
var<workgroup> wg_stats: array<atomic<u32>, 6>;

// Adds v to the 64-bit counter at stats[i] (low word), stats[i + 1] (high word): the add
// that wraps the low word carries one into the high word, so the pair is exact.
fn is_usable(i: u32) -> bool {
    return ((flags[i / 32u] >> (i % 32u)) & 1u) == 1u;
}

struct Walk {
    node: u32,
    prob: f32,
    steps: u32,
};

// The shading point's glossy lobe for the glossy walk's material term (slc_glossy_term).
struct Lobe {
    v: vec3<f32>,
    f0: vec3<f32>,
    a2: f32,
};

// Descends from `start`; node 0 = dead branch (both children weigh 0). `leaves_only`: the
// glossy samples' walk, which ignores substitutes (SST paper, section 4.3) and, with
// sampling.glossy_weights, weighs each child by the glossy material term towards its box
// (section 4.1; twin: `reference::slc::glossy_child_probability`).
fn traverse(start: u32, x: vec3<f32>, n: vec3<f32>, rng: ptr<function, Rng>, tb: u32,
    leaves_only: bool, lobe: Lobe) -> Walk {
    var node = start;
    var prob = 1.0;
    var steps = 0u;
    loop {
        if node >= sp.leaves || (!leaves_only && sp.method != 2u && is_usable(node)
            && slc_far_enough(tree[node], x, sp.epsilon, sp.near_field)) {
            break;
        }
        let c0 = tree_left(node);
        let c1 = tree_right(node);
        var ml = 1.0;
        var mr = 1.0;
        if leaves_only && sp.glossy_material != 0u {
            let l = tree[c0];
            let r = tree[c1];
            ml = select(slc_glossy_term(l.bbox_min, l.bbox_max, x, n, lobe.v, lobe.f0, lobe.a2), 0.0, sst_is_empty(l));
            mr = select(slc_glossy_term(r.bbox_min, r.bbox_max, x, n, lobe.v, lobe.f0, lobe.a2), 0.0, sst_is_empty(r));
        }
        var pl = slc_child_prob_m(tree[c0], tree[c1], x, n, sp.epsilon, sp.child_probability, ml, mr);
        if leaves_only && sp.glossy_material == 2u {
            // Defensive: a share of the geometric probability, so a child the material
            // term underrates keeps part of its geometric share.
            let pg = slc_child_prob(tree[c0], tree[c1], x, n, sp.epsilon, sp.child_probability);
            pl = select(mix(pl, pg, SLC_GLOSSY_DEFENSIVE), pg, pl < 0.0);
        }
        if pl < 0.0 {
            return Walk(0u, 0.0, steps);
        }
        var pc = pl;
        if rng_next(rng) < pl {
            node = c0;
        } else {
            node = c1;
            pc = 1.0 - pl;
        }
        prob *= pc;
        if tb != NO_TRACE && steps < TRACE_PATH {
            trace[tb + 16u + 2u * steps] = node;
            trace[tb + 17u + 2u * steps] = bitcast<u32>(pc);
        }
        steps += 1u;
    }
    return Walk(node, prob, steps);
}

// Standard normal pair (Box-Muller).
fn gauss2(rng: ptr<function, Rng>) -> vec2<f32> {
    let u1 = 1.0 - rng_next(rng);
    let u2 = rng_next(rng);
    let r = sqrt(-2.0 * log(u1));
    return r * vec2<f32>(cos(TAU * u2), sin(TAU * u2));
}

// Flux/pi x G x V of cluster `node` at x (without the BRDF); `point` receives the light
// point (the VPL or the substitute sample).
fn evaluate(node: u32, x: vec3<f32>, n: vec3<f32>, rng: ptr<function, Rng>, tb: u32,
    rays: ptr<function, u32>, point: ptr<function, vec3<f32>>) -> vec3<f32> {
    var pv: vec3<f32>;
    var nv: vec3<f32>;
    var flux: vec3<f32>;
    if node >= sp.leaves {
        let v = sorted_vpls[node - sp.leaves];
        if v.id == VPL_NONE {
            return vec3<f32>(0.0);
        }
        pv = v.position.xyz;
        nv = v.normal;
        flux = v.flux.rgb;
    } else {
        let c = tree[node];
        nv = oct_decode(c.normal);
        let f = sst_basis(nv);
        let sigma = sqrt(max(sst_variance(c), vec3<f32>(0.0)));
        let g = vec3<f32>(gauss2(rng), gauss2(rng).x);
        pv = clamp(c.position + g.x * sigma.x * f[0] + g.y * sigma.y * f[1] + g.z * sigma.z * nv,
            c.bbox_min, c.bbox_max);
        flux = c.intensity;
    }
    *point = pv;
    let geo = vpl_geometry(pv, nv, x, n, sp.epsilon);
    var lit = geo > 0.0;
    if lit && sp.shadow_rays == 2u {
        // The leaf's map; a substitute sample: a random leaf of the node's subtree.
        var m = node - sp.leaves;
        if node < sp.leaves {
            let r = tree_leaf_range(node, sp.leaves);
            let span = r.y - r.x + 1u;
            m = r.x + min(u32(rng_next(rng) * f32(span)), span - 1u);
        }
        let lv = sorted_vpls[m];
        lit = lv.id == VPL_NONE || ism_visible(m, lv.position.xyz, lv.normal, x);
        *rays += 1u;
        if tb != NO_TRACE {
            trace[tb + 14u] = m + 1u;
        }
    } else if lit && sp.shadow_rays != 0u {
        let o = x + n * sp.ray_offset;
        var e = pv + nv * sp.ray_offset;
        if node < sp.leaves {
            e = slc_substitute_end(e, o, sp.substitute_offset);
        }
        lit = segment_visible(o, e);
        *rays += 1u;
    }
    if tb != NO_TRACE {
        trace[tb + 6u] = bitcast<u32>(pv.x);
        trace[tb + 7u] = bitcast<u32>(pv.y);
        trace[tb + 8u] = bitcast<u32>(pv.z);
        // 0 facing away (G = 0), 1 shadow ray blocked, 2 visible.
        trace[tb + 9u] = select(select(1u, 2u, lit), 0u, geo <= 0.0);
    }
    if !lit {
        return vec3<f32>(0.0);
    }
    return flux / PI * geo;
}

// Per leaf its map's light: the leaf's VPL (position, +inf range; an empty leaf: range 0,
// its map stays empty), normal. Twin: the lights of tests/slc.rs's atlas check.
@compute @workgroup_size(64, 1, 1)
fn ism_leaves_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= sp.leaves {
        return;
    }
    let v = sorted_vpls[i];
    let r2 = select(3.0e38, 0.0, v.id == VPL_NONE);
    ism_lights[2u * i] = vec4<f32>(v.position.xyz, r2);
    ism_lights[2u * i + 1u] = vec4<f32>(v.normal, 0.0);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    if DIAGNOSTICS {
        if li < WG_STATS {
            atomicStore(&wg_stats[li], 0u);
        }
        workgroupBarrier();
    }
    let inside = gid.x < sp.width && gid.y < sp.height;
    var g = vec4<f32>(0.0);
    if inside {
        g = textureLoad(gb_position, vec2<i32>(gid.xy), 0);
    }
    if inside && g.w > 0.0 {
        shade_pixel(gid.xy, g.xyz);
    } else if inside {
        let k = gid.y * sp.width + gid.x;
        if sp.accumulate == 0u {
            accum[k] = vec4<f32>(0.0);
        }
        if DIAGNOSTICS {
            diag[k] = vec4<f32>(0.0);
        }
    }
    if DIAGNOSTICS {
        workgroupBarrier();
        if li < WG_STATS {
            let v = atomicLoad(&wg_stats[li]);
            if v > 0u {
                // [0], [1] 32-bit; the others 64-bit pairs from word 2 on.
                if li < 2u {
                    atomicAdd(&stats[li], v);
                } else {
                    stats_add64(2u + 2u * (li - 2u), v);
                }
            }
        }
    }
}

fn shade_pixel(px: vec2<u32>, x: vec3<f32>) {
    let k = px.y * sp.width + px.x;
    let nr = textureLoad(gb_normal, vec2<i32>(px), 0);
    let n = normalize(nr.xyz);
    let albedo4 = textureLoad(gb_albedo, vec2<i32>(px), 0);
    let albedo = albedo4.rgb;
    // Glossy shading (gi.brdf = GGX; SST paper section 4.3): each sample picks the diffuse or
    // the glossy part of the BRDF by the size of its material term (p_glossy); diffuse samples
    // walk as the method does (substitutes allowed), glossy ones walk to leaf VPLs. RTSLC
    // always ends at leaves and shades with the whole BRDF.
    let glossy_brdf = sp.brdf != BRDF_LAMBERT;
    let v = normalize(sp.eye.xyz - x);
    let metallic = albedo4.a;
    let roughness = nr.w;
    var p_glossy = 0.0;
    if glossy_brdf && sp.method != 2u {
        let f0 = brdf_f0(albedo, metallic);
        let spec_term = luminance(brdf_schlick(f0, max(dot(n, v), 0.0)));
        let diff_term = (1.0 - metallic) * luminance(albedo);
        p_glossy = select(1.0, spec_term / (spec_term + diff_term), spec_term + diff_term > 0.0);
    }
    let a = brdf_alpha(roughness);
    let lobe = Lobe(v, brdf_f0(albedo, metallic), a * a);
    var rng = rng_new(k, sp.seed, 0x51c5u);

    // Blending weights of the 4 surrounding blocks (Algorithm 1).
    var blocks = array<u32, 4>(0u, 0u, 0u, 0u);
    var weights = array<f32, 4>(0.0, 0.0, 0.0, 0.0);
    var bil = array<f32, 4>(0.0, 0.0, 0.0, 0.0);
    var wsum = 0.0;
    let f = (vec2<f32>(px) + 0.5) / f32(sp.block) - 0.5;
    let b0 = floor(f);
    let t = f - b0;
    for (var i = 0u; i < 4u; i++) {
        let d = vec2<i32>(i32(i & 1u), i32(i >> 1u));
        let cb = vec2<i32>(b0) + d;
        var w = select(1.0 - t.x, t.x, d.x == 1) * select(1.0 - t.y, t.y, d.y == 1);
        if sp.blending == 1u {
            // Blending off: only the block holding the pixel.
            let own = vec2<i32>(px / sp.block);
            w = select(0.0, 1.0, all(cb == own));
        }
        if cb.x < 0 || cb.y < 0 || cb.x >= i32(sp.grid_x) || cb.y >= i32(sp.grid_y) {
            w = 0.0;
        }
        let b = u32(cb.y) * sp.grid_x + u32(cb.x);
        blocks[i] = b;
        bil[i] = w;
        if w > 0.0 {
            let c = slc_block_centre(b);
            let gc = textureLoad(gb_position, vec2<i32>(c), 0);
            let nc = normalize(textureLoad(gb_normal, vec2<i32>(c), 0).xyz);
            if gc.w == 0.0 || !slc_similar(x, n, gc.xyz, nc, sp.n_min, sp.d_max) {
                w = 0.0;
            }
        }
        weights[i] = w;
        wsum += w;
    }

    // Start nodes: 0 = the blended cuts, 1 = mock cut, 2 = from the root, 3 = own cut.
    var mode = 0u;
    var fell_back = false;
    if sp.method == 1u {
        mode = 2u;
    } else if !(wsum > 0.0) {
        fell_back = true;
        switch sp.fallback {
            case 1u: {
                // Average the (dissimilar) cuts: bilinear weights alone.
                wsum = 0.0;
                for (var i = 0u; i < 4u; i++) {
                    weights[i] = bil[i];
                    wsum += bil[i];
                }
                mode = select(1u, 0u, wsum > 0.0);
            }
            case 2u: {
                mode = 2u;
            }
            case 3u: {
                mode = 3u;
            }
            default: {
                mode = 1u;
            }
        }
    }
    let tracing = DIAGNOSTICS && sp.trace_pixel != NO_TRACE
        && sp.trace_pixel == (px.x | (px.y << 16u));
    if tracing {
        trace[0] = 1u;
        trace[1] = mode;
        trace[2] = select(0u, 1u, fell_back);
        for (var i = 0u; i < 4u; i++) {
            trace[3u + i] = blocks[i];
            trace[7u + i] = bitcast<u32>(bil[i]);
            trace[11u + i] = bitcast<u32>(weights[i]);
        }
        trace[15] = bitcast<u32>(wsum);
    }
    var own_count = 0u;
    if mode == 3u {
        own_count = slc_build_cut(x, n, sp.epsilon, sp.cut_size, sp.cull != 0u, sp.leaves);
    }
    let mock_level = min(firstLeadingBit(max(sp.cut_size, 1u)), sp.levels - 1u);

    var sum = vec3<f32>(0.0);
    var steps = 0u;
    var walks = 0u;
    var evaluated = 0u;
    var first_block = 0u;
    var dead = 0u;
    var rays = 0u;
    // Interleaved sampling over the cut's slots (sampling.interleave; Stochastic Light Culling
    // section 4.2): subset s of the n x n pattern takes the slots i = first + j n^2 with
    // first = (s - the frame's offset) mod n^2, each x n^2, so a pattern's pixels share every
    // slot out exactly once and over frames each pixel takes each slot with probability
    // 1 / n^2. SST and the root fallback, whose samples each estimate the whole sum, take
    // their share of the samples (at least one) and average them. n = 1: every slot.
    // Twin: reference::interleave::slot_subset.
    let cells = sp.interleave * sp.interleave;
    let subset = px.x % sp.interleave + sp.interleave * (px.y % sp.interleave);
    let first = (subset + cells - sp.interleave_offset % cells) % cells;
    var end = sp.cut_size;
    if mode == 2u {
        end = max(end, first + 1u);
    }
    var taken = 0u;
    for (var i = first; i < end; i += cells) {
        var start = 0u;
        var slot = 4u;
        let tb = select(NO_TRACE, TRACE_HEADER + taken * TRACE_RECORD, tracing && taken < TRACE_SAMPLES);
        let first_sample = taken == 0u;
        taken += 1u;
        switch mode {
            case 0u: {
                var u = rng_next(&rng) * wsum;
                var s = 3u;
                for (var j = 0u; j < 3u; j++) {
                    if u < weights[j] && weights[j] > 0.0 {
                        s = j;
                        break;
                    }
                    u -= weights[j];
                }
                // Rounding may leave u past the last positive weight: take the last one.
                if !(weights[s] > 0.0) {
                    for (var j = 0u; j < 4u; j++) {
                        if weights[j] > 0.0 {
                            s = j;
                        }
                    }
                }
                start = cuts[blocks[s] * sp.cut_size + i];
                slot = s;
                if first_sample {
                    first_block = blocks[s] + 1u;
                }
            }
            case 1u: {
                // The perfect tree's level; the radix tree's mock cut after the blocks' cuts
                // (slc_cuts.wgsl).
                if tree_radix() {
                    start = cuts[sp.grid_x * sp.grid_y * sp.cut_size + i];
                } else if i < (1u << mock_level) {
                    start = (1u << mock_level) + i;
                }
            }
            case 2u: {
                start = 1u;
            }
            default: {
                start = select(0u, cut_ids[i], i < own_count);
            }
        }
        if tb != NO_TRACE {
            trace[tb] = slot;
            trace[tb + 1u] = start;
            // Stop reason 3: an empty cut slot (nothing sampled).
            trace[tb + 4u] = 3u;
            trace[tb + 13u] = i;
        }
        if start == 0u {
            continue;
        }
        // The lobe of this sample (a glossy BRDF only; RTSLC takes the whole BRDF).
        var glossy_sample = false;
        if glossy_brdf && sp.method != 2u {
            glossy_sample = rng_next(&rng) < p_glossy;
        }
        let walk = traverse(start, x, n, &rng, tb, glossy_sample, lobe);
        steps += walk.steps;
        walks += 1u;
        if tb != NO_TRACE {
            trace[tb + 2u] = walk.node;
            trace[tb + 3u] = walk.steps;
            trace[tb + 5u] = bitcast<u32>(walk.prob);
            // 0 usable node, 1 leaf, 2 dead branch (both children weigh 0).
            trace[tb + 4u] = select(select(0u, 1u, walk.node >= sp.leaves), 2u, walk.node == 0u);
        }
        if walk.node == 0u {
            dead += 1u;
            continue;
        }
        evaluated += 1u;
        var point = vec3<f32>(0.0);
        var c = evaluate(walk.node, x, n, &rng, tb, &rays, &point) / walk.prob;
        if glossy_brdf {
            let l = normalize(point - x);
            if sp.method == 2u {
                c *= brdf_eval(sp.brdf, n, v, l, albedo, metallic, roughness);
            } else if glossy_sample {
                c *= brdf_specular(sp.brdf, n, v, l, albedo, metallic, roughness) / p_glossy;
            } else {
                c *= brdf_diffuse(sp.brdf, n, v, l, albedo, metallic) / (1.0 - p_glossy);
            }
        }
        if tb != NO_TRACE {
            trace[tb + 10u] = bitcast<u32>(c.x);
            trace[tb + 11u] = bitcast<u32>(c.y);
            trace[tb + 12u] = bitcast<u32>(c.z);
        }
        sum += c;
    }
    if DIAGNOSTICS {
        atomicAdd(&wg_stats[0], 1u);
        if fell_back {
            atomicAdd(&wg_stats[1], 1u);
        }
        atomicAdd(&wg_stats[2], steps);
        atomicAdd(&wg_stats[3], walks);
        atomicAdd(&wg_stats[4], dead);
        atomicAdd(&wg_stats[5], rays);
    }
    if mode == 2u {
        // From the root: every sample estimates the whole sum.
        sum /= f32(max(taken, 1u));
    } else {
        // The subset's slots stand for the whole cut.
        sum *= f32(cells);
    }
    if tracing {
        trace[16] = taken;
        trace[17] = cells;
        trace[18] = subset;
    }
    // Demodulated (half-resolution GI, interleaving): without the albedo, which the upsampler
    // or the interleaving's filter applies.
    var radiance = albedo / PI * sum;
    if glossy_brdf {
        // The BRDF is in every sample (validation keeps demodulation off with it).
        radiance = sum;
    } else if sp.demodulate != 0u {
        radiance = sum / PI;
    }
    if sp.accumulate == 0u {
        accum[k] = vec4<f32>(radiance, 0.0);
    } else {
        accum[k] += vec4<f32>(radiance, 0.0);
    }
    if DIAGNOSTICS {
        diag[k] = vec4<f32>(f32(steps) / f32(max(walks, 1u)), select(0.0, 1.0, fell_back),
            f32(evaluated), f32(first_block));
    }
}
