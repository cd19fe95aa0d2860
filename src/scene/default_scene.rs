//! The embedded default scene, built in code (metres, +Y up).
//!
//! A closed 6 x 3 x 5 m room (x in [-3, 3], y in [0, 3], z in [-2.5, 2.5]) built from thin
//! boxes, with a window opening in the back wall (z = -2.5) fitted with tilted blind slats.
//! A sun low in the sky behind the back wall shines through the blinds and makes a striped
//! patch on the checkered floor, where two boxes and a sphere stand. The left wall is red
//! and the right wall green, so colour bleeding is visible; the rest is off-white.
//!
//! Every face is a closed box side or sphere patch with its normal pointing out of its
//! solid, so the faces seen from inside the room face the room. Front faces are CCW.

use glam::{Quat, Vec2, Vec3};

use super::{Camera, DirectionalLight, Material, Scene, TextureImage};

/// Room half extents in x and z, and height.
const HX: f32 = 3.0;
const HZ: f32 = 2.5;
const H: f32 = 3.0;
/// Wall thickness (real walls are 20-30 cm; thick enough for the shadow map's slope bias at
/// grazing light not to leak through at 512 texels).
const T: f32 = 0.25;
/// Window opening in the back wall: x in [-WX, WX], y in [WY0, WY1].
const WX: f32 = 1.0;
const WY0: f32 = 1.0;
const WY1: f32 = 2.4;

/// Sun angles (see [`DirectionalLight::from_angles`]) and irradiance in W/m^2.
pub const SUN_AZIMUTH_DEG: f32 = -75.0;
pub const SUN_ELEVATION_DEG: f32 = 40.0;
pub const SUN_IRRADIANCE: f32 = 10.0;

// Material indices.
const M_WHITE: u32 = 0;
const M_RED: u32 = 1;
const M_GREEN: u32 = 2;
const M_FLOOR: u32 = 3;
const M_BOX: u32 = 4;
const M_SPHERE: u32 = 5;
const M_BLIND: u32 = 6;

/// Builds the default scene. Deterministic; about 1.2k triangles.
pub fn build() -> Scene {
    let mut s = Scene {
        name: "Default room".into(),
        ..Default::default()
    };
    let mat = |name: &str, c: [f32; 3], tex: Option<usize>| Material {
        name: name.into(),
        base_color_factor: [c[0], c[1], c[2], 1.0],
        base_color_texture: tex,
        ..Default::default()
    };
    s.materials = vec![
        mat("white wall", [0.73, 0.73, 0.70], None),
        mat("red wall", [0.63, 0.065, 0.05], None),
        mat("green wall", [0.14, 0.45, 0.09], None),
        mat("checker floor", [1.0, 1.0, 1.0], Some(0)),
        mat("white box", [0.75, 0.75, 0.75], None),
        mat("blue sphere", [0.15, 0.25, 0.65], None),
        mat("blind slat", [0.85, 0.83, 0.78], None),
    ];
    s.textures.push(checker_texture(128, 16));

    let id = Quat::IDENTITY;
    // Floor and ceiling slabs (the floor's top face carries the checker UVs).
    add_box(
        &mut s,
        Vec3::new(0.0, -T / 2.0, 0.0),
        Vec3::new(HX + T, T / 2.0, HZ + T),
        id,
        M_FLOOR,
    );
    add_box(
        &mut s,
        Vec3::new(0.0, H + T / 2.0, 0.0),
        Vec3::new(HX + T, T / 2.0, HZ + T),
        id,
        M_WHITE,
    );
    // Left (red) and right (green) walls.
    let side = Vec3::new(T / 2.0, H / 2.0, HZ);
    add_box(&mut s, Vec3::new(-HX - T / 2.0, H / 2.0, 0.0), side, id, M_RED);
    add_box(&mut s, Vec3::new(HX + T / 2.0, H / 2.0, 0.0), side, id, M_GREEN);
    // Front wall.
    add_box(
        &mut s,
        Vec3::new(0.0, H / 2.0, HZ + T / 2.0),
        Vec3::new(HX, H / 2.0, T / 2.0),
        id,
        M_WHITE,
    );
    // Back wall with the window opening: below, above, left and right of it.
    let zb = -HZ - T / 2.0;
    add_box(
        &mut s,
        Vec3::new(0.0, WY0 / 2.0, zb),
        Vec3::new(HX, WY0 / 2.0, T / 2.0),
        id,
        M_WHITE,
    );
    add_box(
        &mut s,
        Vec3::new(0.0, (WY1 + H) / 2.0, zb),
        Vec3::new(HX, (H - WY1) / 2.0, T / 2.0),
        id,
        M_WHITE,
    );
    let wside = Vec3::new((HX - WX) / 2.0, (WY1 - WY0) / 2.0, T / 2.0);
    let wy = (WY0 + WY1) / 2.0;
    add_box(&mut s, Vec3::new(-(HX + WX) / 2.0, wy, zb), wside, id, M_WHITE);
    add_box(&mut s, Vec3::new((HX + WX) / 2.0, wy, zb), wside, id, M_WHITE);

    // Blinds: 10 slats 8 cm deep, 1.5 cm thick, tilted 35 degrees (inner edge down), 14 cm apart, hanging just
    // inside the window opening.
    let slats = 10;
    let pitch = (WY1 - WY0) / slats as f32;
    for k in 0..slats {
        let y = WY0 + (k as f32 + 0.5) * pitch;
        let rot = Quat::from_rotation_x(35f32.to_radians());
        add_box(
            &mut s,
            Vec3::new(0.0, y, -HZ + 0.06),
            Vec3::new(WX - 0.02, 0.0075, 0.04),
            rot,
            M_BLIND,
        );
    }

    // Objects in the sunlit area.
    add_box(
        &mut s,
        Vec3::new(-1.5, 0.55, -1.0),
        Vec3::new(0.25, 0.55, 0.25),
        Quat::from_rotation_y(20f32.to_radians()),
        M_BOX,
    );
    add_box(
        &mut s,
        Vec3::new(0.55, 0.2, -1.0),
        Vec3::new(0.3, 0.2, 0.3),
        Quat::from_rotation_y(-15f32.to_radians()),
        M_BOX,
    );
    add_sphere(&mut s, Vec3::new(-0.5, 0.3, -0.2), 0.3, 24, 16, M_SPHERE);

    s.lights.push(DirectionalLight::from_angles(
        "sun",
        SUN_AZIMUTH_DEG,
        SUN_ELEVATION_DEG,
        Vec3::splat(SUN_IRRADIANCE),
    ));
    s.cameras.push(Camera::look_at(
        "Main",
        Vec3::new(2.3, 1.5, 2.2),
        Vec3::new(-0.9, 0.5, -0.7),
        55f32.to_radians(),
        0.01,
        30.0,
    ));
    s.cameras.push(Camera::look_at(
        "Overview",
        Vec3::new(2.85, 2.85, 2.35),
        Vec3::new(-0.6, 0.2, -0.9),
        75f32.to_radians(),
        0.01,
        30.0,
    ));
    s.recompute_bounds();
    s
}

