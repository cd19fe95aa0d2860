//! Direct light only: no indirect term (the GI buffer stays black). A method like the others
//! so that "GI off" is a choice in every list, not a special case.

use super::{FrameCx, Kind, Method, MethodId, MethodInfo, Module};
use crate::gpu::shaders::ShaderError;
use crate::settings::RenderSettings;

pub const ID: MethodId = MethodId::new("off");

pub static MODULE: Module = Module {
    name: "direct_only",
    create,
    shaders: &[],
    entry_shaders: &[],
    wgsl_twins: &[],
    own_workgroups: &[],
    flags: &[],
};

pub static INFO: MethodInfo = MethodInfo {
    id: ID,
    aliases: &["direct", "direct-only", "none"],
    label: "off (direct only)",
    short: "direct only",
    about: "No indirect light: the final image is the direct sunlight with shadow maps.",
    progress_unit: "",
    kind: Kind::DirectOnly,
    module: &MODULE,
    reads: &[],
    views: &[],
    timed_passes: &[],
    story: false,
    shadow_ray_switch: false,
    visibility: None,
    truth_of_vpls: false,
    one_bounce: false,
    glossy: true,
    validate: |_: &RenderSettings| Ok(()),
    fields: super::no_fields,
    invalid_example: None,
    ui: |_, _, _| {},
    tests: &["direct_light::lit_quad_matches_rho_over_pi_e_cos_and_shadow_is_zero"],
    sweep: None,
    bias: |_| super::Bias::NotCompared,
    unbiased: None,
};

struct DirectOnly;

fn create(_: &wgpu::Device) -> Result<Box<dyn Method>, ShaderError> {
    Ok(Box::new(DirectOnly))
}

impl Method for DirectOnly {
    fn record(&mut self, _cx: &mut FrameCx<'_>, _enc: &mut wgpu::CommandEncoder) -> f32 {
        0.0
    }
}
