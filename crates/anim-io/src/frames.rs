//! Numbered frame sequences (`frame_00000.vtu`, `frame_00001.vtu`, ...) and the writer that
//! turns one [`UnstructuredGrid`] (or, for grids, one [`ImageData`]) per frame into files of a
//! chosen format, plus the `.pvd` that lets ParaView play a `.vtu` or `.vti` sequence against
//! simulation time. Blender's and Houdini's
//! importers recognise the numbered names of `.ply`/`.obj` sequences.
//!
//! Frames are **y up** (gravity along `-y`), the frame of every scene's view, and each frame
//! file says so where its format keeps metadata ([`UP`]): a `FieldData` array `up` holding the
//! direction `(0, 1, 0)` in `.vtu` and `.vti` (ParaView lists it in its Information panel), a
//! `comment up y` header line in `.ply` and a `# up y` line in `.obj` (comments every importer
//! skips).

use crate::IoError;
use crate::data::{DataArray, Values};
use crate::ply::Ply;
use crate::vtk::{CellKind, ImageData, UnstructuredGrid, VtkEncoding, write_pvd};
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// The axis that points up in every frame file (and run summary) the workspace writes: `"y"`.
pub const UP: &str = "y";

/// The direction that points up, as the one tuple of the `up` field data of `.vtu`/`.vti`
/// frames.
const UP_DIRECTION: [[f64; 3]; 1] = [[0.0, 1.0, 0.0]];

/// The line that states the up axis in a `.ply` header (after `comment`) and an `.obj` file
/// (after `#`).
fn up_comment() -> String {
    format!("up {UP}")
}

/// Numbered file names in one folder, and the time of each frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameSequence {
    dir: PathBuf,
    stem: String,
    extension: String,
    frames: Vec<(f64, PathBuf)>,
}

impl FrameSequence {
    /// A sequence `dir/{stem}_{index:05}.{extension}`; creates `dir` if needed.
    pub fn new(dir: impl Into<PathBuf>, stem: &str, extension: &str) -> Result<Self, IoError> {
        let dir = dir.into();
        std::fs::create_dir_all(&dir).map_err(|e| IoError::io(&dir, e))?;
        Ok(FrameSequence { dir, stem: stem.into(), extension: extension.into(), frames: Vec::new() })
    }

    /// The file name of frame `index`, e.g. `frame_00042.vtu` (more digits past 99999).
    pub fn file_name(&self, index: usize) -> String {
        format!("{}_{index:05}.{}", self.stem, self.extension)
    }

    /// Continues a sequence whose first frames, at `times`, were written earlier (a run resumed
    /// from a checkpoint): the next frame is numbered `times.len()` and the `.pvd` lists all.
    #[must_use]
    pub fn continuing(mut self, times: &[f64]) -> Self {
        self.frames = times.iter().enumerate().map(|(k, &t)| (t, PathBuf::from(self.file_name(k)))).collect();
        self
    }

    /// Records a frame at `time` and returns the path to write it to.
    pub fn next_path(&mut self, time: f64) -> PathBuf {
        let name = PathBuf::from(self.file_name(self.frames.len()));
        let path = self.dir.join(&name);
        self.frames.push((time, name));
        path
    }

    /// The frames so far: time and file name (relative to [`dir`](Self::dir)).
    pub fn frames(&self) -> &[(f64, PathBuf)] {
        &self.frames
    }

    /// The folder the frames go to.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes `dir/{name}` as a `.pvd` collection of the frames so far whose files are in the
    /// folder, and returns its path. A run resumed into another folder thus lists the frames it
    /// wrote there, not the earlier ones left in the first folder.
    pub fn write_pvd(&self, name: &str) -> Result<PathBuf, IoError> {
        let path = self.dir.join(name);
        let present: Vec<(f64, PathBuf)> =
            self.frames.iter().filter(|(_, file)| self.dir.join(file).is_file()).cloned().collect();
        write_pvd(&path, &present)?;
        Ok(path)
    }
}

