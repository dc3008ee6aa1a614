//! A body of a `pbd` scene file (one `[[scene.bodies]]` table, [`BodySpec`]): a soft body from a
//! tetrahedral mesh (Gmsh `.msh` 2.2 or 4.1, TetGen `.node`/`.ele`, or a closed OBJ surface
//! tetrahedralised on load) or a cloth from an OBJ triangle surface, with its material, placement,
//! initial velocity and pinned vertices.
//!
//! The mesh is read, placed (scale, rotation, translation: [`Placement`]; a mesh placed too
//! large for its volumes to be finite is refused, naming `scale`), checked element by element in
//! the file's numbering (a repeated vertex, an inverted tetrahedron or one of zero volume, or a
//! triangle of zero area is refused, naming the file and the element), and added to a
//! [`PbdBuilder`]:
//!
//! - **soft**: [`PbdBuilder::tet_mesh`], a distance constraint on every edge (`stretch`) and a
//!   volume constraint per tetrahedron (`volume`), the masses lumped from `density` (kg/m^3), a
//!   quarter of each tetrahedron's mass to each corner; as the `soft-blob` preset.
//! - **cloth**: [`PbdBuilder::triangle_mesh`], a distance constraint on every edge (`stretch`),
//!   a bending constraint across every interior edge (`bending`, dihedral or isometric), the
//!   masses lumped from `density` (kg/m^2), a third of each triangle's mass to each corner; with
//!   `pressure`, a closed surface also keeps `pressure` times its enclosed volume (a balloon:
//!   [`PbdBuilder::global_volume`] with the `volume` parameters).
//!
//! Vertices of the file that no element uses (a Gmsh geometry point, a stray OBJ vertex) are left
//! out of the body; pinning one is refused.

use crate::build::{Bending, MeshMass, MeshParams, NotClosed, PbdBuilder, TetMeshParams, closed_outward};
use crate::constraint::{ConstraintParams, tet_is_flat, tet_volume};
use anim_core::glam::DVec3;
use anim_core::scene::{BuildContext, BuildError, Placement, is_default};
use anim_core::scene::{is_unit_scale, unit_scale};
use serde::{Deserialize, Serialize};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// What a body is made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BodyType {
    /// A soft solid from tetrahedra: edge distances and tetrahedral volumes.
    Soft,
    /// A cloth or shell from triangles: edge distances and bending (and a volume with
    /// `pressure`).
    Cloth,
}

/// The material of a body: its density and the parameters of its constraints, each the crate's
/// [`ConstraintParams`] (`{ compliance, stiffness, damping, kind }`, every field optional: XPBD
/// compliance `alpha >= 0`, default 0, rigid; PBD stiffness `k` in `[0, 1]`, default 1; XPBD
/// damping `beta >= 0`, default 0; `kind` `"equality"` (default) or `"inequality"`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyMaterial {
    /// Density: kg/m^3 for a soft body, kg/m^2 (mass per area) for a cloth. Positive; required.
    pub density: f64,
    /// The distance constraint on every edge (compliance in m/N). Default rigid.
    #[serde(default, skip_serializing_if = "is_default")]
    pub stretch: ConstraintParams,
    /// A soft body's volume constraint per tetrahedron, or a cloth's global volume constraint when
    /// it has a `pressure` (compliance in m^6/J). Default rigid; refused on a cloth without
    /// `pressure`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub volume: Option<ConstraintParams>,
    /// A cloth's bending across interior edges: `"none"`, `{ isometric = { compliance = ... } }`
    /// (Bergou et al. 2006, for inextensible cloth) or `{ dihedral = { compliance = ... } }`
    /// (Müller et al. 2007, compliance in rad^2/J). Default `"none"`; refused on a soft body.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending: Option<Bending>,
    /// A closed cloth's over-pressure: it keeps `pressure` times its enclosed volume (1 keeps the
    /// rest volume, more inflates it; Müller et al. 2007, 4.4). Positive; default none; refused on
    /// a soft body and on an open surface.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<f64>,
}

pub use anim_core::scene::{PinBox, PinSpec};

