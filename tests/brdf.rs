//! The BRDF of every method's shading (`shaders/common/brdf.wgsl`) against its CPU twin
//! `reference::brdf` on the GPU (the white furnace and reciprocity are the twin's unit tests).

mod common;

use glam::Vec3;
use lightcut::{
    reference::brdf::{self, Brdf, Surface},
    renderer::brdf_probe::{BrdfProbe, GpuBrdfCase},
};

#[test]
fn gpu_brdf_equals_the_cpu_twin() {
    let Some(ctx) = common::gpu() else { return };
    let probe = BrdfProbe::new(&ctx.device).expect("shader");
    let mut rng = lightcut::reference::light_paths::Rng::new(3, 1, 4);
    let unit = |rng: &mut lightcut::reference::light_paths::Rng| {
        Vec3::new(
            2.0 * rng.next_f32() - 1.0,
            2.0 * rng.next_f32() - 1.0,
            2.0 * rng.next_f32() - 1.0,
        )
        .normalize_or(Vec3::Z)
    };
    let mut cases = Vec::new();
    let mut surfaces = Vec::new();
    for k in 0..4096u32 {
        let n = unit(&mut rng);
        // Mostly above the surface, some below (both must give 0).
        let mut v = unit(&mut rng);
        let mut l = unit(&mut rng);
        if k % 8 != 0 {
            v = if v.dot(n) < 0.0 { v - 2.0 * v.dot(n) * n } else { v };
            l = if l.dot(n) < 0.0 { l - 2.0 * l.dot(n) * n } else { l };
        }
        let model = if k % 4 == 0 { Brdf::Lambert } else { Brdf::Ggx };
        let s = Surface {
            base: Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()),
            metallic: if k % 3 == 0 { 1.0 } else { rng.next_f32() },
            roughness: if k % 5 == 0 { 0.0 } else { rng.next_f32() },
        };
        cases.push(GpuBrdfCase {
            n: n.extend(model.gpu() as f32).to_array(),
            v: v.extend(s.metallic).to_array(),
            l: l.extend(s.roughness).to_array(),
            base: s.base.extend(0.0).to_array(),
        });
        surfaces.push((model, n, v, l, s));
    }
    let gpu = probe.run(&ctx, &cases).expect("run");
    let mut worst = 0.0f32;
    for (k, ((d, sp), (model, n, v, l, s))) in gpu.iter().zip(&surfaces).enumerate() {
        let (cd, cs) = (
            brdf::diffuse(*model, *n, *v, *l, s),
            brdf::specular(*model, *n, *v, *l, s),
        );
        for (g, c) in [(Vec3::from_array(*d), cd), (Vec3::from_array(*sp), cs)] {
            let err = (g - c).abs().max_element() / c.max_element().max(1e-3);
            worst = worst.max(err);
            assert!(err <= 2e-3, "case {k} ({model:?}, {s:?}): GPU {g} vs CPU {c}");
        }
    }
    eprintln!("largest relative difference: {worst:.2e}");
    assert!(ctx.errors.take().is_empty());
}
