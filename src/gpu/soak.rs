//! What a long run holds: live GPU objects per kind (wgpu's internal counters, see
//! [`GpuContext::live_objects`]), GPU memory, and the process's resident memory, sampled
//! between frames. `render` reports them after its warm-up and at its end, `bench soak`
//! over minutes, and `tests/soak.rs` checks that nothing grows after warm-up (issue 42).

use serde::Serialize;

use super::context::{GpuContext, LiveObjects};

/// The process's resident memory from `/proc/self/status` (Linux; `None` elsewhere).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct HostMemory {
    /// Resident set size now (`VmRSS`), bytes.
    pub rss: u64,
    /// The largest resident set size so far (`VmHWM`), bytes.
    pub peak_rss: u64,
}

/// Reads [`HostMemory`] of this process.
pub fn host_memory() -> Option<HostMemory> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    parse_status(&text)
}

/// `VmRSS` and `VmHWM` of a `/proc/<pid>/status` text (kB there, bytes here).
pub fn parse_status(text: &str) -> Option<HostMemory> {
    let field = |name: &str| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(name))?;
        let kb: u64 = line[name.len()..]
            .trim()
            .trim_end_matches("kB")
            .trim()
            .parse()
            .ok()?;
        Some(kb * 1024)
    };
    Some(HostMemory {
        rss: field("VmRSS:")?,
        peak_rss: field("VmHWM:")?,
    })
}

/// Everything a long run could accumulate, at one moment.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Snapshot {
    /// Frames rendered when it was taken.
    pub frame: u64,
    pub live: LiveObjects,
    /// Bytes the GPU allocator has reserved from the driver (its blocks; `None` where the
    /// backend gives no report).
    pub gpu_reserved: Option<u64>,
    pub host: Option<HostMemory>,
}

impl Snapshot {
    pub fn take(ctx: &GpuContext, frame: u64) -> Snapshot {
        Snapshot {
            frame,
            live: ctx.live_objects(),
            gpu_reserved: ctx
                .device
                .generate_allocator_report()
                .map(|r| r.total_reserved_bytes),
            host: host_memory(),
        }
    }

    /// Resident memory now, MiB (NaN where unknown).
    pub fn rss_mib(&self) -> f64 {
        self.host.map_or(f64::NAN, |h| h.rss as f64 / MIB)
    }

    /// GPU memory held by buffers and textures, MiB.
    pub fn gpu_mib(&self) -> f64 {
        (self.live.buffer_bytes + self.live.texture_bytes) as f64 / MIB
    }
}

const MIB: f64 = 1024.0 * 1024.0;

/// The kinds of GPU object that grew from `warm` to `end`, as "kind from -> to".
pub fn grown(warm: &LiveObjects, end: &LiveObjects) -> Vec<String> {
    warm.objects()
        .iter()
        .zip(end.objects())
        .filter(|((_, a), (_, b))| b > a)
        .map(|((k, a), (_, b))| format!("{k} {a} -> {b}"))
        .collect()
}

/// Snapshots of a run: one after its warm-up (the `warm_frame`-th frame, or the last one if
/// the run is shorter) and one at its end.
#[derive(Clone, Debug)]
pub struct Watch {
    warm_frame: u64,
    frames: u64,
    pub warm: Option<Snapshot>,
}

impl Watch {
    /// The warm-up: 30 frames.
    pub const WARM_FRAMES: u64 = 30;

    pub fn new(warm_frame: u64) -> Watch {
        Watch {
            warm_frame: warm_frame.max(1),
            frames: 0,
            warm: None,
        }
    }

    /// Counts one rendered (and waited for) frame; takes the warm snapshot at the warm frame.
    pub fn frame(&mut self, ctx: &GpuContext) {
        self.frames += 1;
        if self.frames == self.warm_frame {
            self.warm = Some(Snapshot::take(ctx, self.frames));
        }
    }

    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// The end snapshot and the report of the run.
    pub fn finish(&self, ctx: &GpuContext) -> Report {
        let end = Snapshot::take(ctx, self.frames);
        Report {
            warm: self.warm.unwrap_or(end),
            end,
        }
    }
}

/// A run's resources after warm-up and at its end.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Report {
    pub warm: Snapshot,
    pub end: Snapshot,
}

impl Report {
    /// One line for a command's output.
    pub fn line(&self) -> String {
        let g = grown(&self.warm.live, &self.end.live);
        let objects = if g.is_empty() {
            format!(
                "live GPU objects unchanged from frame {} to frame {} ({} bind groups, {} buffers, {} texture views)",
                self.warm.frame,
                self.end.frame,
                self.end.live.bind_groups,
                self.end.live.buffers,
                self.end.live.texture_views
            )
        } else {
            format!(
                "live GPU objects GREW from frame {} to frame {}: {}",
                self.warm.frame,
                self.end.frame,
                g.join(", ")
            )
        };
        let host = match self.end.host {
            Some(h) => format!(
                "; resident memory {:.0} MiB at frame {}, {:.0} MiB at the end, peak {:.0} MiB",
                self.warm.rss_mib(),
                self.warm.frame,
                h.rss as f64 / MIB,
                h.peak_rss as f64 / MIB
            ),
            None => String::new(),
        };
        format!(
            "resources: {objects}; GPU buffers and textures {:.1} MiB{host}",
            self.end.gpu_mib()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_fields_parse_to_bytes() {
        let t = "Name:\tx\nVmHWM:\t  2048 kB\nVmRSS:\t  1024 kB\nThreads: 3\n";
        assert_eq!(
            parse_status(t),
            Some(HostMemory {
                rss: 1024 * 1024,
                peak_rss: 2048 * 1024
            })
        );
        assert_eq!(parse_status("Name: x\n"), None);
    }

    #[test]
    fn growth_names_the_kinds_that_grew() {
        let a = LiveObjects {
            bind_groups: 4,
            buffers: 10,
            ..Default::default()
        };
        let mut b = a;
        assert!(grown(&a, &b).is_empty());
        b.bind_groups = 9;
        b.buffers = 8;
        assert_eq!(grown(&a, &b), vec!["bind groups 4 -> 9".to_string()]);
    }
}
