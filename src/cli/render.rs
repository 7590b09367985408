//! `latvox render`: a picture of a part straight from its part file (sphere-traced, never
//! meshed), or of a mesh file (ray cast through a BVH).

use super::command::{parsed, Command};
use super::out::outln;
use super::part::{is_part_file, part_of, Part};
use super::{emit_json, parse_f64};
use clap::Args;
use latvox::geom::bvh::Bvh;
use latvox::render::camera::{Camera, View};
use latvox::render::trace::{Implicit, Scene, Section, Triangles};
use latvox::render::{render, Frame};
use latvox::{Error, Result};
use std::path::PathBuf;
use std::time::Instant;

pub(crate) const EXAMPLES: &str = "\
Examples:
  # A gyroid part saved as a part file, seen from the front-right above
  latvox tpms --type gyroid --density 0.3 --cells 4 -o gyroid.stl --save-part gyroid.toml
  latvox render gyroid.toml -o gyroid.png

  # A strut part, 1200×900, from the top, cut at z = 10 mm to show the inside
  latvox render bcc.toml -o bcc.png --view top --width 1200 --height 900 --section z=10

  # Eight views around the part, side by side in one picture; 36 as an animation (APNG)
  latvox render filled.toml -o turn.png --turntable 8 --width 320 --height 240
  latvox render filled.toml -o spin.png --turntable 36 --animate --width 400 --height 300

  # The meshed part, ray cast, from the same camera (to compare), with its depth as .npy
  latvox render gyroid.stl -o gyroid-mesh.png --depth gyroid-mesh.npy

A part file (from --save-part of tpms, strut, voronoi or fill) is rendered from its implicit
solid at the level its mesh is written at (a filled part's lattice at its unit cell's) — the
part is never meshed whole, so a part of a million cells renders as fast as one of a thousand. A mesh file (.stl, .3mf, .obj, .off, .ply) is ray cast as it is.
Angles: the azimuth turns about z from the front (eye on −y, 0°) towards the right (eye on +x,
90°); the elevation lifts the eye above the xy plane.";

/// `latvox render`.
pub(crate) const COMMAND: Command = Command::new(
    "render",
    "Render a picture of a part file, sphere-traced from its implicit solid without meshing it, or of a mesh file, ray cast",
    EXAMPLES,
    <RenderArgs as clap::Args>::augment_args,
    |m, _| run(&parsed(m)?),
);

/// The most pixels one picture holds (all views together): some 1.3 GB of colour and depth.
const MAX_PIXELS: u64 = 100_000_000;

#[derive(Args)]
pub struct RenderArgs {
    /// A part file (.toml, from --save-part) or a mesh file (.stl, .3mf, .obj, .off, .ply).
    #[arg(value_name = "PART")]
    pub input: PathBuf,
    /// The picture, PNG.
    #[arg(long, short = 'o', value_name = "FILE.png", default_value = "view.png")]
    pub output: PathBuf,
    /// Where the camera looks from.
    #[arg(long, value_enum, default_value = "iso")]
    pub view: View,
    /// Azimuth in degrees (overrides the view's): 0 front, 90 right, 180 back, −90 left.
    #[arg(long, value_name = "DEG", value_parser = parse_angle, allow_hyphen_values = true)]
    pub azimuth: Option<f64>,
    /// Elevation in degrees above the xy plane (overrides the view's), −90 to 90.
    #[arg(long, value_name = "DEG", value_parser = parse_elevation, allow_hyphen_values = true)]
    pub elevation: Option<f64>,
    /// Distance from the eye to the part's centre, mm (default: the part fills the picture).
    #[arg(long, value_name = "MM", value_parser = super::parse_positive)]
    pub distance: Option<f64>,
    /// Width, pixels.
    #[arg(long, default_value_t = 800, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub width: u32,
    /// Height, pixels.
    #[arg(long, default_value_t = 600, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub height: u32,
    /// Cut away the part beyond a plane to show its inside: AXIS=MM removes what lies above
    /// (x=, y= or z=), AXIS<MM keeps what lies below and AXIS>MM what lies above.
    #[arg(long, value_name = "AXIS=MM", value_parser = parse_section)]
    pub section: Option<Section>,
    /// N views around the part (the azimuth stepped by 360°/N), side by side in one picture.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=72))]
    pub turntable: Option<u32>,
    /// With --turntable: an animated PNG (APNG) of the views, a tenth of a second each, instead
    /// of a strip.
    #[arg(long, requires = "turntable")]
    pub animate: bool,
    /// Also write the depth per pixel (mm from the eye, inf where the ray missed) as .npy (the
    /// views side by side, with --turntable).
    #[arg(long, value_name = "FILE.npy")]
    pub depth: Option<PathBuf>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

fn parse_angle(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    v.is_finite()
        .then_some(v)
        .ok_or_else(|| format!("{s} is not an angle in degrees"))
}

fn parse_elevation(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if (-90.0..=90.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "elevation must be between -90 and 90 degrees, got {s}"
        ))
    }
}

