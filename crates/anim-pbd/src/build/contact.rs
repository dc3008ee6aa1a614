//! Contact bodies: ranges of particles that collide with each other's surfaces
//! ([`crate::collide`], "Contacts between bodies"). A contact body names its particles and its
//! surface triangles; a closed surface must be closed and consistently oriented outward (its
//! particles are then pushed out of it along the outward normal), an open one (cloth) is
//! two-sided. The checks run in [`PbdBuilder::build`]: ranges inside the model and disjoint,
//! triangles inside their body's range with three distinct corners, a closed surface closed,
//! consistently oriented and enclosing a positive volume (`build/closed.rs`).

use super::builder::PbdBuilder;
use super::closed::closed_outward;
use super::error::BuildError;
use crate::collide::BodyContact;
use crate::model::ContactBody;
use anim_core::glam::DVec3;
use std::ops::Range;

impl PbdBuilder {
    /// Makes the particles `particles` a contact body with surface `triangles` (model particle
    /// indices inside the range); `closed` for a closed surface oriented outward (a soft body's
    /// boundary, a balloon), else the surface is two-sided (cloth). Returns its index.
    pub fn contact_body(&mut self, particles: Range<usize>, triangles: &[[usize; 3]], closed: bool) -> usize {
        self.contact_bodies.push(ContactBody {
            particles: (particles.start, particles.end),
            triangles: triangles.to_vec(),
            closed,
        });
        self.contact_bodies.len() - 1
    }

    /// Sets the thickness and friction of the contacts between contact bodies (default
    /// [`BodyContact::default`]).
    pub fn body_contact(&mut self, params: BodyContact) -> &mut Self {
        self.body_contact = params;
        self
    }

    /// Checks the contact bodies and their parameters against `n` particles.
    pub(super) fn check_contact_bodies(&self, n: usize) -> Result<(), BuildError> {
        if self.contact_bodies.is_empty() {
            return Ok(());
        }
        self.body_contact.validate().map_err(|reason| BuildError::BadBodyContact { reason })?;
        let mut ranges: Vec<(usize, usize, usize)> = Vec::new();
        for (b, body) in self.contact_bodies.iter().enumerate() {
            let fail = |reason: String| BuildError::BadContactBody { body: b, reason };
            let (start, end) = body.particles;
            if !(start < end && end <= n) {
                return Err(fail(format!(
                    "particles {start}..{end} are not a non-empty range of the model's {n} particles"
                )));
            }
            if let Some(&(other, s, e)) = ranges.iter().find(|&&(_, s, e)| start < e && s < end) {
                return Err(fail(format!(
                    "particles {start}..{end} overlap contact body {other}'s {s}..{e}"
                )));
            }
            ranges.push((b, start, end));
            for (t, tri) in body.triangles.iter().enumerate() {
                if let Some(&i) = tri.iter().find(|&&i| !(start..end).contains(&i)) {
                    return Err(fail(format!("triangle {t} {tri:?}: particle {i} is not in {start}..{end}")));
                }
                if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                    return Err(fail(format!("triangle {t} {tri:?} repeats a particle")));
                }
            }
            if body.closed {
                closed_outward(&body.triangles, |i| DVec3::from_array(self.positions[i]))
                    .map_err(|e| fail(e.to_string()))?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::{BodyContact, BuildError, PbdBuilder};

    /// Two unit tetrahedra's particles, 0..4 and 4..8, each at the origin and its three unit
    /// vectors (the second moved 2 m along x), so that [`TET`] faces outward.
    fn builder() -> PbdBuilder {
        let mut b = PbdBuilder::new();
        let corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for k in 0..8 {
            let [x, y, z] = corners[k % 4];
            b.particle([x + 2.0 * (k / 4) as f64, y, z], 1.0);
        }
        b
    }

    const TET: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];

    #[test]
    fn bad_contact_bodies_are_refused_naming_the_body() {
        let reason = |b: &PbdBuilder| match b.build() {
            Err(BuildError::BadContactBody { body, reason }) => format!("{body}: {reason}"),
            other => panic!("{other:?}"),
        };
        let mut b = builder();
        b.contact_body(0..4, &TET, true);
        b.contact_body(3..8, &[[4, 5, 6]], false);
        assert_eq!(reason(&b), "1: particles 3..8 overlap contact body 0's 0..4");
        let mut b = builder();
        b.contact_body(0..4, &TET, true);
        b.contact_body(4..9, &[[4, 5, 6]], false);
        assert_eq!(reason(&b), "1: particles 4..9 are not a non-empty range of the model's 8 particles");
        let mut b = builder();
        b.contact_body(4..8, &[[4, 5, 2]], false);
        assert_eq!(reason(&b), "0: triangle 0 [4, 5, 2]: particle 2 is not in 4..8");
        let mut b = builder();
        b.contact_body(0..4, &TET[..3], true);
        assert_eq!(reason(&b), "0: edge (2, 1) of triangle 0 has no opposite: the surface is not closed");
        let mut b = builder();
        b.contact_body(0..4, &TET, true);
        b.body_contact(BodyContact { thickness: 0.0, ..BodyContact::default() });
        assert!(matches!(b.build(), Err(BuildError::BadBodyContact { .. })));
        let mut b = builder();
        b.contact_body(0..4, &TET, true);
        b.contact_body(4..8, &[[4, 5, 6]], false);
        let model = b.build().expect("builds");
        assert_eq!(model.contact_bodies().len(), 2);
        assert_eq!(model.body_contact(), BodyContact::default());
    }

    /// A closed surface whose triangles face inward (each of [`TET`]'s reversed) would pull
    /// the other bodies' particles into it: refused, as is a flat closed surface.
    #[test]
    fn a_closed_contact_body_facing_inward_or_flat_is_refused() {
        let reason = |b: &PbdBuilder| match b.build() {
            Err(BuildError::BadContactBody { body, reason }) => format!("{body}: {reason}"),
            other => panic!("{other:?}"),
        };
        let inward = TET.map(|[a, b, c]| [a, c, b]);
        let mut b = builder();
        b.contact_body(4..8, &[[4, 5, 6]], false);
        b.contact_body(0..4, &inward, true);
        assert_eq!(
            reason(&b),
            "1: the enclosed volume -1.6666666666666666e-1 is not positive: the triangles face inward"
        );
        let mut b = PbdBuilder::new();
        for p in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]] {
            b.particle(p, 1.0);
        }
        b.contact_body(0..4, &TET, true);
        assert_eq!(reason(&b), "0: the enclosed volume 0e0 is not positive: the triangles face inward");
    }
}
