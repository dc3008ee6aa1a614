//! What a preview colours by (`--color-by`): a named field of the scene's frames through a
//! colour map, or the bodies' own colours.
//!
//! A field of one component is shown as it is, a vector by its length, a tensor (strain) by
//! its Frobenius norm; `speed` is the length of `velocity`. `material` is drawn as categories
//! (one colour per id, [`colormap::CATEGORIES`]); every other field through viridis over the
//! smallest to the largest value of the frames the preview draws (the range is fixed for the
//! run and printed with it). A grid scene colours its cells by its density (the default) or
//! its speed.

use anim_core::scene::{Context, Field, Frame};
use anim_io::preview::colormap;

/// The field name of a material id per point.
pub const MATERIAL: &str = "material";

/// The derived field `speed`: the length of `velocity`.
pub const SPEED: &str = "speed";

/// What a preview colours its points (or a grid its cells) by.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Paint {
    /// The bodies' own colours: meshes blue, particles orange, lines grey.
    #[default]
    Plain,
    /// A field of the frames (or `speed`).
    Field(String),
}

impl Paint {
    /// The paint of a run: `asked` (`--color-by`, `none` for [`Paint::Plain`]) checked against
    /// the fields of the scene's `frame`, or the default: a grid's shown field, `material` where
    /// the frame has more than one material, otherwise the bodies' own colours.
    ///
    /// # Errors
    /// A name the scene's frames do not have, with the names they do have; any name but `none`
    /// on a scene drawn as a point in the plane (an oscillator, an orbit).
    pub fn choose(asked: Option<&str>, context: &Context, frame: &Frame) -> Result<Self, String> {
        let has_velocity = frame.field("velocity").is_some();
        let choices: Vec<&str> = if let Some(image) = &context.image {
            std::iter::once(image.shown).chain(has_velocity.then_some(SPEED)).collect()
        } else if context.point_dim < 3 {
            vec!["none"]
        } else {
            has_velocity
                .then_some(SPEED)
                .into_iter()
                .chain(frame.fields.iter().map(|f| f.name))
                .chain(std::iter::once("none"))
                .collect()
        };
        match asked {
            None => Ok(if let Some(image) = &context.image {
                Paint::Field(image.shown.to_string())
            } else if frame.field(MATERIAL).is_some_and(|f| f.values.iter().any(|&m| m != f.values[0])) {
                Paint::Field(MATERIAL.to_string())
            } else {
                Paint::Plain
            }),
            Some(name) if choices.contains(&name) => {
                Ok(if name == "none" { Paint::Plain } else { Paint::Field(name.to_string()) })
            }
            Some(name) => Err(format!(
                "--color-by {name}: the scene's frames have no field `{name}`; it can be coloured by {}",
                choices.join(", ")
            )),
        }
    }

    /// Whether the colours are categories (material ids) rather than a colour scale.
    #[must_use]
    pub fn is_categorical(&self) -> bool {
        matches!(self, Paint::Field(name) if name == MATERIAL)
    }

