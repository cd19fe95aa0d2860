// Light-tree overlay over the camera view: the nodes of one tree level drawn as their
// substitute distributions (an ellipse in the node's plane, semi-axes 1 and 2 standard
// deviations along tangent and bitangent, filled inside 1 sigma) or as their bounding boxes.
// Parts behind the G-buffer surface are drawn faint. Colour: node flux on a log scale around
// the level's mean (false colour: 1/100 of the mean -> 0, 100x -> 1), the usable flag
// (green / red), or a colour per node. On the radix tree (issue 23), whose leaves lie at many
// depths, "level l" is the cut of the nodes at depth l and the leaves above it: every VPL once,
// as the perfect tree's level.
#include "common/camera.wgsl"
#include "common/color.wgsl"
#include "common/sst_node.wgsl"
#include "common/tree_links.wgsl"

struct OverlayParams {
    level: u32,      // tree level drawn (root = 0)
    color_mode: u32, // 0 intensity, 1 usable flag, 2 node id
    min_radius: f32, // smallest drawn semi-axis (metres), so leaves stay visible
    radix: u32,      // 1: the radix tree (instances: every node; depth from the parents)
    leaves: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> op: OverlayParams;
@group(0) @binding(1) var<uniform> camera: Camera;
@group(0) @binding(2) var<storage, read> tree: array<SstNode>;
@group(0) @binding(3) var<storage, read> flags: array<u32>;
@group(0) @binding(4) var gb_position: texture_2d<f32>;
// The radix tree's parents (a dummy on the perfect tree).
@group(0) @binding(5) var<storage, read> parents: array<u32>;
// The radix tree's links (a dummy on the perfect tree): common/tree_links.wgsl.
@group(0) @binding(6) var<storage, read> tree_links: array<vec4<u32>>;

fn tree_radix() -> bool {
    return op.radix != 0u;
}

// The node instance `ii` draws, or 0 when it is not in the level's cut.
fn instance_node(ii: u32) -> u32 {
    if op.radix == 0u {
        return (1u << op.level) + ii;
    }
    let i = ii + 1u;
    var depth = 0u;
    var n = i;
    while n != 1u && depth <= op.level {
        n = parents[n];
        depth += 1u;
    }
    if depth == op.level || (i >= op.leaves && depth < op.level) {
        return i;
    }
    return 0u;
}

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) local: vec2<f32>,      // position in units of sigma (ellipses)
    @location(1) world: vec3<f32>,
    @location(2) color: vec3<f32>,
};

fn node_color(i: u32, node: SstNode) -> vec3<f32> {
    if op.color_mode == 1u {
        let usable = (flags[i / 32u] >> (i % 32u)) & 1u;
        return select(vec3<f32>(0.95, 0.22, 0.18), vec3<f32>(0.25, 0.9, 0.3), usable == 1u);
    }
    if op.color_mode == 2u {
        return id_color(i);
    }
    // Flux per leaf against the root's (on the perfect tree: the node's flux against its
    // level's mean).
    let r = tree_node_range(i, op.leaves);
    let span = f32(r.y - r.x + 1u);
    let mean = luminance(tree[1].intensity) / f32(op.leaves);
    let t = (log2(max(luminance(node.intensity) / span, 1e-30) / max(mean, 1e-30)) * 0.30103 + 2.0) / 4.0;
    return false_color(t);
}

// Outside the clip volume: an empty node draws nothing.
fn hidden() -> VsOut {
    return VsOut(vec4<f32>(2.0, 2.0, 2.0, 1.0), vec2<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
}

@vertex
fn vs_ellipse(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> VsOut {
    let i = instance_node(ii);
    if i == 0u {
        return hidden();
    }
    let node = tree[i];
    if sst_is_empty(node) {
        return hidden();
    }
    let corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    );
    let c = corners[vi] * 2.1;
    let n = oct_decode(node.normal);
    let f = sst_basis(n);
    let sigma = max(sqrt(max(sst_variance(node).xy, vec2<f32>(0.0))), vec2<f32>(op.min_radius));
    let world = node.position + c.x * sigma.x * f[0] + c.y * sigma.y * f[1];
    return VsOut(camera.view_proj * vec4<f32>(world, 1.0), c, world, node_color(i, node));
}

@vertex
fn vs_box(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> VsOut {
    let i = instance_node(ii);
    if i == 0u {
        return hidden();
    }
    let node = tree[i];
    if sst_is_empty(node) {
        return hidden();
    }
    // 12 edges: corner bits (x = 1, y = 2, z = 4); each edge joins corners differing in one bit.
    let edges = array<vec2<u32>, 12>(
        vec2<u32>(0u, 1u), vec2<u32>(2u, 3u), vec2<u32>(4u, 5u), vec2<u32>(6u, 7u),
        vec2<u32>(0u, 2u), vec2<u32>(1u, 3u), vec2<u32>(4u, 6u), vec2<u32>(5u, 7u),
        vec2<u32>(0u, 4u), vec2<u32>(1u, 5u), vec2<u32>(2u, 6u), vec2<u32>(3u, 7u),
    );
    let e = edges[vi / 2u];
    let k = select(e.x, e.y, (vi & 1u) == 1u);
    let lo = node.bbox_min - vec3<f32>(op.min_radius * 0.25);
    let hi = node.bbox_max + vec3<f32>(op.min_radius * 0.25);
    let world = select(lo, hi, vec3<bool>((k & 1u) != 0u, (k & 2u) != 0u, (k & 4u) != 0u));
    return VsOut(camera.view_proj * vec4<f32>(world, 1.0), vec2<f32>(0.0), world, node_color(i, node));
}

// Alpha for a fragment at `world`: faint where the G-buffer surface is in front.
fn visibility(frag: vec4<f32>, world: vec3<f32>) -> f32 {
    let g = textureLoad(gb_position, vec2<i32>(frag.xy), 0);
    let dv = distance(camera.position.xyz, world);
    let dg = distance(camera.position.xyz, g.xyz);
    if g.w > 0.0 && dv > dg * 1.01 + 0.02 {
        return 0.3;
    }
    return 1.0;
}

@fragment
fn fs_ellipse(in: VsOut) -> @location(0) vec4<f32> {
    let r = length(in.local);
    let w = max(fwidth(r), 1e-4);
    // A ring at 1 sigma (about 1.5 px wide), a fainter one at 2 sigma, a light fill inside 1 sigma.
    let ring1 = 1.0 - smoothstep(0.0, 1.5 * w, abs(r - 1.0));
    let ring2 = 1.0 - smoothstep(0.0, 1.0 * w, abs(r - 2.0));
    var a = max(max(ring1 * 0.95, ring2 * 0.4), select(0.0, 0.22, r < 1.0));
    if r > 2.0 + 1.5 * w || a <= 0.0 {
        discard;
    }
    a *= visibility(in.clip, in.world);
    return vec4<f32>(in.color, a);
}

@fragment
fn fs_box(in: VsOut) -> @location(0) vec4<f32> {
    return vec4<f32>(in.color, 0.9 * visibility(in.clip, in.world));
}