/// A frame file format.
///
/// | format | geometry | fields |
/// | --- | --- | --- |
/// | `Vtu` | points; vertex, line, triangle, tetrahedron cells | all point and cell fields |
/// | `Ply` | points, triangles (vertex cells add nothing and are not needed) | point fields (a 3-vector `v` as properties `v_x v_y v_z`); cell fields are not written |
/// | `Obj` | points, triangles, lines | none: fields are not written |
/// | `Vti` | a regular grid ([`ImageData`], through [`FrameWriter::write_image`]) | all point and cell fields |
///
/// A cell kind the format cannot hold (tetrahedra in PLY or OBJ, lines in PLY) is an error, not a
/// silent omission: pass [`TetMesh::boundary_triangles`](crate::TetMesh::boundary_triangles)
/// to show a solid's surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameFormat {
    /// VTK XML unstructured grid (ParaView), with a `.pvd` for the sequence.
    Vtu,
    /// Binary PLY (Blender, Houdini, MeshLab).
    Ply,
    /// Wavefront OBJ (any DCC tool).
    Obj,
    /// VTK XML image data (ParaView): regular grids such as fluid fields, with a `.pvd`.
    Vti,
}

impl FrameFormat {
    /// The file extension without a dot.
    pub fn extension(self) -> &'static str {
        match self {
            FrameFormat::Vtu => "vtu",
            FrameFormat::Ply => "ply",
            FrameFormat::Obj => "obj",
            FrameFormat::Vti => "vti",
        }
    }
}

impl FromStr for FrameFormat {
    type Err = String;

    /// Parses `vtu`, `ply`, `obj` or `vti` (any case).
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "vtu" | "vtk" => Ok(FrameFormat::Vtu),
            "ply" => Ok(FrameFormat::Ply),
            "obj" => Ok(FrameFormat::Obj),
            "vti" => Ok(FrameFormat::Vti),
            _ => Err(format!("unknown frame format `{s}` (expected vtu, ply, obj or vti)")),
        }
    }
}

/// Writes one file per frame into a folder; for `.vtu` and `.vti`, [`finish`](Self::finish)
/// adds `frames.pvd`. Every frame states that it is y up ([`UP`], the module's documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameWriter {
    sequence: FrameSequence,
    format: FrameFormat,
    encoding: VtkEncoding,
}

impl FrameWriter {
    /// Frames `dir/frame_NNNNN.{ext}`; creates `dir` if needed.
    pub fn new(dir: impl Into<PathBuf>, format: FrameFormat) -> Result<Self, IoError> {
        let sequence = FrameSequence::new(dir, "frame", format.extension())?;
        Ok(FrameWriter { sequence, format, encoding: VtkEncoding::default() })
    }

    /// Continues a sequence in `dir` whose first frames, at `times`, were written earlier (see
    /// [`FrameSequence::continuing`]).
    pub fn continuing(dir: impl Into<PathBuf>, format: FrameFormat, times: &[f64]) -> Result<Self, IoError> {
        let sequence = FrameSequence::new(dir, "frame", format.extension())?.continuing(times);
        Ok(FrameWriter { sequence, format, encoding: VtkEncoding::default() })
    }

    /// Sets the VTK array encoding (default base64).
    pub fn with_encoding(mut self, encoding: VtkEncoding) -> Self {
        self.encoding = encoding;
        self
    }

    /// The format of the frames.
    pub fn format(&self) -> FrameFormat {
        self.format
    }

    /// The sequence written so far.
    pub fn sequence(&self) -> &FrameSequence {
        &self.sequence
    }

