//! The built-in scenes, written in code (no files): the default room and three small test
//! scenes that stress what the default room does not (issue 37). Every method's bias contract
//! (`tests/methods.rs`) runs on all of them, and `--scene <name>` (CLI) or the scene buttons
//! (GUI) open them.
//!
//! - `window-box`: a closed box lit by the sun through one small window; the sunlit patch is
//!   small, so most of the image is lit indirectly (the VPLs' light dominates).
//! - `corridor`: a 16 m corridor lit through a ceiling opening at its far end, seen from the
//!   other end: the pixels near the camera are lit by VPLs 10 m or more away, which stresses
//!   clustering, light trees' far nodes and distance clamping.
//! - `glossy-thin`: metal (glTF metallic 1, roughness 0.2-0.35) and thin geometry (a window
//!   grille of 2 cm bars, a 2 cm table top on thin legs, a 5 mm hanging plate): GGX shading,
//!   thin occluders in shadow maps, ISMs and BVH rays.
//!
//! Units: metres, +Y up; suns in W/m^2 (glTF's `intensity` of a directional light).

use glam::{Quat, Vec3};

use super::default_scene::{self, add_box, add_sphere};
use super::{Camera, DirectionalLight, Material, Scene};

/// A scene the workbench carries in code.
pub struct BuiltinScene {
    /// Its name for `--scene` and the GUI's button.
    pub name: &'static str,
    /// One line: what it is for.
    pub about: &'static str,
    /// Builds it (deterministic; a few hundred to a thousand triangles).
    pub build: fn() -> Scene,
}

/// Every built-in scene, the default room first.
pub static BUILTIN: &[BuiltinScene] = &[
    BuiltinScene {
        name: "default",
        about: "the default room: sunlight through blinds, coloured walls, two boxes and a sphere",
        build: default_scene::build,
    },
    BuiltinScene {
        name: "window-box",
        about: "a closed box lit through one small window: mostly indirect light",
        build: window_box,
    },
    BuiltinScene {
        name: "corridor",
        about: "a 16 m corridor lit through a ceiling opening at its far end: light from far VPLs",
        build: corridor,
    },
    BuiltinScene {
        name: "glossy-thin",
        about: "metal surfaces (for GGX) and thin geometry: a window grille, a thin table, a hanging plate",
        build: glossy_thin,
    },
];

/// The built-in scene called `name` (exactly as listed in [`BUILTIN`]).
pub fn find(name: &str) -> Option<&'static BuiltinScene> {
    BUILTIN.iter().find(|b| b.name == name)
}

/// The names of every built-in scene.
pub fn names() -> Vec<&'static str> {
    BUILTIN.iter().map(|b| b.name).collect()
}

const T: f32 = 0.25;

fn mat(name: &str, c: [f32; 3]) -> Material {
    Material {
        name: name.into(),
        base_color_factor: [c[0], c[1], c[2], 1.0],
        ..Default::default()
    }
}

fn metal(name: &str, c: [f32; 3], roughness: f32) -> Material {
    Material {
        metallic: 1.0,
        roughness,
        ..mat(name, c)
    }
}

/// Materials every room uses, by index.
struct RoomMaterials {
    floor: u32,
    ceiling: u32,
    left: u32,
    right: u32,
    front: u32,
    back: u32,
}