/// One `[[scene.bodies]]` table of a `pbd` scene file. Every field but `mesh` and `material` has
/// a default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// `"soft"` or `"cloth"`. Default: from the file, a tetrahedral mesh (`.msh`, `.node`,
    /// `.ele`) is soft, an `.obj` is a cloth, or soft when `cell` is given.
    #[serde(rename = "type", default, skip_serializing_if = "Option::is_none")]
    pub body_type: Option<BodyType>,
    /// The mesh file, relative to the scene file: Gmsh `.msh` (2.2 or 4.1 ASCII, its 4-node
    /// tetrahedra), TetGen `.node` or `.ele` (the pair is read), or Wavefront `.obj` (its faces,
    /// polygons split into triangle fans). Required.
    pub mesh: PathBuf,
    /// The edge length (m, after the placement) of the tetrahedra a soft body from a closed OBJ
    /// surface is filled with. Required for such a body, refused otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cell: Option<f64>,
    /// The material. Required.
    pub material: BodyMaterial,
    /// Uniform scale about the mesh's origin, positive. Default 1.
    #[serde(default = "unit_scale", skip_serializing_if = "is_unit_scale")]
    pub scale: f64,
    /// Roll, pitch, yaw (rad) about the mesh's origin, after the scale: `Rz(yaw) Ry(pitch)
    /// Rx(roll)`. Default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub rotate: [f64; 3],
    /// Translation (m), applied last. Default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub translate: [f64; 3],
    /// Initial velocity of every vertex but the pinned ones (m/s). Default at rest.
    #[serde(default, skip_serializing_if = "is_default")]
    pub velocity: [f64; 3],
    /// Pinned vertices. Default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pin: Option<PinSpec>,
}

/// A body added to a builder.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct AddedBody {
    /// Its particles.
    pub particles: Range<usize>,
    /// Its surface triangles (model indices): a soft body's boundary, a cloth's triangles.
    pub surface: Vec<[usize; 3]>,
    /// Whether the surface is closed and oriented outward.
    pub closed: bool,
    /// Its pinned particles (model indices), in increasing order.
    pub pinned: Vec<usize>,
}

/// The file formats a body reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Gmsh,
    TetGen,
    Obj,
}

/// The elements of a mesh: tetrahedra or triangles.
enum Elements {
    Tets(Vec<[usize; 4]>),
    Triangles(Vec<[usize; 3]>),
}

impl BodySpec {
    /// The body's kind: `type` when given, else from the mesh file's extension and `cell`; `None`
    /// for a file of unknown extension.
    #[must_use]
    pub fn kind(&self) -> Option<BodyType> {
        let format = format(&self.mesh)?;
        Some(match (self.body_type, format) {
            (Some(t), _) => t,
            (None, Format::Gmsh | Format::TetGen) => BodyType::Soft,
            (None, Format::Obj) if self.cell.is_some() => BodyType::Soft,
            (None, Format::Obj) => BodyType::Cloth,
        })
    }

    /// The placement of the mesh.
    #[must_use]
    pub fn placement(&self) -> Placement {
        Placement { scale: self.scale, rotate: self.rotate, translate: self.translate }
    }