    /// The painted field's value per point of a particle frame (`fields` and the snapshot's
    /// velocity `v`), appended to `out`; nothing for [`Paint::Plain`].
    pub fn values(&self, fields: &[Field], v: &[f64], out: &mut Vec<f64>) {
        let Paint::Field(name) = self else { return };
        if name == SPEED {
            out.extend(v.chunks_exact(3).map(|c| (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()));
        } else if let Some(f) = fields.iter().find(|f| f.name == name) {
            let k = f.components.max(1);
            out.extend(
                f.values
                    .chunks_exact(k)
                    .map(|c| if k == 1 { c[0] } else { c.iter().map(|x| x * x).sum::<f64>().sqrt() }),
            );
        }
    }

    /// What a caption says of the colours: `"material (one colour per id)"`, `"speed, 0 to 3.1
    /// (viridis)"`; `None` for the bodies' own colours.
    #[must_use]
    pub fn caption(&self, range: (f64, f64)) -> Option<String> {
        match self {
            Paint::Plain => None,
            Paint::Field(name) if self.is_categorical() => Some(format!("{name} (one colour per id)")),
            Paint::Field(name) => Some(format!("{name}, {} to {} (viridis)", short(range.0), short(range.1))),
        }
    }

    /// The colours of `values` over `range`: categories for material ids, viridis otherwise;
    /// magenta for a value that is not finite (or not an id).
    pub fn colors(&self, values: &[f64], range: (f64, f64), out: &mut Vec<[u8; 3]>) {
        const BAD: [u8; 3] = [255, 0, 255];
        out.clear();
        if self.is_categorical() {
            out.extend(values.iter().map(|&m| colormap::category(m, BAD)));
        } else {
            let span = if range.1 > range.0 { range.1 - range.0 } else { 1.0 };
            out.extend(
                values
                    .iter()
                    .map(|&x| if x.is_finite() { colormap::viridis((x - range.0) / span) } else { BAD }),
            );
        }
    }
}

/// A number in three significant digits: `0`, `4.18`, `0.0123`, `1.23e-5`, `2.50e6`.
fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = 2 - x.abs().log10().floor() as i32;
    if (-3..=4).contains(&(2 - digits)) {
        let text = format!("{:.*}", digits.max(0) as usize, x);
        if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
    } else {
        format!("{x:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim_core::scene::ImageGrid;

    fn frame(fields: &[(&'static str, usize, Vec<f64>)]) -> Frame {
        let mut frame = Frame::default();
        for (name, k, values) in fields {
            frame.field_mut(name, *k).extend_from_slice(values);
        }
        frame
    }

    fn particles() -> Context {
        let mut context = Context::default();
        context.point_dim = 3;
        context
    }

    /// Several materials colour by material unless asked otherwise; one material, by nothing;
    /// an unknown name is refused with the names the frames have.
    #[test]
    fn the_default_and_the_choices_come_from_the_frame() {
        let two = frame(&[("velocity", 3, vec![0.0; 6]), (MATERIAL, 1, vec![0.0, 2.0])]);
        let one = frame(&[("velocity", 3, vec![0.0; 6]), (MATERIAL, 1, vec![1.0, 1.0])]);
        let c = particles();
        assert_eq!(Paint::choose(None, &c, &two), Ok(Paint::Field(MATERIAL.into())));
        assert_eq!(Paint::choose(None, &c, &one), Ok(Paint::Plain));
        assert_eq!(Paint::choose(Some("speed"), &c, &two), Ok(Paint::Field(SPEED.into())));
        assert_eq!(Paint::choose(Some("none"), &c, &two), Ok(Paint::Plain));
        let e = Paint::choose(Some("pressure"), &c, &two).unwrap_err();
        assert_eq!(
            e,
            "--color-by pressure: the scene's frames have no field `pressure`; it can be coloured by \
             speed, velocity, material, none"
        );
        let mut planar = Context::default();
        planar.point_dim = 2;
        assert!(Paint::choose(Some("speed"), &planar, &two).is_err());
        let mut grid = Context::default();
        grid.image = Some(ImageGrid {
            dims: [2, 2, 1],
            dim: 2,
            origin: [0.0; 3],
            spacing: 1.0,
            shown: "density",
            range: (0.0, 1.0),
        });
        let cells = frame(&[("density", 1, vec![0.0; 4]), ("velocity", 3, vec![0.0; 12])]);
        assert_eq!(Paint::choose(None, &grid, &cells), Ok(Paint::Field("density".into())));
        assert_eq!(Paint::choose(Some("speed"), &grid, &cells), Ok(Paint::Field(SPEED.into())));
        assert!(Paint::choose(Some("none"), &grid, &cells).is_err());
    }

    /// Speed is the velocity's length, a vector field its length, a 3 x 3 tensor its Frobenius
    /// norm; ids take the categorical palette, values the viridis ends of the range.
    #[test]
    fn values_and_colours() {
        let fields = [
            Field { name: "strain", components: 9, values: [[2.0; 9], [0.0; 9]].concat() },
            Field { name: MATERIAL, components: 1, values: vec![0.0, 3.0] },
        ];
        let v = [3.0, 4.0, 0.0, 0.0, 0.0, -1.0];
        let mut out = Vec::new();
        Paint::Field(SPEED.into()).values(&fields, &v, &mut out);
        assert_eq!(out, [5.0, 1.0]);
        out.clear();
        Paint::Field("strain".into()).values(&fields, &v, &mut out);
        assert_eq!(out, [6.0, 0.0]);
        let mut colors = Vec::new();
        Paint::Field(MATERIAL.into()).colors(&[0.0, 3.0, 0.5], (0.0, 3.0), &mut colors);
        assert_eq!(colors, [colormap::CATEGORIES[0], colormap::CATEGORIES[3], [255, 0, 255]]);
        Paint::Field(SPEED.into()).colors(&[1.0, 5.0, f64::NAN], (1.0, 5.0), &mut colors);
        assert_eq!(
            Paint::Field(SPEED.into()).caption((0.0, 4.1771)).as_deref(),
            Some("speed, 0 to 4.18 (viridis)")
        );
        assert_eq!(
            Paint::Field(MATERIAL.into()).caption((0.0, 2.0)).as_deref(),
            Some("material (one colour per id)")
        );
        let shorts: Vec<String> = [0.0123456, 1.23456e-5, 2.5e6, 123456.0, -0.5].map(short).to_vec();
        assert_eq!(shorts, ["0.0123", "1.23e-5", "2.50e6", "1.23e5", "-0.5"]);
        assert_eq!(colors, [colormap::viridis(0.0), colormap::viridis(1.0), [255, 0, 255]]);
    }
}
