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

    /// At the start of a UI frame: destroys the device when `--lose-device-at-frame` says so,
    /// and hands the app over when the device is lost. True: this window's app is gone (the
    /// window shows a line and closes).
    pub(super) fn hand_over_if_lost(&mut self, ctx: &egui::Context) -> bool {
        if self.handed_over {
            return true;
        }
        let Some(renderer) = self.renderer.as_ref() else {
            return false;
        };
        if self
            .options
            .lose_device_at_frame
            .is_some_and(|n| self.frames >= n)
        {
            self.options.lose_device_at_frame = None;
            log::warn!(
                "destroying the GPU device at frame {} (--lose-device-at-frame)",
                self.frames
            );
            renderer.ctx.device.destroy();
            let _ = renderer.ctx.device.poll(wgpu::PollType::Poll);
        }
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
        if self.recoveries >= MAX_DEVICE_RECOVERIES {
            return false;
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
        *handover.borrow_mut() = Some(app);
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        true
    }

    /// The app after its device was lost, in a new window: the renderer made again on the new
    /// device from the open scene (camera, sun, settings and views as they were).
    pub fn resume(mut self, cc: &eframe::CreationContext<'_>) -> Self {
        self.recoveries += 1;
        // Registered with the old window's egui renderer, which is gone: forget, not free.
        for p in self.layout.panes_mut() {
            p.rt.texture = viewport_texture::ViewportTexture::new();
        }
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
                crate::renderer::context::NO_ADAPTER_HELP
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
                     rendering goes on with the same settings and scene.",
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
