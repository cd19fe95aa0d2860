//! A lost GPU device: the app leaves the window whose device is gone and resumes, state intact,
//! in a new window on a new device.
//!
//! The renderer shares eframe's device, so a loss takes egui's painter with it, and egui-wgpu
//! 0.37 does not recreate its device (emilk/egui#8452 and #8292 are open). eframe can run
//! windows one after the other in one process (`run_and_return`, its event loop reused), so
//! [`super::run_gui`] opens a new window, with a new instance, adapter and device, and hands it
//! the app: settings, open scene and camera, sun, views and their zoom, tools, animation,
//! messages, frame count. Everything made on the old device (the renderer, the views'
//! texture registrations, a running comparison sheet) is made again or dropped.

use super::*;

impl WorkbenchApp {
    /// Sends the app to `handover` when its device is lost, for [`super::run_gui`] to resume in
    /// a new window (at most [`MAX_DEVICE_RECOVERIES`] times).
    pub fn with_handover(mut self, handover: Handover) -> Self {
        self.handover = Some(handover);
        self
    }

    /// How many lost devices this app recovered from.
    pub fn recoveries(&self) -> u32 {
        self.recoveries
    }

    /// Whether this window's app went to the handover (the window closes; the app goes on in
    /// the next one).
    pub fn handed_over(&self) -> bool {
        self.handed_over
    }

    /// `--lose-device-at-frame N`: destroys the device once this window has rendered N frames
    /// (in every window, so that repeated losses reach [`MAX_DEVICE_RECOVERIES`]).
    pub(super) fn lose_device_if_asked(&mut self) {
        let (Some(n), Some(renderer)) = (self.options.lose_device_at_frame, self.renderer.as_ref()) else {
            return;
        };
        if self.frames.saturating_sub(self.window_start_frame) < n || renderer.ctx.errors.device_lost() {
            return;
        }
        log::warn!(
            "destroying the GPU device at frame {} (--lose-device-at-frame)",
            self.frames
        );
        renderer.ctx.device.destroy();
        // wgpu reports the loss once the device's queue is empty.
        let _ = renderer.ctx.device.poll(wgpu::PollType::wait_indefinitely());
    }

    /// When the device is lost (checked at the start and at the end of a UI frame): drops the
    /// frame's shapes (egui-wgpu 0.37 panics uploading them to a lost device), hands the app
    /// over for [`super::run_gui`] to resume in a new window, or past [`MAX_DEVICE_RECOVERIES`]
    /// leaves the reason there, and closes the window. True: this window's app is gone (it
    /// draws nothing more). Without a handover (a test harness) it returns false and the
    /// viewport says that rendering stopped.
    pub(super) fn hand_over_if_lost(&mut self, ctx: &egui::Context) -> bool {
        if self.handed_over {
            return true;
        }
        let Some(renderer) = self.renderer.as_ref() else {
            return false;
        };
        if !renderer.ctx.errors.device_lost() {
            return false;
        }
        for e in renderer.ctx.errors.take() {
            if !self.errors.contains(&e) {
                self.errors.push(e);
            }
        }
        let Some(handover) = self.handover.clone() else {
            return false;
        };
        ctx.graphics_mut(|g| *g = Default::default());
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        if self.recoveries >= MAX_DEVICE_RECOVERIES {
            let cause = self
                .errors
                .iter()
                .rev()
                .find(|e| e.starts_with("GPU device lost"))
                .cloned()
                .unwrap_or_else(|| "GPU device lost".into());
            log::error!("the GPU device was lost again after {MAX_DEVICE_RECOVERIES} recoveries; stopping");
            *handover.borrow_mut() = Some(Err(format!(
                "{cause}; it was lost again after {MAX_DEVICE_RECOVERIES} recoveries, so the \
                 workbench stops (restart it; its view layout was saved)"
            )));
            self.handed_over = true;
            return true;
        }
        log::warn!(
            "the GPU device was lost; opening a new window on a new device (recovery {} of {})",
            self.recoveries + 1,
            MAX_DEVICE_RECOVERIES
        );
        let layout = Layout::new(&[], &self.settings.display);
        let mut empty = Self::unbound(self.options.clone(), self.settings.clone(), layout, false);
        empty.handed_over = true;
        let app = std::mem::replace(self, empty);
        *handover.borrow_mut() = Some(Ok(app));
        true
    }

    /// The app after its device was lost, in a new window: the renderer made again on the new
    /// device from the open scene (camera, sun, settings and views as they were).
    pub fn resume(mut self, cc: &eframe::CreationContext<'_>) -> Self {
        self.recoveries += 1;
        self.window_start_frame = self.frames;
        // The views' textures were registered with the old window's egui renderer, which is
        // gone (forgotten, not freed), and their metrics were timed by the old window's clock.
        for p in self.layout.panes_mut() {
            p.rt = image_views::PaneRuntime::default();
        }
        // The new window's clock starts again at 0: every "last done at" goes.
        self.last_frame_time = None;
        self.frame_ms_smoothed = 0.0;
        self.last_metrics_time = 0.0;
        self.pixel.read = None;
        self.pixel.rows.clear();
        self.story.forget_read_time();
        self.tree_panel.forget_refresh_time();
        // A screenshot asked of the old window never comes: ask the new one.
        if !self.screenshot_done.load(Ordering::Acquire) {
            self.screenshot_requested = false;
        }
        self.cancel_sheet = false;
        self.renderer = None;
        self.timings = None;
        self.sampling_stats = None;
        self.compare_metrics = None;
        self.cut_inspect = None;
        if self.sheet_job.take().is_some() {
            self.sheet_status = None;
            self.errors
                .push("comparison sheet: cancelled by the lost GPU device; start it again".into());
        }
        self.render_state = cc.wgpu_render_state.clone();
        let Some(rs) = self.render_state.clone() else {
            self.errors.push(format!(
                "The GPU device was lost and no new one could be made: {}",
                crate::gpu::context::NO_ADAPTER_HELP
            ));
            return self;
        };
        self.adapter = describe_adapter(&rs.adapter.get_info());
        let made = match &self.open {
            Some(open) => self.make_renderer(&rs, &open.scene).map(Some),
            None => Ok(None),
        };
        match made {
            Ok(r) => {
                self.renderer = r;
                self.errors.push(format!(
                    "The GPU device was lost and was recreated ({}, recovery {} of {}); \
                     rendering goes on with the same settings, scene and views (the A/B \
                     snapshots were on the lost device and are gone).",
                    self.adapter, self.recoveries, MAX_DEVICE_RECOVERIES
                ));
            }
            Err(e) => self.errors.push(format!(
                "The GPU device was lost; the new device could not render: {e}"
            )),
        }
        self
    }
}
