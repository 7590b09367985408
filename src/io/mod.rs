//! Mesh files in and out: STL (binary and ASCII), OBJ, OFF, PLY (ASCII and binary) and 3MF.
//!
//! Every reader returns the same thing — an indexed [`Mesh`] with bit-identical vertices welded,
//! polygons cut into triangles — and treats its input as hostile: counts in headers only bound
//! loops, never size an allocation beyond what the bytes present can hold; a bad byte gives an
//! error naming where, never a panic. Writers go through [`crate::io::atomic`]'s atomic writes.
//!
//! The format is chosen by the file's extension (`.stl .obj .off .ply .3mf`); files without a
//! known extension are recognised by their first bytes.

pub mod atomic;
pub mod canvas;
pub mod npy;
pub mod obj;
pub mod off;
pub mod ply;
pub mod png;
pub mod points;
pub mod sink;
pub mod stl;
pub mod threemf;
pub mod weld;

use crate::error::{Error, Result};
use crate::geom::Mesh;
use std::path::Path;

pub use stl::StlFormat;

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// STL, binary or ASCII.
    Stl,
    /// Wavefront OBJ.
    Obj,
    /// Object File Format (OFF).
    Off,
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// 3MF (3D Manufacturing Format), a zip package.
    #[serde(rename = "3mf")]
    ThreeMf,
}

impl Format {
    /// By file extension, case-insensitive.
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "stl" => Format::Stl,
            "obj" => Format::Obj,
            "off" => Format::Off,
            "ply" => Format::Ply,
            "3mf" => Format::ThreeMf,
            _ => return None,
        })
    }

    /// By content, for files without a known extension.
    pub fn sniff(data: &[u8]) -> Format {
        let start = data
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .unwrap_or(0);
        let head = &data[start..data.len().min(start + 16)];
        let starts = |s: &[u8]| head.len() >= s.len() && head[..s.len()].eq_ignore_ascii_case(s);
        if data.starts_with(b"PK\x03\x04") {
            Format::ThreeMf
        } else if starts(b"ply") {
            Format::Ply
        } else if off::has_off_keyword(head) {
            Format::Off
        } else if starts(b"v ") || starts(b"#") || starts(b"o ") || starts(b"mtllib") {
            Format::Obj
        } else {
            Format::Stl
        }
    }

    /// The format's usual name (`STL`, `3MF`, …).
    pub fn name(self) -> &'static str {
        match self {
            Format::Stl => "STL",
            Format::Obj => "OBJ",
            Format::Off => "OFF",
            Format::Ply => "PLY",
            Format::ThreeMf => "3MF",
        }
    }
}

/// What a reader produced.
#[derive(Debug, Clone, Default)]
pub struct Parsed {
    /// The triangles read (polygons split, vertices welded exactly).
    pub mesh: Mesh,
    /// Per-facet normals as stored in the file (STL only; zero or NaN when the file had none).
    pub normals: Option<Vec<[f32; 3]>>,
    /// Faces with fewer than three corners, skipped.
    pub short_faces: u64,
    /// Faces with more than three corners, cut into triangles.
    pub polygons_split: u64,
    /// Beam lattices (3MF Beam Lattice extension), not meshed: the part is `mesh` united with
    /// their solids.
    pub lattices: Vec<threemf::BeamLattice>,
}

/// How to read.
#[derive(Debug, Clone, Copy, Default)]
pub struct ReadOptions {
    /// Also merge vertices closer than this, mm (0 = exact welding only).
    pub weld_tolerance: f64,
    /// Voxel for meshing beam lattices, mm (automatic when `None`; see
    /// [`crate::mesh::part::read`]).
    pub beam_voxel: Option<f64>,
}

/// Beam lattices read as a solid: what was meshed, on what voxels.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct BeamsMeshed {
    /// Lattices (placed objects holding one).
    pub lattices: u64,
    /// Beams meshed.
    pub beams: u64,
    /// Balls meshed.
    pub balls: u64,
    /// Beams shorter than their lattice's `minlength`, ignored as the extension says.
    pub short_beams_ignored: u64,
    /// The thinnest beam or ball radius, mm.
    #[serde(rename = "thinnest_radius_mm")]
    pub thinnest_radius: f64,
    /// The voxel meshed on, mm.
    #[serde(rename = "voxel_mm")]
    pub voxel: f64,
    /// Triangles of the lattices' solid.
    pub triangles: u64,
}

