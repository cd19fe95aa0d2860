//! `bench soak`: a long run that keeps rendering, as the GUI or an overnight sweep would, and
//! watches what the process holds (issue 42). The camera moves along the scene's bookmarks
//! (or the sun sweeps where the scene has fewer than two), the method changes every
//! `--switch-seconds` through `--methods`, and every `--sample-seconds` one line is printed:
//! frames per second (wall clock of whole frames, each waited for), resident memory, GPU
//! memory and live GPU objects. The samples go to `soak.csv`, `soak_memory.png`,
//! `soak_objects.png` and `soak_fps.png`.
//!
//! The verdict compares like with like: the snapshot at the end of each method's slot in the
//! second cycle through the methods (the first where every lazily made resource exists) with
//! the same method's slot in the last cycle (so a run needs three cycles for a verdict). Live objects must not grow and resident memory
//! must stay within 10% (+ 8 MiB); `--check` turns a failed verdict into a non-zero exit.

use anyhow::anyhow;

use super::bench::BenchArgs;
use crate::{
    harness::{
        Csv, num,
        plot::{self, Series},
        sequence::Motion,
    },
    methods::{self, MethodId},
    renderer::{
        FrameMode, Renderer,
        context::GpuContext,
        settings::RenderSettings,
        soak::{Snapshot, grown},
    },
    scene::preset::{SceneSource, open_scene},
};

/// One printed sample.
struct Sample {
    seconds: f64,
    method: MethodId,
    fps: f64,
    snap: Snapshot,
}

/// The snapshot at the end of one method's slot.
struct SlotEnd {
    cycle: usize,
    method: MethodId,
    snap: Snapshot,
    /// The highest resident memory sampled during the slot.
    max_rss: u64,
}

