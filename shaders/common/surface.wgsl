// The surface a BVH ray hit (issue 23's light paths: a bounce's VPL sits there): position,
// normals, texture coordinates, material and diffuse albedo, from the triangle and the hit's
// barycentrics. Compute shaders have no derivatives, so the albedo is read at an explicit mip
// level (`lod`), nearest texel (a VPL is a point sample; the level sets how much texture
// detail one VPL averages). CPU twin: `reference::surface::surface_at`.
// Contract: the includer includes common/material.wgsl and declares
// `scene_vertices: array<u32>` (GpuVertex: 9 words each), `scene_indices: array<u32>`,
// `materials: array<MaterialGpu>` and `textures: texture_2d_array<f32>`.

const VERTEX_WORDS: u32 = 9u;

struct Surface {
    position: vec3<f32>,
    material: u32,
    // The interpolated vertex normal, on the side the ray came from (the geometric normal's).
    normal: vec3<f32>,
    valid: u32,
    // The triangle's normal, facing the ray's origin.
    geometric_normal: vec3<f32>,
    _pad: u32,
    albedo: vec3<f32>,
    _pad1: u32,
    uv: vec2<f32>,
    _pad2: vec2<u32>,
};

fn vertex_vec3(i: u32, word: u32) -> vec3<f32> {
    let b = i * VERTEX_WORDS + word;
    return vec3<f32>(bitcast<f32>(scene_vertices[b]), bitcast<f32>(scene_vertices[b + 1u]),
        bitcast<f32>(scene_vertices[b + 2u]));
}

fn vertex_uv(i: u32) -> vec2<f32> {
    let b = i * VERTEX_WORDS + 6u;
    return vec2<f32>(bitcast<f32>(scene_vertices[b]), bitcast<f32>(scene_vertices[b + 1u]));
}

// The base colour at `uv` (repeat), mip level `lod` (clamped to the chain), nearest texel.
fn material_albedo_lod(material: u32, uv: vec2<f32>, lod: u32) -> vec4<f32> {
    let m = materials[material];
    var albedo = m.base_color;
    if m.texture.x >= 0 {
        let level = min(lod, textureNumLevels(textures) - 1u);
        // Level `level`'s size from level 0's (each level halves, at least 1): the same as
        // textureDimensions(textures, level), which lavapipe answers with level 0's size
        // when the level is not a compile-time constant.
        let size = max(textureDimensions(textures) >> vec2<u32>(level), vec2<u32>(1u));
        let f = uv - floor(uv);
        let t = min(vec2<u32>(f * vec2<f32>(size)), size - 1u);
        // Rgba8UnormSrgb: the load returns linear values.
        albedo *= textureLoad(textures, t, m.texture.x, level);
    }
    return albedo;
}

// Triangle `tri` at barycentrics (u, v) (weights 1 - u - v, u, v of its corners), hit by a ray
// along `dir`.
fn surface_at(tri: u32, u: f32, v: f32, dir: vec3<f32>, lod: u32) -> Surface {
    var s: Surface;
    let i0 = scene_indices[3u * tri];
    let i1 = scene_indices[3u * tri + 1u];
    let i2 = scene_indices[3u * tri + 2u];
    let w = 1.0 - u - v;
    let p0 = vertex_vec3(i0, 0u);
    let p1 = vertex_vec3(i1, 0u);
    let p2 = vertex_vec3(i2, 0u);
    s.position = w * p0 + u * p1 + v * p2;
    var ng = cross(p1 - p0, p2 - p0);
    let len = length(ng);
    s.valid = select(0u, 1u, len > 0.0);
    ng = select(vec3<f32>(0.0, 0.0, 1.0), ng / max(len, 1e-30), len > 0.0);
    if dot(ng, dir) > 0.0 {
        ng = -ng;
    }
    s.geometric_normal = ng;
    var ns = w * vertex_vec3(i0, 3u) + u * vertex_vec3(i1, 3u) + v * vertex_vec3(i2, 3u);
    let nl = length(ns);
    ns = select(ng, ns / max(nl, 1e-30), nl > 0.0);
    if dot(ns, ng) < 0.0 {
        ns = -ns;
    }
    s.normal = ns;
    s.uv = w * vertex_uv(i0) + u * vertex_uv(i1) + v * vertex_uv(i2);
    s.material = scene_vertices[i0 * VERTEX_WORDS + 8u];
    s.albedo = material_albedo_lod(s.material, s.uv, lod).rgb;
    return s;
}
