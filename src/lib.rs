//! lightcut-workbench: a GUI research workbench and debugger for real-time many-light global
//! illumination (Stochastic Light Cut Exploration). See ARCHITECTURE.md for the module map.

pub mod app;
pub mod cli;
pub mod export;
pub mod harness;
pub mod metrics;
#[doc(hidden)]
pub mod reference;
pub mod renderer;
pub mod scene;
pub mod sheet;
