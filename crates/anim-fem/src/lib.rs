//! # anim-fem
//!
//! Tetrahedral finite elements for hyperelastic solids (seed section 5.2): explicit and implicit time integration, Newton with sparse assembly, contact.
