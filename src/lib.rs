//! lightcut-workbench: a GUI research workbench and debugger for real-time many-light global
//! illumination (Stochastic Light Cut Exploration). See ARCHITECTURE.md for the module map.

pub mod app;
pub mod base;
pub mod capture;
pub mod cli;
pub mod export;
pub mod gpu;
pub mod harness;
#[doc(hidden)]
pub mod methods;
pub mod metrics;
pub mod reference;
pub mod renderer;
pub mod scene;
pub mod settings;
pub mod sheet;