/// A file read into a mesh, with what reading did to it.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The format read.
    pub format: Format,
    /// The mesh, welded.
    pub mesh: Mesh,
    /// Per-facet normals as stored in the file (STL only).
    pub normals: Option<Vec<[f32; 3]>>,
    /// Faces with fewer than three corners, skipped.
    pub short_faces: u64,
    /// Faces with more than three corners, cut into triangles.
    pub polygons_split: u64,
    /// Vertices merged by `weld_tolerance` (beyond exact welding).
    pub tolerance_welded: u64,
    /// Beam lattices (3MF), not meshed: [`crate::mesh::part::read`] meshes them into `mesh`.
    pub lattices: Vec<threemf::BeamLattice>,
    /// The beam lattices meshed into `mesh`, when there were any.
    pub beams: Option<BeamsMeshed>,
}

impl Loaded {
    /// What reading did to the file.
    pub fn reading(&self) -> Reading {
        Reading {
            faces_with_fewer_than_3_corners_skipped: self.short_faces,
            polygons_split_into_triangles: self.polygons_split,
            vertices_merged_by_tolerance: self.tolerance_welded,
            beam_lattices: self.beams,
        }
    }
}

/// What reading a file did to it, as reports give it (all zero for a clean file).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Reading {
    /// Faces with fewer than three corners, skipped.
    pub faces_with_fewer_than_3_corners_skipped: u64,
    /// Faces with more than three corners, cut into triangles.
    pub polygons_split_into_triangles: u64,
    /// Vertices merged by the weld tolerance (beyond exact welding).
    pub vertices_merged_by_tolerance: u64,
    /// Beam lattices meshed into the part.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub beam_lattices: Option<BeamsMeshed>,
}

/// Parses `data` as `format`.
pub fn parse(data: &[u8], format: Format) -> Result<Parsed> {
    match format {
        Format::Stl => stl::parse_facets(data),
        Format::Obj => obj::parse(data),
        Format::Off => off::parse(data),
        Format::Ply => ply::parse(data),
        Format::ThreeMf => threemf::parse(data),
    }
}

/// Reads a mesh file of any supported format.
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded> {
    if !(opts.weld_tolerance >= 0.0 && opts.weld_tolerance.is_finite()) {
        return Err(Error::invalid(
            "weld tolerance must be a finite length ≥ 0 mm",
        ));
    }
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let format = Format::from_path(path).unwrap_or_else(|| Format::sniff(&data));
    let p = parse(&data, format)
        .map_err(|e| Error::parse(format!("{}: {e}", format.name())).in_file(path))?;
    drop(data);
    let mut mesh = p.mesh;
    let tolerance_welded = weld::weld_tolerance(&mut mesh, opts.weld_tolerance);
    Ok(Loaded {
        format,
        mesh,
        normals: p.normals,
        short_faces: p.short_faces,
        polygons_split: p.polygons_split,
        tolerance_welded,
        lattices: p.lattices,
        beams: None,
    })
}

/// Writes `mesh` in `format` (`ascii` picks ASCII STL / ASCII PLY; other formats are text or zip).
pub fn write(
    mesh: &Mesh,
    format: Format,
    ascii: bool,
    w: &mut dyn std::io::Write,
) -> std::io::Result<()> {
    match format {
        Format::Stl => stl::write(
            mesh,
            if ascii {
                StlFormat::Ascii
            } else {
                StlFormat::Binary
            },
            w,
        ),
        Format::Obj => obj::write(mesh, w),
        Format::Off => off::write(mesh, w),
        Format::Ply => ply::write(mesh, ascii, w),
        Format::ThreeMf => threemf::write(mesh, w),
    }
}

/// Collects polygons from an indexed-format reader and turns them into a welded triangle mesh.
pub(crate) struct PolygonSink {
    pub positions: Vec<f32>,
    indices: Vec<u32>,
    corners: Vec<u32>,
    pub short_faces: u64,
    pub polygons_split: u64,
}

impl PolygonSink {
    pub fn new() -> Self {
        PolygonSink {
            positions: Vec::new(),
            indices: Vec::new(),
            corners: Vec::new(),
            short_faces: 0,
            polygons_split: 0,
        }
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len() / 3
    }

