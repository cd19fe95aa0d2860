//! `methods`: the GI-method registry as a table (CLI name, kind, label, the views each draws,
//! its timed GPU passes, its bias against the ground truth (and how to make it unbiased), and
//! the tests that check it).

use crate::methods::{Kind, REGISTRY};

pub fn run() -> anyhow::Result<()> {
    println!("{:<14} {:<12} {:<34} about", "method", "kind", "label");
    for m in REGISTRY {
        let kind = match m.kind {
            Kind::DirectOnly => "direct only",
            Kind::Progressive => "progressive",
            Kind::PerFrame => "per frame",
        };
        println!("{:<14} {:<12} {:<34} {}", m.id.cli(), kind, m.label, m.about);
        if !m.reads.is_empty() {
            let r: Vec<String> = m.reads.iter().map(|r| format!("{r:?}")).collect();
            println!("{:<14} reads: {}", "", r.join(", "));
        }
        if !m.views.is_empty() {
            let v: Vec<&str> = m.views.iter().map(|v| v.name).collect();
            println!("{:<14} views: {}", "", v.join("; "));
        }
        if !m.timed_passes.is_empty() {
            println!("{:<14} GPU passes: {}", "", m.timed_passes.join(", "));
        }
        if m.story {
            println!("{:<14} pixel story: yes", "");
        }
        if let Some(vm) = m.visibility {
            let v: Vec<String> = vm.modes.iter().map(|(n, what)| format!("{n} ({what})")).collect();
            println!("{:<14} visibility (--visibility): {}; none", "", v.join("; "));
        } else if m.shadow_ray_switch {
            println!("{:<14} visibility (--visibility): rays; none", "");
        }
        if m.kind != crate::methods::Kind::DirectOnly {
            let brdf = if m.glossy { "Lambert, GGX" } else { "Lambert only" };
            let bounces = if m.one_bounce { "1 (RSM texels)" } else { "1..=8" };
            println!("{:<14} BRDF: {brdf}; VPL bounces: {bounces}", "");
        }
        if m.kind == Kind::PerFrame {
            let defaults = crate::settings::RenderSettings {
                gi: crate::settings::GiSettings {
                    method: m.id,
                    ..Default::default()
                },
                ..Default::default()
            };
            println!(
                "{:<14} against the ground truth of the same VPLs: {}",
                "",
                (m.bias)(&defaults).describe()
            );
            if let Some(u) = &m.unbiased {
                println!("{:<14} unbiased with: {}", "", u.how);
            }
        }
        if !m.tests.is_empty() {
            println!("{:<14} checked by: {}", "", m.tests.join(", "));
        }
    }
    Ok(())
}