    /// Reads body `k`'s mesh (relative to `context`), places it and adds it to `b`.
    pub(crate) fn add(
        &self,
        k: usize,
        context: &BuildContext<'_>,
        b: &mut PbdBuilder,
    ) -> Result<AddedBody, BuildError> {
        let field = |name: &str| format!("bodies[{k}].{name}");
        let path = context.resolve(&self.mesh);
        let file = path.display().to_string();
        let Some(format) = format(&self.mesh) else {
            return Err(BuildError::invalid(
                field("mesh"),
                format!("{file}: unknown mesh format (a Gmsh .msh, a TetGen .node/.ele or an .obj)"),
            ));
        };
        let kind = self.kind().unwrap_or(BodyType::Soft);
        match (kind, format, self.cell) {
            (BodyType::Cloth, Format::Gmsh | Format::TetGen, _) => {
                return Err(BuildError::invalid(
                    field("type"),
                    format!("a cloth is made of an OBJ surface; {file} is a tetrahedral mesh"),
                ));
            }
            (BodyType::Soft, Format::Obj, None) => {
                return Err(BuildError::invalid(
                    field("cell"),
                    format!(
                        "a soft body from the OBJ surface {file} needs `cell`, the edge length (m) of the \
                         tetrahedra it is filled with"
                    ),
                ));
            }
            (BodyType::Cloth, _, Some(_)) | (_, Format::Gmsh | Format::TetGen, Some(_)) => {
                return Err(BuildError::invalid(
                    field("cell"),
                    "only a soft body from an OBJ surface is tetrahedralised: a tetrahedral mesh has its \
                     own cells and a cloth has none",
                ));
            }
            _ => {}
        }
        if let Some(cell) = self.cell
            && !(cell > 0.0 && cell.is_finite())
        {
            return Err(BuildError::invalid(
                field("cell"),
                format!("must be positive and finite, got {cell}"),
            ));
        }
        self.check_material(k, kind)?;
        let placement = self.placement();
        placement.check().map_err(|e| e.within(&format!("bodies[{k}]")))?;
        if !self.velocity.iter().all(|v| v.is_finite()) {
            return Err(BuildError::invalid(
                field("velocity"),
                format!("{:?} holds a non-finite value", self.velocity),
            ));
        }
        let (mut positions, elements) =
            read(&path, format, kind).map_err(|m| BuildError::invalid(field("mesh"), m))?;
        placement.apply_all(&mut positions);
        if let Some(i) = positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(BuildError::invalid(
                field("scale"),
                format!("{file}: vertex {i} is not finite after the placement ({:?})", positions[i]),
            ));
        }
        // Volumes are products of three coordinate differences, each at most twice the span.
        let span = span(&positions, &elements);
        if !(2.0 * span).powi(3).is_finite() {
            return Err(BuildError::invalid(
                field("scale"),
                format!(
                    "{file}: placed, the mesh spans {span:e} m, too large to measure its volumes (the scale \
                     is too large)"
                ),
            ));
        }
        // A soft body from an OBJ surface: its tetrahedra replace the surface.
        let (positions, elements, file_vertices) = match (kind, elements, self.cell) {
            (BodyType::Soft, Elements::Triangles(tris), Some(cell)) => {
                let (p, t) = super::surface::tetrahedralize(&file, positions, tris, cell)
                    .map_err(|(name, m)| BuildError::invalid(field(name), m))?;
                (p, Elements::Tets(t), None)
            }
            (_, elements, _) => {
                let n = positions.len();
                (positions, elements, Some(n))
            }
        };
        check_elements(&file, &positions, &elements).map_err(|m| BuildError::invalid(field("mesh"), m))?;
        // The used vertices, in file order: file index -> body vertex.
        let mut map: Vec<Option<usize>> = vec![None; positions.len()];
        match &elements {
            Elements::Tets(t) => t.iter().flatten().for_each(|&i| map[i] = Some(0)),
            Elements::Triangles(t) => t.iter().flatten().for_each(|&i| map[i] = Some(0)),
        }
        let mut used = Vec::with_capacity(positions.len());
        for (i, m) in map.iter_mut().enumerate() {
            if m.is_some() {
                *m = Some(used.len());
                used.push(positions[i]);
            }
        }
        let pinned = self.pins(k, &file, &positions, &map, file_vertices)?;
        let local = |i: usize| map[i].unwrap_or(0);
        let first = b.num_particles();
        let material = self.material;
        let mass = MeshMass::Density(material.density);
        let builder_error = |e: crate::BuildError| BuildError::invalid(field("mesh"), format!("{file}: {e}"));
        let (particles, surface, closed) = match elements {
            Elements::Tets(tets) => {
                let tets: Vec<[usize; 4]> = tets.iter().map(|t| t.map(local)).collect();
                let params = TetMeshParams {
                    mass,
                    stretch: Some(material.stretch),
                    volume: Some(material.volume.unwrap_or_default()),
                };
                let before = b.recorded_triangles().len();
                let r = b.tet_mesh(&used, &tets, &params).map_err(builder_error)?;
                // The boundary faces the builder recorded, in the body's numbering.
                let surface: Vec<[usize; 3]> =
                    b.recorded_triangles()[before..].iter().map(|t| t.map(|i| i - r.start)).collect();
                let closed = closed_outward(&surface, |i| DVec3::from_array(used[i])).is_ok();
                (r, surface, closed)
            }
            Elements::Triangles(tris) => {
                let tris: Vec<[usize; 3]> = tris.iter().map(|t| t.map(local)).collect();
                let params = MeshParams {
                    mass,
                    stretch: material.stretch,
                    bending: material.bending.unwrap_or(Bending::None),
                };
                let outward = closed_outward(&tris, |i| DVec3::from_array(used[i]));
                let closed = outward.is_ok();
                if let Some(pressure) = material.pressure {
                    match outward {
                        Ok(()) => {}
                        Err(NotClosed::Open(reason)) => {
                            return Err(BuildError::invalid(
                                field("material.pressure"),
                                format!(
                                    "{file}: a cloth with pressure must be a closed surface, but {reason}"
                                ),
                            ));
                        }
                        Err(inward @ NotClosed::Inward(_)) => {
                            return Err(BuildError::invalid(
                                field("material.pressure"),
                                format!("{file}: {inward}"),
                            ));
                        }
                    }
                    let r = b.triangle_mesh(&used, &tris, &params).map_err(builder_error)?;
                    let shifted: Vec<[usize; 3]> = tris.iter().map(|t| t.map(|i| r.start + i)).collect();
                    b.global_volume(&shifted, pressure, material.volume.unwrap_or_default());
                    (r, tris, closed)
                } else {
                    let r = b.triangle_mesh(&used, &tris, &params).map_err(builder_error)?;
                    (r, tris, closed)
                }
            }
        };
        debug_assert_eq!(particles.start, first);
        let surface = surface.iter().map(|t| t.map(|i| first + i)).collect();
        let pinned: Vec<usize> = pinned.iter().map(|&i| first + i).collect();
        for &p in &pinned {
            b.pin(p);
        }
        Ok(AddedBody { particles, surface, closed, pinned })
    }

    /// Checks the material of body `k` of kind `kind`.
    fn check_material(&self, k: usize, kind: BodyType) -> Result<(), BuildError> {
        let field = |name: &str| format!("bodies[{k}].material.{name}");
        let m = &self.material;
        if !(m.density > 0.0 && m.density.is_finite()) {
            return Err(BuildError::invalid(
                field("density"),
                format!("must be positive and finite, got {}", m.density),
            ));
        }
        check_constraint(&field("stretch"), &m.stretch)?;
        if let Some(v) = &m.volume {
            check_constraint(&field("volume"), v)?;
        }
        match kind {
            BodyType::Soft => {
                for (name, given) in [("bending", m.bending.is_some()), ("pressure", m.pressure.is_some())] {
                    if given {
                        return Err(BuildError::invalid(
                            field(name),
                            format!(
                                "a soft body has no {name} (a cloth's); its tetrahedra keep their volumes"
                            ),
                        ));
                    }
                }
            }
            BodyType::Cloth => {
                if m.volume.is_some() && m.pressure.is_none() {
                    return Err(BuildError::invalid(
                        field("volume"),
                        "a cloth has a volume constraint only with `pressure` (a closed surface)",
                    ));
                }
                if let Some(p) = m.pressure
                    && !(p > 0.0 && p.is_finite())
                {
                    return Err(BuildError::invalid(
                        field("pressure"),
                        format!("must be positive and finite, got {p}"),
                    ));
                }
                match m.bending {
                    Some(Bending::Dihedral(c) | Bending::Isometric(c)) => {
                        check_constraint(&field("bending"), &c)?
                    }
                    Some(Bending::None) | None => {}
                }
            }
        }
        Ok(())
    }

    /// The pinned body vertices of body `k` (placed `positions`, file index -> body vertex
    /// `map`; `file_vertices` the file's vertex count, `None` when the body's vertices are not
    /// the file's), in increasing order.
    fn pins(
        &self,
        k: usize,
        file: &str,
        positions: &[[f64; 3]],
        map: &[Option<usize>],
        file_vertices: Option<usize>,
    ) -> Result<Vec<usize>, BuildError> {
        let Some(pin) = &self.pin else { return Ok(Vec::new()) };
        let fail = |m: String| BuildError::invalid(format!("bodies[{k}].pin"), m);
        if file_vertices.is_none() && !pin.vertices.is_empty() {
            return Err(fail(format!(
                "`vertices` name vertices of the mesh file, but a soft body tetrahedralised from {file} has \
                 vertices of its own: pin it with a `box`"
            )));
        }
        let pinned = pin
            .resolve_among(positions, file, |i| map[i].is_some())
            .map_err(|e| BuildError::invalid(e.field_under(&format!("bodies[{k}].pin")), e.to_string()))?;
        // The box took used vertices only; a listed one may be unused.
        pinned
            .iter()
            .map(|&i| {
                map[i].ok_or_else(|| fail(format!("vertex {i} of {file} belongs to no element of the body")))
            })
            .collect()
    }
}