/// A grey sRGB checkerboard, `size` x `size` texels with `checks` squares per side.
pub fn checker_texture(size: u32, checks: u32) -> TextureImage {
    let cell = (size / checks.max(1)).max(1);
    let mut rgba8 = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            let v = if ((x / cell) + (y / cell)).is_multiple_of(2) {
                190
            } else {
                130
            };
            rgba8.extend_from_slice(&[v, v, v, 255]);
        }
    }
    TextureImage {
        name: "checker".into(),
        width: size,
        height: size,
        rgba8,
    }
}

pub(crate) fn push_vertex(s: &mut Scene, p: Vec3, n: Vec3, uv: Vec2) -> u32 {
    s.positions.push(p);
    s.normals.push(n);
    s.uvs.push(uv);
    (s.positions.len() - 1) as u32
}

/// Pushes a triangle, ordering it CCW around the average of its vertex normals.
pub(crate) fn push_triangle(s: &mut Scene, a: u32, b: u32, c: u32, material: u32) {
    let (pa, pb, pc) = (
        s.positions[a as usize],
        s.positions[b as usize],
        s.positions[c as usize],
    );
    let n = s.normals[a as usize] + s.normals[b as usize] + s.normals[c as usize];
    if (pb - pa).cross(pc - pa).dot(n) >= 0.0 {
        s.indices.extend_from_slice(&[a, b, c]);
    } else {
        s.indices.extend_from_slice(&[a, c, b]);
    }
    s.triangle_materials.push(material);
}

/// A box with centre `c`, half extents `h` in its local frame, rotated by `rot`; faces point
/// out of the box. Each face has UVs spanning [0, 1].
pub(crate) fn add_box(s: &mut Scene, c: Vec3, h: Vec3, rot: Quat, material: u32) {
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    for a in 0..3 {
        for sign in [1.0f32, -1.0] {
            let n = axes[a] * sign;
            let u = axes[(a + 1) % 3];
            let v = axes[(a + 2) % 3];
            let (hn, hu, hv) = (h[a], h[(a + 1) % 3], h[(a + 2) % 3]);
            let corner = |du: f32, dv: f32| c + rot * (n * hn + u * (du * hu) + v * (dv * hv));
            let wn = (rot * n).normalize();
            let ids: Vec<u32> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .iter()
                .map(|&(du, dv)| {
                    let uv = Vec2::new(0.5 * (du + 1.0), 0.5 * (dv + 1.0));
                    push_vertex(s, corner(du, dv), wn, uv)
                })
                .collect();
            push_triangle(s, ids[0], ids[1], ids[2], material);
            push_triangle(s, ids[0], ids[2], ids[3], material);
        }
    }
}

/// A UV sphere with smooth outward normals.
pub(crate) fn add_sphere(s: &mut Scene, c: Vec3, r: f32, slices: u32, stacks: u32, material: u32) {
    let base = s.positions.len() as u32;
    for i in 0..=stacks {
        let theta = std::f32::consts::PI * i as f32 / stacks as f32;
        for j in 0..=slices {
            let phi = std::f32::consts::TAU * j as f32 / slices as f32;
            let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            let uv = Vec2::new(j as f32 / slices as f32, i as f32 / stacks as f32);
            push_vertex(s, c + r * n, n, uv);
        }
    }
    let idx = |i: u32, j: u32| base + i * (slices + 1) + j;
    for i in 0..stacks {
        for j in 0..slices {
            let (a, b, cc, d) = (idx(i, j), idx(i, j + 1), idx(i + 1, j + 1), idx(i + 1, j));
            if i != 0 {
                push_triangle(s, a, b, cc, material);
            }
            if i != stacks - 1 {
                push_triangle(s, a, cc, d, material);
            }
        }
    }
}
