//! TPMS lattices on a cell map ([`crate::field::cellmap`]): cells wrapped around an axis (the
//! lattice `F(u(p))` cut by the tube) or a centre (cut by the spherical shell), or growing along
//! one axis of a box. The part goes through the
//! one pipeline ([`crate::mesh::pipeline`]): meshed whole (or in tiles), its level found on the
//! part itself against the tube's volume.
//!
//! With one cell through the wall and whole cells around and along, every cell is the image of
//! every other under a turn about the axis or a shift along it, so the part's density is each
//! cell's. With several cells through the wall the map's Jacobian (∝ r) weighs the layers
//! differently: the density of each layer is measured on the mesh (the solid within each radius,
//! by the divergence theorem) and reported. Cells that grow along an axis are stretched unevenly
//! within each cell; the level is found on the part against its box.

use super::calibrate::{self, Connectivity};
use super::job::TpmsJob;
use super::{Structure, Surface, TpmsField, TpmsReport};
use crate::error::{Error, Result};
use crate::field::cellmap::{CellMap, Cylindrical, GradedCells, Layered, Mapping, Spherical};
use crate::field::sizing::Fit;
use crate::field::{intersection_clearance, Aabb, Field, Vec3};
use crate::grid::GridSpec;
use crate::io::sink::{MeshSink, Triangle};
use crate::mesh::pipeline::{self, Family, Route, Solid};
use crate::mesh::report::{LevelSearch, PartReport, Timings};
use crate::mesh::resolution;
use crate::progress::Progress;
use std::time::Instant;

/// A TPMS lattice on a cell map (cut by its region), at one level.
#[derive(Debug, Clone)]
pub struct MappedLattice<M> {
    /// Which minimal surface.
    pub surface: Surface,
    /// Net, sheet or the other labyrinth.
    pub structure: Structure,
    /// The level `t`.
    pub level: f64,
    /// The cell map (and the region it fills).
    pub map: M,
}

/// The mapped lattice's field: the first-order distance `(F∘u − t)/|∇(F∘u)|`, cut by the map's
/// region where it is not the box.
struct MappedField<M> {
    /// The surface with unit cells at the origin: `distance_at` and `implicit_at` in cell
    /// coordinates.
    tpms: TpmsField,
    map: M,
    /// `|∇(F∘u)|` bound (within the map's room of a point).
    lipschitz: f64,
}

impl<M: CellMap> MappedField<M> {
    /// `F`, the implicit function and its gradient in world coordinates.
    #[inline(always)]
    fn eval(&self, p: Vec3) -> (f64, f64, Vec3) {
        let (u, j) = self.map.coords(p);
        let (f, g) = self.tpms.surface.eval(u);
        let gw = [0, 1, 2].map(|i| g[0] * j[0][i] + g[1] * j[1][i] + g[2] * j[2][i]);
        (f, self.tpms.implicit_at(f, self.tpms.level), gw)
    }

    /// The lattice's clearance: its implicit value over the gradient bound, within the ball
    /// where the bound holds (out of the inner half of a tube's bore).
    fn lattice_clearance(&self, p: Vec3, implicit: f64) -> f64 {
        let room = self.map.room(p);
        if room <= 0.0 {
            return 0.0;
        }
        (implicit.abs() / self.lipschitz).min(room)
    }
}

impl<M: CellMap> Field for MappedField<M> {
    fn value(&self, p: Vec3) -> f64 {
        self.value_and_clearance(p).0
    }

    fn clearance(&self, p: Vec3) -> f64 {
        self.value_and_clearance(p).1
    }

    fn value_and_clearance(&self, p: Vec3) -> (f64, f64) {
        let (f, v, g) = self.eval(p);
        let a = self.tpms.distance_at(f, g, self.tpms.level);
        let ca = self.lattice_clearance(p, v);
        match self.map.cut(p) {
            None => (a, ca),
            Some((b, _)) => (
                a.max(b.clamp(-self.tpms.clamp, self.tpms.clamp)),
                intersection_clearance(a, ca, b, b.abs()),
            ),
        }
    }

