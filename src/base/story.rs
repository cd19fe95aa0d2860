//! What the pixel story shows of a method (`Method::read_story`): a sampling method's traced
//! samples ([`PixelTrace`], the tree samplers' `slc_sample` records it on the GPU) or a
//! cut-based method's cuts ([`CutStory`]). Plain data: the app draws it, the methods fill it.

/// The pinned pixel's story as a method tells it.
#[derive(Clone, Debug, PartialEq)]
pub enum Story {
    /// Every sample of a sampling method (the tree samplers).
    Samples(PixelTrace),
    /// The cuts of a cut-based method (Lightcuts, Lightcut Interpolation).
    Cuts(CutStory),
}

/// Where a traversal stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// At a usable node (v >= v_min and sigma_z < sigma_max): its distribution is sampled.
    Usable,
    /// At a leaf (a single VPL).
    Leaf,
    /// Both children of a node weigh 0 (nothing there can light the point).
    Dead,
    /// The cut slot was empty (fewer nodes than the cut size).
    EmptySlot,
}

impl StopReason {
    pub fn name(self) -> &'static str {
        match self {
            StopReason::Usable => "usable node",
            StopReason::Leaf => "leaf (VPL)",
            StopReason::Dead => "dead branch",
            StopReason::EmptySlot => "empty cut slot",
        }
    }
}

/// Whether the sampled light point reached the pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleVisibility {
    /// G = 0: the point and the pixel face away from each other (no shadow ray).
    FacingAway,
    /// The shadow ray hit geometry.
    Blocked,
    Visible,
}

/// One sample of the traced pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceSample {
    /// Which of the 4 surrounding blocks' cuts it came from (0-3), or None (mock cut, root,
    /// recomputed cut).
    pub slot: Option<usize>,
    /// The cut slot it sampled (its index in the cut; SST: the sample's number).
    pub cut_slot: u32,
    /// The node the traversal started at (0: empty slot).
    pub start: u32,
    /// The node it stopped at (0: dead branch).
    pub end: u32,
    pub steps: u32,
    pub stop: StopReason,
    /// Probability of the path (product of the child probabilities).
    pub prob: f32,
    /// The nodes taken below `start`, each with the probability of taking it (at most
    /// the trace's path length).
    pub path: Vec<(u32, f32)>,
    /// The sampled light point (world) and what its shadow ray found (None: not evaluated).
    pub point: Option<(glam::Vec3, SampleVisibility)>,
    /// Flux/pi x G x V / prob: the sample's estimate of the incident sum (times rho/pi is
    /// radiance; SST divides by the sample count).
    pub contribution: glam::Vec3,
    /// With ISM visibility: the light-tree leaf whose map it looked up.
    pub ism_map: Option<u32>,
}

/// The story of one pixel in the last tree-sampling frame: the 4 surrounding blocks, their
/// bilinear and blend weights, whether it fell back, and every sample (at most
/// the trace's sample count).
#[derive(Clone, Debug, PartialEq)]
pub struct PixelTrace {
    /// 0 blended cuts, 1 mock cut, 2 from the root, 3 recomputed cut.
    pub mode: u32,
    pub fell_back: bool,
    pub blocks: [u32; 4],
    pub bilinear: [f32; 4],
    /// Bilinear x similarity (the blend weights before normalising).
    pub weights: [f32; 4],
    pub weight_sum: f32,
    /// Samples the pixel took this frame: the cut size, or with interleaving its subset's
    /// share of the slots.
    pub taken: u32,
    /// The interleaving's n^2 (1: off) and the pixel's subset.
    pub cells: u32,
    pub subset: u32,
    /// Whether the interleaving's geometry-aware filter ran after the samples (the GI buffer
    /// then holds the filtered value, not this pixel's estimate).
    pub filtered: bool,
    pub samples: Vec<TraceSample>,
}

impl PixelTrace {
    /// The pixel's estimate of the incident sum from its samples (times rho / pi it is the
    /// radiance; before the interleaving's filter): their sum x n^2, or from the root their
    /// mean.
    pub fn estimate(&self) -> glam::Vec3 {
        let sum: glam::Vec3 = self.samples.iter().map(|s| s.contribution).sum();
        if self.mode == 2 {
            sum / self.taken.max(1) as f32
        } else {
            sum * self.cells as f32
        }
    }

    pub fn mode_name(&self) -> &'static str {
        match self.mode {
            0 => "blended cuts of the 4 surrounding blocks",
            1 => "mock cut (no similar block cut)",
            2 => "from the root",
            _ => "own cut, recomputed at the pixel",
        }
    }
}

/// One cut of a cut story: nodes of the frame's light tree (root 1).
#[derive(Clone, Debug, PartialEq)]
pub struct StoryCut {
    pub label: String,
    pub nodes: Vec<u32>,
}

/// The pinned pixel's cuts as a cut-based method tells them (Lightcuts: its cut; Lightcut
/// Interpolation: the records' cuts, the interpolated cut and where the inputs disagree).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CutStory {
    /// (what, value) rows of the story's table.
    pub rows: Vec<(String, String)>,
    /// Input cuts (drawn in colours) and the pixel's own cut (drawn last, white).
    pub inputs: Vec<StoryCut>,
    pub cut: Option<StoryCut>,
    /// Leaf intervals [start, end) where the inputs disagree.
    pub disagreements: Vec<(u32, u32)>,
    /// The radix tree's links when the cuts are on it (`base::sst_node::Topology::radix`;
    /// the renderer fills them in), empty on the perfect tree.
    pub links: Vec<[u32; 4]>,
}

/// A block's light cut, picked in a view of a method's cut blocks (`Method::pick_block`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BlockCut {
    /// The block's index (row-major over the method's block grid) and its (x, y) in blocks.
    pub index: u32,
    pub block: (u32, u32),
    /// The cut's node ids, in slot order, without empty slots.
    pub nodes: Vec<u32>,
}