/// A constraint's parameters in range, or an error naming `field`.
fn check_constraint(field: &str, c: &ConstraintParams) -> Result<(), BuildError> {
    let bad = |m: String| Err(BuildError::invalid(field, m));
    if !(0.0..=1.0).contains(&c.stiffness) {
        return bad(format!("stiffness must lie in [0, 1], got {}", c.stiffness));
    }
    if !(c.compliance >= 0.0 && c.compliance.is_finite()) {
        return bad(format!("compliance must be non-negative and finite, got {}", c.compliance));
    }
    if !(c.damping >= 0.0 && c.damping.is_finite()) {
        return bad(format!("damping must be non-negative and finite, got {}", c.damping));
    }
    Ok(())
}

/// The format of a mesh file by its extension.
fn format(mesh: &Path) -> Option<Format> {
    match mesh.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "msh" => Some(Format::Gmsh),
        "node" | "ele" => Some(Format::TetGen),
        "obj" => Some(Format::Obj),
        _ => None,
    }
}

/// Reads a mesh file: its positions and elements (file numbering), or a message naming the
/// file.
fn read(path: &Path, format: Format, kind: BodyType) -> Result<(Vec<[f64; 3]>, Elements), String> {
    let file = path.display();
    match format {
        Format::Gmsh => {
            let m = anim_io::gmsh::read_gmsh(path).map_err(|e| e.to_string())?;
            if let Some(s) = m.skipped_volume_elements().first() {
                return Err(format!(
                    "{file}: holds {} volume elements of Gmsh type {} that are not 4-node tetrahedra",
                    s.count, s.element_type
                ));
            }
            if m.tets.is_empty() {
                return Err(format!("{file}: holds no 4-node tetrahedra"));
            }
            Ok((m.positions, Elements::Tets(m.tets)))
        }
        Format::TetGen => {
            let m = anim_io::tetgen::read_tetgen(path).map_err(|e| e.to_string())?;
            if m.tets.is_empty() {
                return Err(format!("{file}: holds no tetrahedra"));
            }
            Ok((m.positions, Elements::Tets(m.tets)))
        }
        Format::Obj => {
            let m = anim_io::obj::read_obj(path, anim_io::obj::Polygons::Triangulate)
                .map_err(|e| e.to_string())?;
            if m.triangles.is_empty() {
                return Err(format!("{file}: holds no faces"));
            }
            if !m.lines.is_empty() {
                let what = if kind == BodyType::Soft { "a soft body's surface" } else { "a cloth" };
                return Err(format!(
                    "{file}: holds {} line elements (`l`); {what} is made of faces only",
                    m.lines.len()
                ));
            }
            Ok((m.positions, Elements::Triangles(m.triangles)))
        }
    }
}

