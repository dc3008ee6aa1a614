//! A soft body from a closed OBJ surface: the surface filled with tetrahedra.

/// The tetrahedra filling the closed surface `positions`, `triangles` of `file`, of edge about
/// `cell`; or the field (under the body) and the message.
pub(super) fn tetrahedralize(
    file: &str,
    positions: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    cell: f64,
) -> Result<(Vec<[f64; 3]>, Vec<[usize; 4]>), (&'static str, String)> {
    let _ = (positions, triangles, cell);
    Err(("cell", format!("{file}: filling an OBJ surface with tetrahedra is not available in this build")))
}