    /// Writes the next frame at simulation time `time` and returns its path.
    pub fn write(&mut self, time: f64, frame: &UnstructuredGrid<'_>) -> Result<PathBuf, IoError> {
        let name = self.sequence.file_name(self.sequence.frames().len());
        let what = self.sequence.dir().join(&name);
        frame.check().map_err(|e| IoError::data(what.display(), e))?;
        match self.format {
            FrameFormat::Vtu => {
                frame
                    .clone()
                    .field_data(DataArray::vectors("up", &UP_DIRECTION))
                    .write(&what, self.encoding)?;
            }
            FrameFormat::Vti => {
                return Err(IoError::data(
                    what.display(),
                    "vti frames hold grids: write them with FrameWriter::write_image",
                ));
            }
            FrameFormat::Ply => ply_of(frame)
                .map_err(|e| IoError::data(what.display(), e))?
                .comment(&up_comment())
                .write(&what)?,
            FrameFormat::Obj => {
                let (tris, lines) = surface(frame, true).map_err(|e| IoError::data(what.display(), e))?;
                let up = [up_comment()];
                let text = match frame.points {
                    Values::F32(p) => crate::obj::obj_text(p.as_chunks::<3>().0, &tris, &lines, &up),
                    Values::F64(p) => crate::obj::obj_text(p.as_chunks::<3>().0, &tris, &lines, &up),
                    Values::I32(_) => Err("integer point coordinates".to_string()),
                }
                .map_err(|e| IoError::data(what.display(), e))?;
                crate::vtk::write_file(&what, &text)?;
            }
        }
        Ok(self.sequence.next_path(time))
    }

    /// Writes the next frame of a [`FrameFormat::Vti`] sequence, a regular grid, at simulation
    /// time `time` and returns its path. A grid in another format's sequence, or a grid that
    /// fails [`ImageData::check`], is an [`IoError::InvalidData`] naming the file and the cause;
    /// nothing is recorded then.
    pub fn write_image(&mut self, time: f64, frame: &ImageData<'_>) -> Result<PathBuf, IoError> {
        let name = self.sequence.file_name(self.sequence.frames().len());
        let what = self.sequence.dir().join(&name);
        if self.format != FrameFormat::Vti {
            return Err(IoError::data(
                what.display(),
                format!("a grid frame in a {} sequence: grids are written as vti", self.format.extension()),
            ));
        }
        frame.clone().field_data(DataArray::vectors("up", &UP_DIRECTION)).write(&what, self.encoding)?;
        Ok(self.sequence.next_path(time))
    }

    /// Finishes the sequence: for `.vtu` and `.vti` writes `frames.pvd` and returns its path.
    pub fn finish(&self) -> Result<Option<PathBuf>, IoError> {
        match self.format {
            FrameFormat::Vtu | FrameFormat::Vti => self.sequence.write_pvd("frames.pvd").map(Some),
            _ => Ok(None),
        }
    }
}

/// Triangles and lines of a grid; tetrahedra (and lines unless `lines_ok`) are refused.
/// Triangles and line segments.
type Surface = (Vec<[usize; 3]>, Vec<[usize; 2]>);

fn surface(g: &UnstructuredGrid<'_>, lines_ok: bool) -> Result<Surface, String> {
    let mut tris = Vec::new();
    let mut lines = Vec::new();
    for block in &g.cells {
        match block.kind {
            CellKind::Vertex => {}
            CellKind::Triangle => tris.extend_from_slice(block.connectivity.as_chunks::<3>().0),
            CellKind::Line if lines_ok => lines.extend_from_slice(block.connectivity.as_chunks::<2>().0),
            CellKind::Line => {
                return Err("PLY frames hold points and triangles, not lines: use vtu or obj".into());
            }
            CellKind::Tetra => {
                return Err("tetrahedra need vtu; for PLY/OBJ pass the boundary triangles".into());
            }
        }
    }
    Ok((tris, lines))
}