/// Refuses an element with a repeated vertex, a tetrahedron with `|V| <= 1e-12 l^3` (`l` its
/// longest edge) or a negative signed volume (inverted), or a triangle with twice its area `<= 1e-12` times its longer edge at the first
/// corner squared: the builder's own tests, here in the file's numbering.
fn check_elements(file: &str, positions: &[[f64; 3]], elements: &Elements) -> Result<(), String> {
    let p = |i: usize| DVec3::from_array(positions[i]);
    let list = |v: &[usize]| v.iter().map(ToString::to_string).collect::<Vec<_>>().join(", ");
    match elements {
        Elements::Tets(tets) => {
            for (t, tet) in tets.iter().enumerate() {
                if (0..4).any(|a| (a + 1..4).any(|b| tet[a] == tet[b])) {
                    return Err(format!("{file}: tetrahedron {t} (vertices {}) repeats a vertex", list(tet)));
                }
                let x = tet.map(p);
                let v = tet_volume(x).0;
                if tet_is_flat(x, v) {
                    return Err(format!(
                        "{file}: tetrahedron {t} (vertices {}) has zero volume (placed: {v:e} m^3)",
                        list(tet)
                    ));
                }
                if v < 0.0 {
                    return Err(format!(
                        "{file}: tetrahedron {t} (vertices {}) is inverted (signed volume {v:e} m^3)",
                        list(tet)
                    ));
                }
            }
        }
        Elements::Triangles(tris) => {
            for (t, tri) in tris.iter().enumerate() {
                let [a, b, c] = *tri;
                if a == b || b == c || a == c {
                    return Err(format!("{file}: triangle {t} (vertices {}) repeats a vertex", list(tri)));
                }
                let (e1, e2) = (p(b) - p(a), p(c) - p(a));
                if !(e1.cross(e2).length() > 1e-12 * e1.length_squared().max(e2.length_squared())) {
                    return Err(format!("{file}: triangle {t} (vertices {}) has zero area", list(tri)));
                }
            }
        }
    }
    Ok(())
}

/// The largest extent along an axis of the vertices of `elements`.
fn span(positions: &[[f64; 3]], elements: &Elements) -> f64 {
    let mut used = vec![None; positions.len()];
    match elements {
        Elements::Tets(t) => t.iter().flatten().for_each(|&i| used[i] = Some(0)),
        Elements::Triangles(t) => t.iter().flatten().for_each(|&i| used[i] = Some(0)),
    }
    let (lo, hi) = bounds(positions, &used);
    (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max)
}

/// The bounds of the used vertices.
fn bounds(positions: &[[f64; 3]], map: &[Option<usize>]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (p, _) in positions.iter().zip(map).filter(|(_, m)| m.is_some()) {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}
