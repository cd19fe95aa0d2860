//! Per-pass GPU timings from timestamp queries, or "timestamps not supported".

use super::readback::AsyncReadback;

/// Most timed passes per frame.
pub const MAX_TIMED_PASSES: u32 = 32;

/// GPU time of each pass of a frame, in milliseconds, in recording order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PassTimings {
    pub passes: Vec<(String, f64)>,
}

impl PassTimings {
    pub fn total_ms(&self) -> f64 {
        self.passes.iter().map(|(_, t)| t).sum()
    }
    pub fn get(&self, name: &str) -> Option<f64> {
        self.passes.iter().find(|(n, _)| n == name).map(|(_, t)| *t)
    }
    /// One line: `gbuffer 0.41 ms | shadow_map 0.20 ms | ... | total 1.2 ms`.
    pub fn summary(&self) -> String {
        let mut parts: Vec<String> = self
            .passes
            .iter()
            .map(|(n, t)| format!("{n} {t:.3} ms"))
            .collect();
        parts.push(format!("total {:.3} ms", self.total_ms()));
        parts.join(" | ")
    }
}

/// Timestamp queries for one frame at a time: `begin_frame`, `compute_pass`/`render_pass` per
/// pass, `resolve` before submit, `after_submit`, then `collect` (non-blocking) or
/// `collect_blocking`. A frame gets timestamps only while the previous readback is done.
pub struct GpuTimer {
    inner: Option<TimerInner>,
    /// Whether the current frame is timed (`begin_frame`).
    timing: bool,
    names: Vec<String>,
    last: Option<PassTimings>,
}

struct TimerInner {
    query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: AsyncReadback,
    period_ns: f32,
    pending_names: Vec<String>,
}

impl GpuTimer {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let inner = device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| {
                let count = 2 * MAX_TIMED_PASSES;
                let size = count as u64 * 8;
                TimerInner {
                    query_set: device.create_query_set(&wgpu::QuerySetDescriptor {
                        label: Some("timer::queries"),
                        ty: wgpu::QueryType::Timestamp,
                        count,
                    }),
                    resolve: device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("timer::resolve"),
                        size,
                        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                        mapped_at_creation: false,
                    }),
                    readback: AsyncReadback::new(device, "timer::readback", size),
                    period_ns: queue.get_timestamp_period(),
                    pending_names: Vec::new(),
                }
            });
        Self {
            inner,
            timing: true,
            names: Vec::new(),
            last: None,
        }
    }

    pub fn supported(&self) -> bool {
        self.inner.is_some()
    }

    /// True when this frame's passes get timestamps (a timed frame, and the previous
    /// readback is finished).
    fn active(&self) -> bool {
        self.timing && self.inner.as_ref().is_some_and(|i| i.readback.is_idle())
    }

    /// Starts a frame; `timed = false` records no timestamps (a diagnostic frame).
    pub fn begin_frame(&mut self, timed: bool) {
        self.timing = timed;
        self.names.clear();
    }

    fn next_index(&mut self, name: &str) -> Option<u32> {
        if !self.active() || self.names.len() as u32 >= MAX_TIMED_PASSES {
            return None;
        }
        self.names.push(name.to_string());
        Some(2 * (self.names.len() as u32 - 1))
    }

    pub fn compute_pass(&mut self, name: &str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let i = self.next_index(name)?;
        let inner = self.inner.as_ref()?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: &inner.query_set,
            beginning_of_pass_write_index: Some(i),
            end_of_pass_write_index: Some(i + 1),
        })
    }

    pub fn render_pass(&mut self, name: &str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let i = self.next_index(name)?;
        let inner = self.inner.as_ref()?;
        Some(wgpu::RenderPassTimestampWrites {
            query_set: &inner.query_set,
            beginning_of_pass_write_index: Some(i),
            end_of_pass_write_index: Some(i + 1),
        })
    }

    /// Records the query resolve and readback copy; call once at the end of the frame's encoder.
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        if !self.active() || self.names.is_empty() {
            return;
        }
        let Some(inner) = self.inner.as_mut() else { return };
        let n = 2 * self.names.len() as u32;
        encoder.resolve_query_set(&inner.query_set, 0..n, &inner.resolve, 0);
        if inner
            .readback
            .record(encoder, &[(&inner.resolve, 0, 0, n as u64 * 8)])
        {
            inner.pending_names = std::mem::take(&mut self.names);
        }
    }

    /// Starts mapping the readback buffer; call right after submitting the frame.
    pub fn after_submit(&mut self) {
        if let Some(inner) = self.inner.as_ref() {
            inner.readback.after_submit();
        }
    }

    /// Picks up finished timings without blocking; returns the latest known timings.
    pub fn collect(&mut self, device: &wgpu::Device) -> Option<&PassTimings> {
        let _ = device.poll(wgpu::PollType::Poll);
        self.read_if_ready();
        self.last.as_ref()
    }

    /// Waits for the frame's timings.
    pub fn collect_blocking(&mut self, device: &wgpu::Device) -> Option<&PassTimings> {
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
        self.read_if_ready();
        self.last.as_ref()
    }

    /// Waits for the GPU; returns the timings only if a frame's timings came back by this
    /// call (never a stale earlier frame's).
    pub fn collect_new_blocking(&mut self, device: &wgpu::Device) -> Option<PassTimings> {
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
        self.read_if_ready().then(|| self.last.clone()).flatten()
    }

    /// Reads finished timings (the caller polled the device); true if new ones came.
    pub fn read_if_ready(&mut self) -> bool {
        let Some(inner) = self.inner.as_mut() else {
            return false;
        };
        let Some(bytes) = inner.readback.try_take() else {
            return false;
        };
        let ticks: &[u64] = bytemuck::cast_slice(&bytes);
        let passes = inner
            .pending_names
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let dt = ticks[2 * i + 1].wrapping_sub(ticks[2 * i]);
                // Guard against wrapped or reordered stamps.
                let dt = if dt > (1u64 << 62) { 0 } else { dt };
                (name.clone(), dt as f64 * inner.period_ns as f64 * 1e-6)
            })
            .collect();
        self.last = Some(PassTimings { passes });
        true
    }

    pub fn last(&self) -> Option<&PassTimings> {
        self.last.as_ref()
    }
}