fn ply_of<'a>(g: &UnstructuredGrid<'a>) -> Result<Ply<'a>, String> {
    let (tris, _) = surface(g, false)?;
    let mut ply = Ply::from_values(g.points).owned_triangles(tris);
    for f in &g.point_data {
        let names = match f.components {
            1 => vec![f.name.clone()],
            3 => ["x", "y", "z"].iter().map(|a| format!("{}_{a}", f.name)).collect(),
            c => (0..c).map(|k| format!("{}_{k}", f.name)).collect(),
        };
        let names = names.into_iter().map(|n| n.replace(char::is_whitespace, "_")).collect();
        ply =
            ply.field(names, DataArray { name: f.name.clone(), components: f.components, values: f.values });
    }
    Ok(ply)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("anim-io-frames-{}-{name}", std::process::id()))
    }

    #[test]
    fn names_pvd_and_format_limits() {
        let dir = tmp("seq");
        let pts = [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let tets = [[0, 1, 2, 3]];
        let tris = [[0, 1, 2]];
        let lines = [[0, 3]];
        let mut w = FrameWriter::new(&dir, FrameFormat::Obj).unwrap();
        let p = w.write(0.5, &UnstructuredGrid::new(&pts).triangles(&tris).lines(&lines)).unwrap();
        assert_eq!(p, dir.join("frame_00000.obj"));
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.contains("f 1 2 3\n") && text.contains("l 1 4\n"), "{text}");
        let e = w.write(1.0, &UnstructuredGrid::new(&pts).tetrahedra(&tets)).unwrap_err();
        assert!(e.to_string().contains("tetrahedra need vtu"), "{e}");
        assert_eq!(w.sequence().frames().len(), 1, "a failed frame is not recorded");
        assert_eq!(w.finish().unwrap(), None);

        let mut w = FrameWriter::new(&dir, FrameFormat::Ply).unwrap();
        let e = w.write(0.0, &UnstructuredGrid::new(&pts).lines(&lines)).unwrap_err();
        assert!(e.to_string().contains("not lines"), "{e}");

        let mut w = FrameWriter::new(&dir, FrameFormat::Vtu).unwrap();
        for k in 0..2 {
            w.write(k as f64 * 0.25, &UnstructuredGrid::new(&pts).tetrahedra(&tets)).unwrap();
        }
        let pvd = w.finish().unwrap().unwrap();
        let text = std::fs::read_to_string(pvd).unwrap();
        assert!(text.contains("timestep=\"0e0\" group=\"\" part=\"0\" file=\"frame_00000.vtu\""), "{text}");
        assert!(
            text.contains("timestep=\"2.5e-1\" group=\"\" part=\"0\" file=\"frame_00001.vtu\""),
            "{text}"
        );
        // A resumed run continues the numbering and its .pvd lists the earlier frames too.
        let mut w = FrameWriter::continuing(&dir, FrameFormat::Vtu, &[0.0, 0.25]).unwrap();
        let p = w.write(0.5, &UnstructuredGrid::new(&pts).tetrahedra(&tets)).unwrap();
        assert_eq!(p, dir.join("frame_00002.vtu"));
        let text = std::fs::read_to_string(w.finish().unwrap().unwrap()).unwrap();
        assert!(
            text.contains("file=\"frame_00000.vtu\"") && text.contains("file=\"frame_00002.vtu\""),
            "{text}"
        );
        // Resumed into another folder: its .pvd lists only the frame written there.
        let other = tmp("vtu-elsewhere");
        let mut w = FrameWriter::continuing(&other, FrameFormat::Vtu, &[0.0, 0.25]).unwrap();
        w.write(0.5, &UnstructuredGrid::new(&pts).tetrahedra(&tets)).unwrap();
        let text = std::fs::read_to_string(w.finish().unwrap().unwrap()).unwrap();
        assert!(
            text.contains("file=\"frame_00002.vtu\"")
                && !text.contains("frame_00000")
                && !text.contains("frame_00001"),
            "{text}"
        );
        std::fs::remove_dir_all(other).unwrap();
        assert_eq!("PLY".parse::<FrameFormat>(), Ok(FrameFormat::Ply));
        assert_eq!("vti".parse::<FrameFormat>(), Ok(FrameFormat::Vti));
        assert!("stl".parse::<FrameFormat>().is_err());
        std::fs::remove_dir_all(dir).unwrap();
    }

    /// Every frame file says it is y up, read back as a reader sees it: the `up` field data of
    /// a `.vtu` or `.vti` (an XML parser finds the one tuple `(0, 1, 0)`), the header comment of
    /// a `.ply` (before `end_header`), the comment line of an `.obj`.
    #[test]
    fn every_frame_file_states_that_y_is_up() {
        let dir = tmp("up");
        let pts = [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let tris = [[0, 1, 2]];
        let grid = UnstructuredGrid::new(&pts).triangles(&tris);
        let up_of_xml = |path: &Path| {
            let text = std::fs::read_to_string(path).unwrap();
            let doc = roxmltree::Document::parse(&text).unwrap();
            let array = doc
                .descendants()
                .find(|n| n.has_tag_name("DataArray") && n.attribute("Name") == Some("up"))
                .unwrap_or_else(|| panic!("no up array in {text:.400}"));
            assert_eq!(array.parent_element().map(|p| p.tag_name().name()), Some("FieldData"));
            assert_eq!(
                (array.attribute("NumberOfTuples"), array.attribute("format")),
                (Some("1"), Some("ascii"))
            );
            array
                .text()
                .unwrap_or("")
                .split_whitespace()
                .map(|t| t.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        };
        let mut vtu = FrameWriter::new(dir.join("vtu"), FrameFormat::Vtu).unwrap();
        assert_eq!(up_of_xml(&vtu.write(0.0, &grid).unwrap()), [0.0, 1.0, 0.0]);
        let density = [1.0f64; 4];
        let image = ImageData::from_cells_2d([2, 2], [0.0; 2], [0.5; 2])
            .cell_field(DataArray::scalars("density", &density));
        let mut vti = FrameWriter::new(dir.join("vti"), FrameFormat::Vti).unwrap();
        assert_eq!(up_of_xml(&vti.write_image(0.0, &image).unwrap()), [0.0, 1.0, 0.0]);
        let mut ply = FrameWriter::new(dir.join("ply"), FrameFormat::Ply).unwrap();
        let bytes = std::fs::read(ply.write(0.0, &grid).unwrap()).unwrap();
        let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap();
        let header = String::from_utf8(bytes[..end].to_vec()).unwrap();
        assert!(header.lines().any(|l| l == "comment up y"), "{header}");
        let mut obj = FrameWriter::new(dir.join("obj"), FrameFormat::Obj).unwrap();
        let text = std::fs::read_to_string(obj.write(0.0, &grid).unwrap()).unwrap();
        assert!(text.lines().take_while(|l| l.starts_with('#')).any(|l| l == "# up y"), "{text}");
        assert_eq!(UP, "y");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn grid_frames_are_vti_with_a_pvd() {
        let dir = tmp("vti");
        let density = [0.0f64, 1.0, 2.0, 3.0, 4.0, 5.0];
        let img = ImageData::from_cells_2d([3, 2], [0.0, 0.0], [0.5, 0.5])
            .cell_field(DataArray::scalars("density", &density));
        let mut w = FrameWriter::new(&dir, FrameFormat::Vti).unwrap();
        for k in 0..2 {
            let p = w.write_image(0.1 * k as f64, &img).unwrap();
            assert_eq!(p, dir.join(format!("frame_0000{k}.vti")));
            assert!(std::fs::read_to_string(&p).unwrap().contains("<ImageData WholeExtent=\"0 3 0 2 0 0\""));
        }
        let pts = [[0.0f64; 3]];
        let e = w.write(0.2, &UnstructuredGrid::new(&pts)).unwrap_err();
        assert!(e.to_string().contains("write_image"), "{e}");
        let short = [1.0f64; 5];
        let bad = ImageData::from_cells_2d([3, 2], [0.0, 0.0], [0.5, 0.5])
            .cell_field(DataArray::scalars("density", &short));
        let e = w.write_image(0.2, &bad).unwrap_err();
        assert!(e.to_string().contains("field `density` has 5 tuples"), "{e}");
        assert_eq!(w.sequence().frames().len(), 2, "a failed frame is not recorded");
        let text = std::fs::read_to_string(w.finish().unwrap().unwrap()).unwrap();
        assert!(text.contains("file=\"frame_00001.vti\""), "{text}");
        let mut u = FrameWriter::new(&dir, FrameFormat::Vtu).unwrap();
        let e = u.write_image(0.0, &img).unwrap_err();
        assert!(e.to_string().contains("grids are written as vti"), "{e}");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