    /// Not smooth where the lattice meets the region's curved wall (a tube's or a shell's):
    /// Newton steps on the larger of the two land on either side of the edge, and neighbouring
    /// vertices on different sides can cross (a self-intersection CGAL finds).
    fn smooth_near(&self, p: Vec3, reach: f64) -> bool {
        match self.map.cut(p) {
            Some((b, _)) if b.abs() < reach => {
                let (f, _, g) = self.eval(p);
                self.tpms.distance_at(f, g, self.tpms.level).abs() >= reach
            }
            _ => true,
        }
    }

    fn implicit_with_gradient(&self, p: Vec3) -> (f64, Vec3) {
        let (f, v, g) = self.eval(p);
        let sign = match self.tpms.structure {
            Structure::Net => 1.0,
            Structure::Sheet => f.signum(),
            Structure::NetOther => -1.0,
        };
        let g = g.map(|x| sign * x);
        let n = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt().max(1e-12);
        // Whichever of the two solids is the boundary here, in the same (distance) units.
        match self.map.cut(p) {
            Some((b, gb)) if b > v / n => (b, gb),
            _ => (v / n, g.map(|x| x / n)),
        }
    }
}

impl<M: CellMap> Solid for MappedLattice<M> {
    fn field(&self, spec: &GridSpec) -> Box<dyn Field + '_> {
        let tpms = TpmsField::new(
            self.surface,
            self.structure,
            self.level,
            [1.0; 3],
            [0.0; 3],
            spec.half_width * spec.voxel,
        );
        Box::new(MappedField {
            tpms,
            map: self.map.clone(),
            lipschitz: self.map.lipschitz(self.surface.lipschitz_per_axis()),
        })
    }

    fn bounds(&self) -> Aabb {
        self.map.bounds()
    }

    fn with_bounds(&self, _bounds: Aabb) -> Self {
        // Only periodic solids are clipped to other boxes (templates, calibration cells).
        self.clone()
    }

    fn period(&self) -> Option<Vec3> {
        None
    }
}

/// The mapped lattice at every level; its density is its share of the map's region.
#[derive(Debug, Clone)]
pub struct MappedFamily<M> {
    /// The part at some level (replaced).
    pub part: MappedLattice<M>,
}

impl<M: CellMap> Family for MappedFamily<M> {
    type Solid = MappedLattice<M>;

    fn at(&self, level: f64) -> MappedLattice<M> {
        MappedLattice {
            level,
            ..self.part.clone()
        }
    }

    fn model_fraction(&self, level: f64) -> f64 {
        calibrate::analytic_fraction(self.part.surface, self.part.structure, level)
    }

    fn model_level(&self, fraction: f64) -> f64 {
        calibrate::analytic_level(self.part.surface, self.part.structure, fraction)
    }

    fn fraction(&self, volume: f64, _bounds: &Aabb) -> f64 {
        volume / CellMap::volume(&self.part.map)
    }
}

/// The cell map, and how a tube's layers met the density.
#[derive(Debug, Clone, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CellMapReport {
    /// Cells wrapped around an axis.
    Cylindrical {
        /// The map: axis, bore, cells, sizes.
        #[serde(flatten)]
        map: Cylindrical,
        /// Outer radius, mm.
        outer_radius: f64,
        /// Length along the axis, mm.
        length: f64,
        /// The tube's volume, mm³ (the density's base).
        tube_volume: f64,
        /// The density of each layer of cells through the wall, bore outwards, measured on the
        /// written mesh.
        layer_densities: Vec<f64>,
    },
    /// Cells wrapped around a centre (a cubed sphere).
    Spherical {
        /// The map: centre, bore, cells, size through the wall.
        #[serde(flatten)]
        map: Spherical,
        /// Outer radius, mm.
        outer_radius: f64,
        /// The shell's volume, mm³ (the density's base).
        shell_volume: f64,
        /// Every cell of the shell.
        total_cells: u64,
        /// The density of each layer of cells through the wall, bore outwards, measured on the
        /// written mesh.
        layer_densities: Vec<f64>,
    },
    /// Cells growing along an axis.
    Graded {
        /// The map: box, axis, end sizes, count.
        #[serde(flatten)]
        map: GradedCells,
        /// The cells' faces along the graded axis, mm.
        faces: Vec<f64>,
    },
    /// Cells sized by a field.
    Sized {
        /// The box.
        #[serde(rename = "box")]
        bounds: Aabb,
        /// Whole cells along each axis.
        counts: [u32; 3],
        /// The cell-size field, as given.
        field: String,
        /// How the cells came from the field.
        #[serde(flatten)]
        fit: Fit,
    },
}