/// The methods of `--methods`: `all` (every per-frame method) or a comma-separated list.
fn parse_methods(list: &str) -> anyhow::Result<Vec<MethodId>> {
    if list.trim() == "all" {
        return Ok(methods::per_frame());
    }
    let ms: Vec<MethodId> = list
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| MethodId::parse(s).map_err(|e| anyhow!("--methods: {e}")))
        .collect::<anyhow::Result<_>>()?;
    if let Some(m) = ms.iter().find(|m| !m.per_frame()) {
        return Err(anyhow!(
            "--methods: {} converges over frames of one view; a soak renders per-frame methods",
            m.cli()
        ));
    }
    if ms.is_empty() {
        return Err(anyhow!("--methods: name at least one method (or `all`)"));
    }
    Ok(ms)
}

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let minutes = args.minutes;
    if !(minutes > 0.0 && minutes <= 7.0 * 24.0 * 60.0) {
        return Err(anyhow!("--minutes must be in (0, 10080] (got {minutes})"));
    }
    if !(args.sample_seconds > 0.0 && args.switch_seconds >= args.sample_seconds) {
        return Err(anyhow!(
            "--sample-seconds must be > 0 and at most --switch-seconds (got {} and {})",
            args.sample_seconds,
            args.switch_seconds
        ));
    }
    let methods = parse_methods(&args.methods)?;
    let opened = open_scene(&SceneSource::from_arg(&args.scene)).map_err(|e| anyhow!("{e}"))?;
    let scene = &opened.scene;
    let camera = scene
        .camera_or_default(opened.camera_name.as_deref())
        .map_err(|e| anyhow!("{e}"))?;
    let motion = if scene.cameras.len() >= 2 {
        Motion::camera_path(scene, &[], 240, &scene.lights)?
    } else {
        Motion::sun_sweep(&camera, &scene.lights, 60.0, 240)?
    };
    let mut settings = RenderSettings::default();
    settings.display.exposure_ev = opened.exposure_ev;
    settings.gi.method = methods[0];
    if let Some(v) = args.vpls {
        settings.vpl.count = v;
    }
    settings.validate().map_err(|e| anyhow!("{e}"))?;
    let ctx = GpuContext::new_headless()?;
    println!("adapter: {}", ctx.describe());
    println!(
        "soak: {minutes} min on {} at {}x{}, {} frames of motion ({}), methods {} switching every {} s",
        args.scene,
        args.width,
        args.height,
        motion.len(),
        if scene.cameras.len() >= 2 {
            "camera path"
        } else {
            "sun sweep"
        },
        methods.iter().map(|m| m.cli()).collect::<Vec<_>>().join(","),
        args.switch_seconds
    );
    let mut r = Renderer::new(ctx, scene, (args.width, args.height), settings.clone())?;
    // Diagnostic frames, as the GUI renders them (views, statistics readbacks).
    r.set_frame_mode(FrameMode::Diagnostic);

    let t0 = std::time::Instant::now();
    let limit = minutes * 60.0;
    let mut samples: Vec<Sample> = Vec::new();
    let mut slots: Vec<SlotEnd> = Vec::new();
    let mut frame: u64 = 0;
    let mut slot = 0usize;
    let mut slot_max_rss = 0u64;
    let (mut next_sample, mut last_sample_t, mut last_sample_frame) = (args.sample_seconds, 0.0, 0u64);
    println!(
        "{:>8} {:>8} {:<14} {:>7} {:>9} {:>9} {:>7} {:>7} {:>7} {:>7}",
        "seconds", "frame", "method", "fps", "RSS MiB", "GPU MiB", "buffers", "views", "bgroups", "pipes"
    );
    loop {
        let t = t0.elapsed().as_secs_f64();
        if t >= limit {
            break;
        }
        // The method of this moment's slot; a new slot ends the last one.
        // (One slot a switch period, each method in turn even when a frame outlasts one.)
        let now_slot = (t / args.switch_seconds) as usize;
        if now_slot > slot {
            let snap = Snapshot::take(&r.ctx, frame);
            slots.push(SlotEnd {
                cycle: slot / methods.len(),
                method: methods[slot % methods.len()],
                snap,
                max_rss: slot_max_rss.max(snap.host.map_or(0, |h| h.rss)),
            });
            slot += 1;
            slot_max_rss = 0;
            let m = methods[slot % methods.len()];
            if r.settings().gi.method != m {
                let mut s = r.settings().clone();
                s.gi.method = m;
                r.set_settings(s)?;
            }
        }
        motion.render(&mut r, frame as usize % motion.len());
        r.ctx.wait_idle()?;
        if let Some(e) = r.ctx.errors.take().into_iter().next() {
            return Err(anyhow!(
                "GPU error after frame {frame} ({}): {e}",
                r.settings().gi.method.cli()
            ));
        }
        frame += 1;
        let t = t0.elapsed().as_secs_f64();
        if t >= next_sample {
            let snap = Snapshot::take(&r.ctx, frame);
            let fps = (frame - last_sample_frame) as f64 / (t - last_sample_t).max(1e-9);
            slot_max_rss = slot_max_rss.max(snap.host.map_or(0, |h| h.rss));
            let m = r.settings().gi.method;
            println!(
                "{:>8.1} {:>8} {:<14} {:>7.1} {:>9.1} {:>9.1} {:>7} {:>7} {:>7} {:>7}",
                t,
                frame,
                m.cli(),
                fps,
                snap.rss_mib(),
                snap.gpu_mib(),
                snap.live.buffers,
                snap.live.texture_views,
                snap.live.bind_groups,
                snap.live.pipelines
            );
            samples.push(Sample {
                seconds: t,
                method: m,
                fps,
                snap,
            });
            (last_sample_t, last_sample_frame) = (t, frame);
            while next_sample <= t {
                next_sample += args.sample_seconds;
            }
        }
    }
    let snap = Snapshot::take(&r.ctx, frame);
    slots.push(SlotEnd {
        cycle: slot / methods.len(),
        method: methods[slot % methods.len()],
        snap,
        max_rss: slot_max_rss.max(snap.host.map_or(0, |h| h.rss)),
    });
    write_outputs(args, &samples)?;
    let verdict = verdict(&slots, methods.len());
    println!(
        "{frame} frames in {:.1} s ({:.1} frames per second, wall clock); wrote {}",
        t0.elapsed().as_secs_f64(),
        frame as f64 / t0.elapsed().as_secs_f64(),
        args.out.display()
    );
    match verdict {
        Ok(line) if args.check && line.contains("too short") => return Err(anyhow!("--check: {line}")),
        Ok(line) => println!("{line}"),
        Err(line) if args.check => return Err(anyhow!("{line}")),
        Err(line) => println!("{line}"),
    }
    Ok(())
}

