//! # anim-fluid
//!
//! Grid fluids (seed section 6): Stam's stable fluids reproduced operation for operation, and a MAC-grid solver with BFECC advection and multigrid-preconditioned pressure, 2D and 3D.
