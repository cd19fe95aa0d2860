//! ReSTIR over the VPLs (issue 39; Bitterli et al. 2020): per pixel, candidates drawn from
//! the light tree and by flux, resampled into one reservoir against the unshadowed
//! contribution, reused across frames and neighbours, one shadow ray for the kept VPL.
//!
//! This first part is the resampling as plain Rust ([`reservoir`]): weighted reservoir
//! sampling, RIS over several candidate sources with the balance heuristic, the biased and
//! the unbiased (1/Z) combination, the temporal M cap, each held to its distribution by a
//! statistical test. The GPU method (its passes, registry line, views and story) builds on
//! it and is checked against it.

pub mod reservoir;
