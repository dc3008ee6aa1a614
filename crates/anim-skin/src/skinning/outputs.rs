//! The output slices of one chunk of vertices: posed positions and unit normals as
//! structure-of-arrays, the part of the mesh's outputs that one parallel task writes. Both the
//! portable and the AVX2 kernels fill them.

/// One chunk's output slices.
pub(super) struct Outputs<'a> {
    pub(super) x: &'a mut [f64],
    pub(super) y: &'a mut [f64],
    pub(super) z: &'a mut [f64],
    pub(super) nx: &'a mut [f64],
    pub(super) ny: &'a mut [f64],
    pub(super) nz: &'a mut [f64],
}
