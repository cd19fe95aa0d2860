//! Kernels bind by WGSL variable name (`renderer::kernel`): a layout reflected from the
//! shader, a bind group checked against it before wgpu sees it.

mod common;

use lightcut::renderer::kernel::{Kernel, KernelOptions, buf, check_bindings, tex};

fn storage(ctx: &lightcut::renderer::context::GpuContext, label: &str) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: 256,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::UNIFORM,
        mapped_at_creation: false,
    })
}

#[test]
fn bindings_by_name_are_checked_for_names_kinds_and_completeness() {
    let Some(ctx) = common::gpu() else { return };
    let k = Kernel::new(&ctx.device, "brdf_eval.wgsl", &["main"], KernelOptions::default()).unwrap();
    let slots = &k.group(0).slots;
    let names: Vec<&str> = slots.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["cases", "out"]);
    let (a, b) = (storage(&ctx, "t::a"), storage(&ctx, "t::b"));
    // Right names, any order: entries at the reflected binding numbers.
    let e = check_bindings(slots, &[("out", buf(&b)), ("cases", buf(&a))]).unwrap();
    assert_eq!(e.iter().map(|e| e.binding).collect::<Vec<_>>(), [1, 0]);
    let _ = k.bind(&ctx.device, 0, &[("cases", buf(&a)), ("out", buf(&b))]);
    ctx.wait_idle().unwrap();
    assert!(ctx.errors.take().is_empty());
    // A misspelt name, a name twice, a missing one, a texture for a buffer.
    let e = check_bindings(slots, &[("case", buf(&a)), ("out", buf(&b))]).unwrap_err();
    assert!(
        e.contains("no variable 'case'") && e.contains("cases, out"),
        "{e}"
    );
    let e = check_bindings(slots, &[("cases", buf(&a)), ("cases", buf(&b))]).unwrap_err();
    assert!(e.contains("given twice"), "{e}");
    let e = check_bindings(slots, &[("cases", buf(&a))]).unwrap_err();
    assert_eq!(e, "not given: out");
    let t = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("t::tex"),
        size: wgpu::Extent3d {
            width: 4,
            height: 4,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let v = t.create_view(&Default::default());
    let e = check_bindings(slots, &[("cases", tex(&v)), ("out", buf(&b))]).unwrap_err();
    assert!(e.contains("'cases'") && e.contains("another kind"), "{e}");
    // `bind` refuses the same with the file and group named.
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        k.bind(&ctx.device, 0, &[("cases", buf(&a))]);
    }));
    let msg = r.unwrap_err();
    let msg = msg.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(
        msg.starts_with("brdf_eval.wgsl @group(0): not given: out"),
        "{msg}"
    );
}