/// `z=12` (cut away above), `z<12` (keep below), `z>12` (keep above).
pub(crate) fn parse_section(s: &str) -> std::result::Result<Section, String> {
    let t = s.trim();
    let bad = || format!("'{s}' is not a section: give AXIS=MM, AXIS<MM or AXIS>MM, e.g. z=12");
    let axis = match t.chars().next().map(|c| c.to_ascii_lowercase()) {
        Some('x') => 0,
        Some('y') => 1,
        Some('z') => 2,
        _ => return Err(bad()),
    };
    let rest = &t[1..];
    let (keep_above, value) = match rest.chars().next() {
        Some('=') | Some('<') => (false, &rest[1..]),
        Some('>') => (true, &rest[1..]),
        _ => return Err(bad()),
    };
    let v: f64 = value.trim().parse().map_err(|_| bad())?;
    if !v.is_finite() {
        return Err(bad());
    }
    let mut normal = [0.0; 3];
    normal[axis] = if keep_above { -1.0 } else { 1.0 };
    Ok(Section {
        normal,
        offset: if keep_above { -v } else { v },
    })
}

/// What was rendered, as `--json` prints it.
#[derive(serde::Serialize)]
struct Rendered {
    input: String,
    output: String,
    /// "implicit" (a part file, sphere traced) or "mesh" (ray cast).
    method: &'static str,
    width: u32,
    height: u32,
    views: u32,
    /// Share of pixels on the part.
    coverage: f64,
    seconds: f64,
}

pub fn run(a: &RenderArgs) -> Result<i32> {
    let start = Instant::now();
    let png = a
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png {
        return Err(Error::invalid(format!(
            "{}: pictures are written as PNG: name the output .png",
            a.output.display()
        )));
    }
    let n_views = a.turntable.unwrap_or(1) as u64;
    let pixels = a.width as u64 * a.height as u64 * n_views;
    if pixels > MAX_PIXELS {
        return Err(Error::invalid(format!(
            "{} × {} pixels{} is more than latvox renders at once ({} million pixels)",
            a.width,
            a.height,
            if n_views > 1 {
                format!(" × {n_views} views")
            } else {
                String::new()
            },
            MAX_PIXELS / 1_000_000
        )));
    }
    latvox::io::atomic::check_writable(&a.output)?;
    if let Some(d) = &a.depth {
        latvox::io::atomic::check_writable(d)?;
    }
    let (frames, method) = if is_part_file(&a.input) {
        let frames = match part_of(&a.input, latvox::render::Fidelity::Look)? {
            Part::Block(model) => {
                let field = model.field();
                let scene =
                    Implicit::new(&*field, model.bounds(), a.section, model.voxel, model.cell)
                        .dropping(&model.loose, model.voxel);
                views(a, &scene)
            }
            Part::Filled(traced) => {
                let field = traced.lattice_field();
                views(a, &traced.scene(&*field, a.section))
            }
        };
        (frames, "implicit")
    } else {
        let loaded = latvox::mesh::part::read(&a.input, &Default::default())?;
        if loaded.mesh.indices.is_empty() {
            return Err(Error::invalid(format!(
                "{}: no triangles to render",
                a.input.display()
            )));
        }
        let bvh = Bvh::new(&loaded.mesh);
        let scene = Triangles {
            bvh: &bvh,
            section: a.section,
        };
        (views(a, &scene), "mesh")
    };
    let frame = Frame::strip(&frames)?;
    if a.animate {
        let rgb: Vec<&[u8]> = frames.iter().map(|f| f.rgb.as_slice()).collect();
        latvox::io::png::write_animated(&a.output, a.width, a.height, &rgb, 100)?;
    } else {
        frame.write_png(&a.output)?;
    }
    if let Some(d) = &a.depth {
        frame.write_depth(d)?;
    }
    let r = Rendered {
        input: a.input.display().to_string(),
        output: a.output.display().to_string(),
        method,
        width: frame.width,
        height: frame.height,
        views: a.turntable.unwrap_or(1),
        coverage: frame.hits() as f64 / frame.depth.len() as f64,
        seconds: start.elapsed().as_secs_f64(),
    };
    if !emit_json(None, a.json, &r)? {
        outln!(
            "{} → {}: {}×{} px{}, {} ({}), part on {:.1} % of pixels, {:.2} s",
            r.input,
            r.output,
            r.width,
            r.height,
            if r.views > 1 {
                format!(" ({} views)", r.views)
            } else {
                String::new()
            },
            if method == "implicit" {
                "sphere traced from the part file"
            } else {
                "mesh ray cast"
            },
            method,
            100.0 * r.coverage,
            r.seconds
        );
    }
    Ok(0)
}

/// The view asked for, or the turntable's views.
fn views(a: &RenderArgs, scene: &dyn Scene) -> Vec<Frame> {
    let bounds = scene.bounds();
    let (az0, el0) = a.view.angles();
    let az = a.azimuth.unwrap_or(az0);
    let el = a.elevation.unwrap_or(el0);
    let camera = |az: f64| Camera::looking_at(&bounds, az, el, a.distance, a.width, a.height);
    let n = a.turntable.unwrap_or(1);
    (0..n)
        .map(|i| render(scene, &camera(az + 360.0 * i as f64 / n as f64)))
        .collect()
}