/// Each method's slot in the second cycle against its slot in the last (possibly partial)
/// cycle; fewer than three cycles: too short to judge.
fn verdict(slots: &[SlotEnd], n_methods: usize) -> Result<String, String> {
    // The second cycle is the reference: in the first, each method's slot ends before the
    // later methods have made what they keep.
    let last_cycle = slots.last().map_or(0, |s| s.cycle);
    let reference = 1;
    if last_cycle < 2 {
        return Ok(format!(
            "verdict: too short to judge ({} slot(s) of {} method(s)); run at least {} switch periods",
            slots.len(),
            n_methods,
            2 * n_methods + 1
        ));
    }
    let mut problems = Vec::new();
    let mut compared = 0;
    for late in slots.iter().filter(|s| s.cycle == last_cycle) {
        let Some(early) = slots
            .iter()
            .find(|s| s.cycle == reference && s.method == late.method)
        else {
            continue;
        };
        compared += 1;
        let g = grown(&early.snap.live, &late.snap.live);
        if !g.is_empty() {
            problems.push(format!(
                "{}: live GPU objects grew from cycle {} to {}: {}",
                late.method.cli(),
                reference + 1,
                last_cycle + 1,
                g.join(", ")
            ));
        }
        let bound = early.max_rss as f64 * 1.1 + 8.0 * 1024.0 * 1024.0;
        if early.max_rss > 0 && late.max_rss as f64 > bound {
            problems.push(format!(
                "{}: resident memory {:.0} MiB in cycle {} against {:.0} MiB in cycle {} (more than 10% + 8 MiB)",
                late.method.cli(),
                late.max_rss as f64 / 1048576.0,
                last_cycle + 1,
                early.max_rss as f64 / 1048576.0,
                reference + 1
            ));
        }
    }
    if compared < n_methods.min(slots.iter().filter(|s| s.cycle == last_cycle).count()) {
        problems.push(format!(
            "only {compared} slot(s) of cycle {} had a slot to compare with",
            last_cycle + 1
        ));
    }
    if problems.is_empty() {
        Ok(format!(
            "verdict: flat: {compared} method slot(s) of cycle {} against cycle {}: no kind of live GPU object grew, resident memory within 10% + 8 MiB",
            last_cycle + 1,
            reference + 1
        ))
    } else {
        Err(format!("verdict: GREW: {}", problems.join("; ")))
    }
}