/// A closed room x in [-hx, hx], y in [0, h], z in [-hz, hz] of walls `T` thick, the back wall
/// (z = -hz) with an optional window `[x0, x1] x [y0, y1]`, the ceiling with an optional
/// opening over z in `[z0, z1]` (across the whole width).
fn room(
    s: &mut Scene,
    (hx, h, hz): (f32, f32, f32),
    window: Option<[f32; 4]>,
    ceiling_opening: Option<[f32; 2]>,
    m: &RoomMaterials,
) {
    let id = Quat::IDENTITY;
    add_box(
        s,
        Vec3::new(0.0, -T / 2.0, 0.0),
        Vec3::new(hx + T, T / 2.0, hz + T),
        id,
        m.floor,
    );
    // Ceiling, in one piece or either side of its opening.
    let (c0, c1) = ceiling_opening.map_or((hz + T, hz + T), |[z0, z1]| (z0, z1));
    let yc = h + T / 2.0;
    if ceiling_opening.is_none() {
        add_box(
            s,
            Vec3::new(0.0, yc, 0.0),
            Vec3::new(hx + T, T / 2.0, hz + T),
            id,
            m.ceiling,
        );
    } else {
        for (a, b) in [(-hz - T, c0), (c1, hz + T)] {
            if b - a > 1e-3 {
                add_box(
                    s,
                    Vec3::new(0.0, yc, 0.5 * (a + b)),
                    Vec3::new(hx + T, T / 2.0, 0.5 * (b - a)),
                    id,
                    m.ceiling,
                );
            }
        }
    }
    let side = Vec3::new(T / 2.0, h / 2.0, hz);
    add_box(s, Vec3::new(-hx - T / 2.0, h / 2.0, 0.0), side, id, m.left);
    add_box(s, Vec3::new(hx + T / 2.0, h / 2.0, 0.0), side, id, m.right);
    add_box(
        s,
        Vec3::new(0.0, h / 2.0, hz + T / 2.0),
        Vec3::new(hx, h / 2.0, T / 2.0),
        id,
        m.front,
    );
    let zb = -hz - T / 2.0;
    match window {
        None => add_box(
            s,
            Vec3::new(0.0, h / 2.0, zb),
            Vec3::new(hx, h / 2.0, T / 2.0),
            id,
            m.back,
        ),
        Some([x0, x1, y0, y1]) => {
            // Below, above, left and right of the opening.
            add_box(
                s,
                Vec3::new(0.0, y0 / 2.0, zb),
                Vec3::new(hx, y0 / 2.0, T / 2.0),
                id,
                m.back,
            );
            add_box(
                s,
                Vec3::new(0.0, (y1 + h) / 2.0, zb),
                Vec3::new(hx, (h - y1) / 2.0, T / 2.0),
                id,
                m.back,
            );
            let (yc, hy) = ((y0 + y1) / 2.0, (y1 - y0) / 2.0);
            add_box(
                s,
                Vec3::new((x0 - hx) / 2.0, yc, zb),
                Vec3::new((x0 + hx) / 2.0, hy, T / 2.0),
                id,
                m.back,
            );
            add_box(
                s,
                Vec3::new((x1 + hx) / 2.0, yc, zb),
                Vec3::new((hx - x1) / 2.0, hy, T / 2.0),
                id,
                m.back,
            );
        }
    }
}

fn finish(mut s: Scene, sun: DirectionalLight, cameras: Vec<Camera>) -> Scene {
    s.lights.push(sun);
    s.cameras = cameras;
    s.recompute_bounds();
    s
}

/// A 4 x 2.8 x 4 m closed box with a 0.6 x 0.6 m window in the back wall; the sun (30 W/m^2,
/// 35 degrees up) makes a patch of about 0.6 x 0.9 m on the floor, and the rest of the room
/// sees only indirect light.
pub fn window_box() -> Scene {
    let mut s = Scene {
        name: "Window box".into(),
        ..Default::default()
    };
    s.materials = vec![
        mat("white", [0.75, 0.75, 0.72]),
        mat("warm floor", [0.7, 0.55, 0.4]),
        mat("blue wall", [0.2, 0.3, 0.7]),
        mat("grey box", [0.6, 0.6, 0.6]),
        mat("yellow sphere", [0.8, 0.7, 0.15]),
    ];
    let m = RoomMaterials {
        floor: 1,
        ceiling: 0,
        left: 2,
        right: 0,
        front: 0,
        back: 0,
    };
    room(&mut s, (2.0, 2.8, 2.0), Some([-0.3, 0.3, 1.3, 1.9]), None, &m);
    add_box(
        &mut s,
        Vec3::new(0.9, 0.35, -0.9),
        Vec3::new(0.3, 0.35, 0.3),
        Quat::from_rotation_y(25f32.to_radians()),
        3,
    );
    add_sphere(&mut s, Vec3::new(-1.1, 0.35, 0.9), 0.35, 20, 12, 4);
    let sun = DirectionalLight::from_angles("sun", -80.0, 35.0, Vec3::splat(30.0));
    let cams = vec![
        Camera::look_at(
            "Main",
            Vec3::new(1.6, 1.6, 1.75),
            Vec3::new(-0.6, 0.6, -1.0),
            60f32.to_radians(),
            0.01,
            30.0,
        ),
        Camera::look_at(
            "Window",
            Vec3::new(0.0, 1.4, 1.8),
            Vec3::new(0.0, 1.2, -2.0),
            60f32.to_radians(),
            0.01,
            30.0,
        ),
    ];
    finish(s, sun, cams)
}