impl TpmsJob {
    /// Runs a job on a cell map.
    pub(super) fn run_mapped(
        &self,
        mapping: Mapping,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<TpmsReport> {
        match mapping {
            Mapping::Cylindrical(map) => {
                let (mut report, layer_densities) =
                    self.run_layered(map, "tube", progress, sink)?;
                report.cell_map = Some(CellMapReport::Cylindrical {
                    map,
                    outer_radius: map.outer(),
                    length: map.length(),
                    tube_volume: map.volume(),
                    layer_densities,
                });
                Ok(report)
            }
            Mapping::Spherical(map) => {
                let (mut report, layer_densities) =
                    self.run_layered(map, "spherical shell", progress, sink)?;
                report.cell_map = Some(CellMapReport::Spherical {
                    map,
                    outer_radius: map.outer(),
                    shell_volume: map.volume(),
                    total_cells: map.total(),
                    layer_densities,
                });
                Ok(report)
            }
            Mapping::Graded(map) => {
                let mut report = self.run_on(map, "part with graded cells", progress, sink)?;
                report.cell_map = Some(CellMapReport::Graded {
                    map,
                    faces: map.faces(),
                });
                Ok(report)
            }
            Mapping::Sized(map) => {
                let fit = map.fit();
                let mut report =
                    self.run_on(map.clone(), "part with sized cells", progress, sink)?;
                for (a, [lo, hi]) in fit.made_over_asked.iter().enumerate() {
                    if *lo < 2.0 / 3.0 || *hi > 1.5 {
                        report.part.warnings.push(format!(
                            "cells across {} are {lo:.2}–{hi:.2}× the field's size: every line along {} holds the same {} whole cells, so a field that varies across it is followed only in its shape along the line",
                            ["x", "y", "z"][a],
                            ["x", "y", "z"][a],
                            map.cell_counts()[a]
                        ));
                    }
                }
                report.cell_map = Some(CellMapReport::Sized {
                    bounds: CellMap::bounds(&map),
                    counts: map.cell_counts(),
                    field: map.source().to_string(),
                    fit,
                });
                Ok(report)
            }
        }
    }

    /// Runs a job on a map whose cells lie in layers through a wall; each layer's density is
    /// measured on the triangles on their way to the sink (a layer off by more than 0.005 is a
    /// warning).
    fn run_layered<M: Layered>(
        &self,
        map: M,
        what: &str,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<(TpmsReport, Vec<f64>)> {
        let mut layers = Layers::new(map, sink);
        let mut report = self.run_on(map, what, progress, &mut layers)?;
        let layer_densities = layers.densities();
        for (k, d) in layer_densities.iter().enumerate() {
            if (d - self.density).abs() > 0.005 {
                report.part.warnings.push(format!(
                    "layer {} of {} through the wall holds {d:.4}, the {what} {:.4}: the map's Jacobian weighs the layers differently",
                    k + 1,
                    layer_densities.len(),
                    report.part.achieved_density
                ));
            }
        }
        Ok((report, layer_densities))
    }

    /// Runs a job on the cell map `map` (`what` the part is, for messages).
    fn run_on<M: CellMap>(
        &self,
        map: M,
        what: &str,
        progress: &Progress,
        sink: &mut dyn MeshSink,
    ) -> Result<TpmsReport> {
        let start = Instant::now();
        if self.grading.is_some() || self.blend.is_some() {
            return Err(Error::invalid(format!(
                "a cell map makes a uniform density: a graded or blended {what} is not supported yet"
            )));
        }
        let (s, st) = (self.surface, self.structure);
        let range = calibrate::feasible(s, st);
        let (conn, mut warnings): (Connectivity, Vec<String>) = self.connectivity(range)?;
        let t0 = calibrate::analytic_level(s, st, self.density);
        let opts = self.options(false, !conn.solid);
        let request = self.request(format!("the {} {} {what}", s.name(), st.name()), t0);
        let mut calibrate_seconds = 0.0;
        let mut calibration = None;
        let resolved = resolution::search(&request, &mut |r| {
            let _p = progress.stage("calibrating and meshing");
            let voxel = map.shortest_edge() / r as f64;
            let t = Instant::now();
            // The unit cell at a typical cell's size: a first level.
            let cal = calibrate::calibrate(
                s,
                st,
                self.density,
                map.mid_cell(),
                voxel,
                [1e6; 3],
                self.adaptivity,
            )?;
            calibrate_seconds += t.elapsed().as_secs_f64();
            let level = if cal.converged {
                cal.level
            } else {
                cal.analytic_level
            };
            calibration = Some(cal);
            let family = MappedFamily {
                part: MappedLattice {
                    surface: s,
                    structure: st,
                    level,
                    map: map.clone(),
                },
            };
            let route = Route::choose(&family.part, voxel, &opts);
            let solved = pipeline::solve(&family, self.density, level, voxel, route, &opts)?;
            Ok(if solved.met {
                Ok((voxel, family, route, solved))
            } else {
                Err(solved.best.fraction)
            })
        })?;
        warnings.extend(resolved.raised);
        let (voxel, family, route, solved) = resolved.found;
        let level = solved.best.level;
        let level_search = LevelSearch::new(&solved.best, route, &solved.tried, resolved.coarser);
        let written = pipeline::write(&family, solved.best, voxel, route, &opts, progress, sink)?;
        let volume = written.measures.volume;
        let mut part = PartReport::new(
            map.bounds(),
            Some(self.density),
            route,
            written,
            solved.meshing,
            Timings {
                calibrate: calibrate_seconds,
                ..Timings::default()
            },
        );
        part.density_against(self.density, volume / map.volume());
        warnings.append(&mut part.warnings);
        part.warnings = warnings;
        part.timings.total = start.elapsed().as_secs_f64();
        Ok(TpmsReport {
            surface: s,
            structure: st,
            level,
            calibration: calibration.expect("the resolution search calibrated"),
            level_search,
            feasible_range: range,
            connectivity: conn,
            resolution_requested: self.resolution,
            resolution: resolved.resolution,
            voxel_size: voxel,
            thinnest_wall_voxels: (st == Structure::Sheet)
                .then(|| calibrate::thinnest_sheet_wall(s, t0) * map.shortest_edge() / voxel),
            cell_size: map.mid_cell(),
            cells: map.counts(),
            grading: None,
            blend: None,
            cell_map: None,
            part,
        })
    }
}

/// A sink that passes the triangles on and measures, as they pass, the solid within each
/// radius between two layers of cells (bore to outer wall).
struct Layers<'a, M> {
    sink: &'a mut dyn MeshSink,
    map: M,
    radii: Vec<f64>,
    within: Vec<f64>,
}

impl<'a, M: Layered> Layers<'a, M> {
    fn new(map: M, sink: &'a mut dyn MeshSink) -> Self {
        let radii = map.layer_radii();
        Layers {
            sink,
            map,
            within: vec![0.0; radii.len()],
            radii,
        }
    }

    /// The density of each layer: the solid between its two radii over the region's volume
    /// there.
    fn densities(&self) -> Vec<f64> {
        (0..self.within.len() - 1)
            .map(|k| {
                let ring = self.map.region_between(self.radii[k], self.radii[k + 1]);
                (self.within[k + 1] - self.within[k]) / ring
            })
            .collect()
    }
}

impl<M: Layered> MeshSink for Layers<'_, M> {
    fn begin(&mut self, triangles: Option<u64>) -> Result<()> {
        self.sink.begin(triangles)
    }

    fn triangles(&mut self, batch: &[Triangle]) -> Result<()> {
        use rayon::prelude::*;
        let tri = |t: &Triangle| t.map(|p| p.map(f64::from));
        for (k, &r) in self.radii.iter().enumerate() {
            // Fixed chunks added in order: the same sum whatever the scheduling.
            let parts: Vec<f64> = batch
                .par_chunks(4096)
                .map(|c| self.map.volume_within(&mut c.iter().map(tri), r))
                .collect();
            self.within[k] += parts.iter().sum::<f64>();
        }
        self.sink.triangles(batch)
    }

    fn finish(&mut self) -> Result<()> {
        self.sink.finish()
    }
}
