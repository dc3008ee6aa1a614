//! # anim-mpm
//!
//! The material point method (seed section 5.3): APIC and MLS-MPM in 2D and 3D with elastic, snow, fluid and sand materials on a sparse grid, parallel and deterministic.