/// A 2 x 2.5 x 16 m corridor (z in [-8, 8]) with a 1.8 m ceiling opening at its far end and
/// three pairs of pillars; the sun (20 W/m^2, 65 degrees up) lights the floor below the
/// opening, and the camera looks down the corridor from the other end.
pub fn corridor() -> Scene {
    let mut s = Scene {
        name: "Corridor".into(),
        ..Default::default()
    };
    s.materials = vec![
        mat("plaster", [0.72, 0.72, 0.7]),
        mat("oak floor", [0.55, 0.4, 0.25]),
        mat("red pillar", [0.6, 0.15, 0.1]),
        mat("green end wall", [0.2, 0.5, 0.25]),
    ];
    let m = RoomMaterials {
        floor: 1,
        ceiling: 0,
        left: 0,
        right: 0,
        front: 0,
        back: 3,
    };
    room(&mut s, (1.0, 2.5, 8.0), None, Some([-8.0, -6.2]), &m);
    for z in [-3.5, 0.5, 4.5] {
        for x in [-0.85, 0.85] {
            add_box(
                &mut s,
                Vec3::new(x, 1.25, z),
                Vec3::new(0.15, 1.25, 0.15),
                Quat::IDENTITY,
                2,
            );
        }
    }
    let sun = DirectionalLight::from_angles("sun", -90.0, 65.0, Vec3::splat(20.0));
    let cams = vec![
        Camera::look_at(
            "Main",
            Vec3::new(0.3, 1.5, 7.6),
            Vec3::new(0.0, 1.0, -8.0),
            50f32.to_radians(),
            0.01,
            40.0,
        ),
        Camera::look_at(
            "Lit end",
            Vec3::new(0.0, 1.6, -2.0),
            Vec3::new(0.0, 0.5, -7.0),
            60f32.to_radians(),
            0.01,
            40.0,
        ),
    ];
    finish(s, sun, cams)
}

