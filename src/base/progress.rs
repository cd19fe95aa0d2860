//! How far a progressive method (the ground truth, the converged reference) has come.

/// Progress of a progressive method: VPLs (ground truth) or samples per pixel (reference).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GiProgress {
    /// Units done so far (`MethodInfo::progress_unit`).
    pub done: u32,
    pub total: u32,
}

impl GiProgress {
    pub fn fraction(&self) -> f32 {
        if self.total == 0 {
            1.0
        } else {
            self.done as f32 / self.total as f32
        }
    }
    pub fn finished(&self) -> bool {
        self.done >= self.total
    }
}