fn write_outputs(args: &BenchArgs, samples: &[Sample]) -> anyhow::Result<()> {
    let out = &args.out;
    std::fs::create_dir_all(out).map_err(|e| anyhow!("cannot create {}: {e}", out.display()))?;
    let mut csv = Csv::new(&[
        "seconds",
        "frame",
        "method",
        "fps_wall",
        "rss_mib",
        "peak_rss_mib",
        "gpu_buffers_textures_mib",
        "gpu_reserved_mib",
        "buffers",
        "textures",
        "texture_views",
        "bind_groups",
        "pipelines",
        "query_sets",
        "command_encoders",
    ]);
    let mib = |b: u64| num(b as f64 / 1048576.0);
    for s in samples {
        let l = &s.snap.live;
        csv.row(vec![
            num(s.seconds),
            s.snap.frame.to_string(),
            s.method.cli().to_string(),
            num(s.fps),
            num(s.snap.rss_mib()),
            s.snap.host.map_or(String::new(), |h| mib(h.peak_rss)),
            num(s.snap.gpu_mib()),
            s.snap.gpu_reserved.map_or(String::new(), mib),
            l.buffers.to_string(),
            l.textures.to_string(),
            l.texture_views.to_string(),
            l.bind_groups.to_string(),
            l.pipelines.to_string(),
            l.query_sets.to_string(),
            l.command_encoders.to_string(),
        ]);
    }
    csv.write(&out.join("soak.csv"))?;
    if samples.len() < 2 {
        return Ok(());
    }
    let minutes = |s: &Sample| s.seconds / 60.0;
    let series = |name: &str, color: usize, f: &dyn Fn(&Sample) -> f64| Series {
        name: name.to_string(),
        color,
        points: samples
            .iter()
            .map(|s| (minutes(s), f(s)))
            .filter(|p| p.1.is_finite())
            .collect(),
    };
    plot::lines(
        &out.join("soak_memory.png"),
        "Memory over a soak run",
        "minutes",
        "MiB",
        &[
            series("resident (host)", 0, &|s| s.snap.rss_mib()),
            series("GPU buffers + textures", 1, &|s| s.snap.gpu_mib()),
            series("GPU allocator reserved", 2, &|s| {
                s.snap.gpu_reserved.map_or(f64::NAN, |b| b as f64 / 1048576.0)
            }),
        ],
        false,
        false,
    )?;
    plot::lines(
        &out.join("soak_objects.png"),
        "Live GPU objects over a soak run",
        "minutes",
        "objects",
        &[
            series("buffers", 0, &|s| s.snap.live.buffers as f64),
            series("texture views", 1, &|s| s.snap.live.texture_views as f64),
            series("bind groups", 2, &|s| s.snap.live.bind_groups as f64),
            series("pipelines", 3, &|s| s.snap.live.pipelines as f64),
        ],
        false,
        false,
    )?;
    plot::lines(
        &out.join("soak_fps.png"),
        "Frames per second over a soak run (wall clock, each frame waited for)",
        "minutes",
        "frames per second",
        &[series("fps", 0, &|s| s.fps)],
        false,
        false,
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::soak::HostMemory;

    fn slot(cycle: usize, method: MethodId, bind_groups: isize, rss_mib: u64) -> SlotEnd {
        let mut snap = Snapshot::default();
        snap.live.bind_groups = bind_groups;
        snap.host = Some(HostMemory {
            rss: rss_mib << 20,
            peak_rss: rss_mib << 20,
        });
        SlotEnd {
            cycle,
            method,
            snap,
            max_rss: rss_mib << 20,
        }
    }

    #[test]
    fn the_verdict_compares_each_methods_slot_in_the_last_cycle_with_the_second() {
        // Any two methods.
        let m = crate::methods::per_frame();
        let (a, b) = (m[0], m[1]);
        // The first cycle makes what the methods keep: its smaller counts are not compared.
        let mut s = vec![slot(0, a, 1, 100), slot(0, b, 3, 150)];
        assert!(verdict(&s, 2).unwrap().contains("too short"));
        s.extend([slot(1, a, 4, 160), slot(1, b, 4, 160), slot(2, a, 4, 165)]);
        assert!(
            verdict(&s, 2)
                .unwrap()
                .starts_with("verdict: flat: 1 method slot")
        );
        s.push(slot(2, b, 5, 160));
        let e = verdict(&s, 2).unwrap_err();
        assert!(e.contains("bind groups 4 -> 5") && e.contains(b.cli()), "{e}");
        s.pop();
        s.push(slot(2, b, 4, 200));
        assert!(verdict(&s, 2).unwrap_err().contains("resident memory 200 MiB"));
    }
}
