//! The floor every other module stands on: plain CPU types and functions with no GPU, UI or
//! method knowledge. The image type, display encoding and tonemaps, colour maps, the GPU
//! record layouts of a VPL and a tree node (and the node's decoding and merge), and the
//! choices shared by settings and CPU references. `renderer`, `reference`, `methods`,
//! `metrics`, `export`, `harness`, `sheet` and `app` import from here; nothing here imports
//! from them.

pub mod brdf;
pub mod colormap;
pub mod display;
pub mod field;
pub mod gpu_layout;
pub mod image;
pub mod progress;
pub mod sampling;
pub mod settings_ui;
pub mod sst_node;
pub mod story;
pub mod traversal;