/// A 5 x 3 x 5 m room with a large window behind a grille of 2 cm bars; a polished stone
/// floor, a brushed-aluminium wall panel, a gold sphere, a 2 cm table top on 3 cm legs and a
/// 5 mm aluminium plate hanging in the sunlight (sun 10 W/m^2, 40 degrees up).
pub fn glossy_thin() -> Scene {
    let mut s = Scene {
        name: "Glossy and thin".into(),
        ..Default::default()
    };
    s.materials = vec![
        mat("white", [0.75, 0.75, 0.72]),
        Material {
            roughness: 0.25,
            ..mat("polished stone", [0.55, 0.55, 0.6])
        },
        metal("brushed aluminium", [0.91, 0.92, 0.92], 0.35),
        metal("gold", [1.0, 0.78, 0.34], 0.2),
        mat("dark bars", [0.1, 0.1, 0.1]),
        mat("wood", [0.6, 0.4, 0.2]),
        mat("red wall", [0.63, 0.065, 0.05]),
    ];
    let m = RoomMaterials {
        floor: 1,
        ceiling: 0,
        left: 6,
        right: 0,
        front: 0,
        back: 0,
    };
    let (wx0, wx1, wy0, wy1) = (-1.2, 1.2, 0.8, 2.4);
    room(&mut s, (2.5, 3.0, 2.5), Some([wx0, wx1, wy0, wy1]), None, &m);
    let id = Quat::IDENTITY;
    // The window grille: vertical 2 cm bars every 15 cm, in the opening's inner half.
    let mut x = wx0 + 0.075;
    while x < wx1 {
        add_box(
            &mut s,
            Vec3::new(x, 0.5 * (wy0 + wy1), -2.5 - 0.05),
            Vec3::new(0.01, 0.5 * (wy1 - wy0), 0.01),
            id,
            4,
        );
        x += 0.15;
    }
    // Aluminium panel on the right wall.
    add_box(
        &mut s,
        Vec3::new(2.49, 1.3, 0.0),
        Vec3::new(0.01, 0.9, 1.4),
        id,
        2,
    );
    // Gold sphere.
    add_sphere(&mut s, Vec3::new(-0.9, 0.4, -0.3), 0.4, 24, 16, 3);
    // Table: a 2 cm top on four 3 cm legs.
    let (tx, tz, th) = (0.9, 0.3, 0.75);
    add_box(
        &mut s,
        Vec3::new(tx, th - 0.01, tz),
        Vec3::new(0.6, 0.01, 0.4),
        id,
        5,
    );
    for dx in [-0.55, 0.55] {
        for dz in [-0.35, 0.35] {
            add_box(
                &mut s,
                Vec3::new(tx + dx, 0.5 * (th - 0.02), tz + dz),
                Vec3::new(0.015, 0.5 * (th - 0.02), 0.015),
                id,
                5,
            );
        }
    }
    // A 5 mm aluminium plate hanging at 30 degrees in the sunlight.
    add_box(
        &mut s,
        Vec3::new(0.0, 1.9, -1.3),
        Vec3::new(0.5, 0.0025, 0.35),
        Quat::from_rotation_x(30f32.to_radians()),
        2,
    );
    let sun = DirectionalLight::from_angles("sun", -70.0, 40.0, Vec3::splat(10.0));
    let cams = vec![Camera::look_at(
        "Main",
        Vec3::new(2.0, 1.7, 2.2),
        Vec3::new(-0.5, 0.7, -1.2),
        60f32.to_radians(),
        0.01,
        30.0,
    )];
    finish(s, sun, cams)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_scene_is_well_formed_and_sunlit() {
        for b in BUILTIN {
            let s = (b.build)();
            assert!(s.triangle_count() > 0, "{}", b.name);
            assert_eq!(s.indices.len() % 3, 0);
            assert_eq!(s.triangle_materials.len(), s.triangle_count(), "{}", b.name);
            assert!(
                s.triangle_materials
                    .iter()
                    .all(|&m| (m as usize) < s.materials.len()),
                "{}",
                b.name
            );
            assert!(
                s.indices.iter().all(|&i| (i as usize) < s.positions.len()),
                "{}",
                b.name
            );
            assert_eq!(s.lights.len(), 1, "{}: one sun", b.name);
            assert!(s.lights[0].direction.y < 0.0, "{}: the sun shines down", b.name);
            assert!(!s.cameras.is_empty() && !s.bounds.is_empty(), "{}", b.name);
            // Every camera is inside the room (the bounds less the walls' thickness), and
            // looks at geometry (a closed room: its view ray hits a wall, never the sky).
            let bvh = crate::scene::bvh::Bvh::build(&s.positions, &s.indices);
            let (lo, hi) = (s.bounds.min + Vec3::splat(T), s.bounds.max - Vec3::splat(T));
            for c in &s.cameras {
                let p = c.position;
                assert!(
                    p.cmpgt(lo).all() && p.cmplt(hi).all(),
                    "{}: camera {} at {p} is outside the room",
                    b.name,
                    c.name
                );
                let ray = crate::scene::bvh::Ray::new(p, c.forward, 1e-3, 1e3);
                assert!(
                    bvh.closest_hit(&ray).is_some(),
                    "{}: camera {} sees the sky",
                    b.name,
                    c.name
                );
            }
        }
        assert_eq!(BUILTIN[0].name, "default");
        assert!(find("corridor").is_some() && find("nope").is_none());
    }

    /// `--scene <name>` opens a built-in scene; a misspelt name is refused with the names.
    #[test]
    fn scene_arguments_name_the_builtin_scenes() {
        use crate::scene::preset::{SceneSource, open_scene};
        for b in BUILTIN {
            let o = open_scene(&SceneSource::from_arg(b.name)).unwrap();
            assert_eq!(o.scene.name, (b.build)().name);
        }
        assert_eq!(
            SceneSource::from_arg("corridor"),
            SceneSource::Builtin("corridor")
        );
        let e = open_scene(&SceneSource::from_arg("corridoor"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("corridoor") && e.contains("window-box") && e.contains("glossy-thin"),
            "{e}"
        );
    }

    /// The sun reaches into each room through its opening: a ray against the sun from a
    /// point on the lit patch escapes (checked with the CPU BVH).
    #[test]
    fn the_sun_enters_each_test_scene() {
        use crate::scene::bvh::{Bvh, Ray};
        let lit = [
            ("window-box", Vec3::new(-0.4, 0.01, 0.25)),
            ("corridor", Vec3::new(0.0, 0.01, -6.0)),
            ("glossy-thin", Vec3::new(0.3, 0.01, -0.4)),
        ];
        for (name, p) in lit {
            let s = (find(name).unwrap().build)();
            let bvh = Bvh::build(&s.positions, &s.indices);
            let to_sun = -s.lights[0].direction;
            assert!(
                !bvh.any_hit(&Ray::new(p, to_sun, 1e-3, 100.0)),
                "{name}: the sun does not reach {p}"
            );
            // And a point in the room's far corner is in shadow (closed rooms).
            let dark = s.bounds.min + Vec3::new(0.5, 0.3, s.bounds.extent().z - 0.6);
            assert!(
                bvh.any_hit(&Ray::new(dark, to_sun, 1e-3, 100.0)),
                "{name}: {dark} is sunlit"
            );
        }
    }
}
