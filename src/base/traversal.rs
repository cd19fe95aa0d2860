//! Counters of a light-tree traversal (plain numbers, no GPU): what the tree samplers count
//! in their diagnostic frames and every figure, the GUI's statistics and `render`'s summary
//! read through `Method::traversal_stats`, without naming the method that counted them.

/// Counters of tree sampling: one frame's, or several frames' summed ([`TraversalStats::add`]).
/// 64-bit: SST at 64 spp takes ~6e8 steps per 1280x720 frame, so a few frames' sum passes
/// 2^32 (the 64-spp anomaly of the H100 sweeps was a u32 sum that wrapped).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraversalStats {
    /// Pixels with geometry.
    pub pixels: u64,
    /// Pixels without a similar cut (mock cut or other fallback).
    pub fallback_pixels: u64,
    /// Traversal steps, all pixels.
    pub steps: u64,
    /// Traversals started.
    pub traversals: u64,
    /// Traversals that ended in a dead branch (both children weigh 0).
    pub dead: u64,
    /// Shadow rays traced (samples with G > 0 while shadow rays are on).
    pub rays: u64,
}

impl TraversalStats {
    /// Parses the counter words: two 32-bit counters, then four 64-bit ones as (low, high)
    /// pairs (the tree samplers' layout in `slc_sample.wgsl`).
    pub fn from_words(w: &[u32]) -> Self {
        let g = |i: usize| w.get(i).copied().unwrap_or(0) as u64;
        let pair = |i: usize| g(i) | (g(i + 1) << 32);
        Self {
            pixels: g(0),
            fallback_pixels: g(1),
            steps: pair(2),
            traversals: pair(4),
            dead: pair(6),
            rays: pair(8),
        }
    }
}

/// The sum of two frames' counters.
impl std::ops::Add for TraversalStats {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            pixels: self.pixels + o.pixels,
            fallback_pixels: self.fallback_pixels + o.fallback_pixels,
            steps: self.steps + o.steps,
            traversals: self.traversals + o.traversals,
            dead: self.dead + o.dead,
            rays: self.rays + o.rays,
        }
    }
}

impl TraversalStats {
    /// Mean traversal steps per traversal (thesis fig. 7.2 counts per pixel and sample).
    pub fn steps_per_traversal(&self) -> f64 {
        self.steps as f64 / self.traversals.max(1) as f64
    }
    /// Mean traversal steps per pixel (all its samples).
    pub fn steps_per_pixel(&self) -> f64 {
        self.steps as f64 / self.pixels.max(1) as f64
    }
    pub fn fallback_fraction(&self) -> f64 {
        self.fallback_pixels as f64 / self.pixels.max(1) as f64
    }
}

/// Per pixel of a diagnostic frame (row-major at the method's GI resolution): traversal steps
/// per traversal and whether the pixel had no similar cut (fell back).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TraversalPixels {
    pub steps: Vec<f32>,
    pub fallback: Vec<bool>,
}