    pub fn push_vertex(&mut self, p: [f32; 3]) -> Result<()> {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(Error::parse(format!(
                "vertex {}: non-finite coordinate {p:?}",
                self.vertex_count() + 1
            )));
        }
        if self.vertex_count() >= u32::MAX as usize {
            return Err(Error::parse("more than 2^32 vertices"));
        }
        self.positions.extend_from_slice(&p);
        Ok(())
    }

    /// Adds a corner to the current face; `end_face` closes it.
    pub fn corner(&mut self, i: u32) {
        self.corners.push(i);
    }

    /// Closes the current face; its indices must name vertices already read.
    pub fn end_face(&mut self) -> Result<()> {
        let nv = self.vertex_count();
        if let Some(&bad) = self.corners.iter().find(|&&i| i as usize >= nv) {
            return Err(Error::parse(format!(
                "face corner {bad} past the {nv} vertices"
            )));
        }
        let c = std::mem::take(&mut self.corners);
        match c.len() {
            0..=2 => self.short_faces += 1,
            3 => self.indices.extend_from_slice(&c),
            _ => {
                self.polygons_split += 1;
                let pts: Vec<[f64; 3]> = c
                    .iter()
                    .map(|&i| {
                        let i = 3 * i as usize;
                        [0, 1, 2].map(|a| self.positions[i + a] as f64)
                    })
                    .collect();
                match crate::geom::triangulate::triangulate_polygon(&pts) {
                    Some(tris) => {
                        for t in tris {
                            self.indices.extend(t.map(|k| c[k]));
                        }
                    }
                    None => {
                        // Not simple in projection: a fan keeps every corner and the winding.
                        for k in 1..c.len() - 1 {
                            self.indices.extend_from_slice(&[c[0], c[k], c[k + 1]]);
                        }
                    }
                }
            }
        }
        self.corners = c;
        self.corners.clear();
        Ok(())
    }

    pub fn finish(self) -> Result<Parsed> {
        self.finish_or_empty(false)
    }

    /// As [`PolygonSink::finish`], with no triangles allowed when `empty_ok` (the file holds
    /// its geometry otherwise).
    pub fn finish_or_empty(self, empty_ok: bool) -> Result<Parsed> {
        if self.indices.is_empty() && !empty_ok {
            return Err(Error::parse("no triangles in the file"));
        }
        Ok(Parsed {
            mesh: if self.indices.is_empty() {
                Mesh::default()
            } else {
                weld::weld_indexed(&self.positions, &self.indices)?
            },
            normals: None,
            short_faces: self.short_faces,
            polygons_split: self.polygons_split,
            lattices: Vec::new(),
        })
    }
}

/// An upper bound for `reserve` from a count read in a file: never more items than `bytes_left`
/// could hold at `min_bytes` each.
pub(crate) fn bounded(count: u64, bytes_left: usize, min_bytes: usize) -> usize {
    count.min((bytes_left / min_bytes.max(1)) as u64) as usize
}

/// Whitespace-separated words of a byte buffer, with line counting (CR, LF and CRLF each end
/// one line).
pub(crate) struct Words<'a> {
    data: &'a [u8],
    pub pos: usize,
    pub line: usize,
}

impl<'a> Words<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Words {
            data,
            pos: 0,
            line: 1,
        }
    }

    fn skip_space(&mut self) {
        while let Some(&b) = self.data.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if b == b'\n' || (b == b'\r' && self.data.get(self.pos + 1) != Some(&b'\n')) {
                self.line += 1;
            }
            self.pos += 1;
        }
    }

    pub fn next(&mut self) -> Option<&'a [u8]> {
        self.skip_space();
        let start = self.pos;
        while self
            .data
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        (self.pos > start).then(|| &self.data[start..self.pos])
    }

    pub fn peek(&mut self) -> Option<&'a [u8]> {
        let (pos, line) = (self.pos, self.line);
        let t = self.next();
        self.pos = pos;
        self.line = line;
        t
    }

    pub fn skip_line(&mut self) {
        while let Some(&b) = self.data.get(self.pos) {
            if b == b'\n' || b == b'\r' {
                break;
            }
            self.pos += 1;
        }
    }
}
