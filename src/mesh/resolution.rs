//! The resolution a part needs: the one asked for, unless its members are too thin for those
//! voxels or no level there gives the target density — then the smallest finer one that works
//! (steps that double, then bisection), or, with a fixed resolution, a refusal that names it.
//!
//! A lattice whose members span under a voxel or so is not represented faithfully by a narrow
//! band: samples miss the member and it perforates or falls apart, and its volume jumps with the
//! level instead of growing with it. The capability says how thick its thinnest member is (and
//! so which resolution it needs at least); the search finds the rest by meshing.

use super::instance;
use super::pipeline::PROMISE;
use crate::error::{Error, Result};

/// A resolution at which no level gave the target density.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct ResolutionMiss {
    /// Voxels per cell.
    pub resolution: u32,
    /// The closest volume fraction found.
    pub closest: f64,
}

/// What the search is asked.
#[derive(Debug, Clone)]
pub struct Request {
    /// The part, for messages: "the gyroid net".
    pub part: String,
    /// What it is made to, for messages: "density 0.3", "radius 0.25 mm".
    pub setting: String,
    /// Voxels per cell asked for.
    pub requested: u32,
    /// The resolution the part's thinnest members need, with the reason the requested one falls
    /// short (`None` when it does not).
    pub thin: Option<(u32, String)>,
    /// The target density, when one is sought.
    pub density: Option<f64>,
    /// Raise the resolution (`true`), or refuse naming the smallest that works.
    pub auto: bool,
    /// What the resolution counts voxels per, for messages: "cell", "spacing".
    pub per: &'static str,
}

/// The resolution found and what was found there.
pub struct Resolved<T> {
    /// Voxels per cell used.
    pub resolution: u32,
    /// What the attempt found at it.
    pub found: T,
    /// Resolutions tried that missed the density, in increasing order.
    pub coarser: Vec<ResolutionMiss>,
    /// Why the resolution was raised, as a warning (`None` when it was not).
    pub raised: Option<String>,
}

/// Refuses a volume fraction outside (0, 1).
pub fn check_density(d: f64) -> Result<()> {
    if d > 0.0 && d < 1.0 {
        return Ok(());
    }
    Err(Error::setting(
        "density",
        format!("density must be in (0, 1), got {d}"),
    ))
}

/// Refuses a blend radius that is not a length ≥ 0.
pub fn check_blend(blend: f64) -> Result<()> {
    if blend >= 0.0 && blend.is_finite() {
        return Ok(());
    }
    Err(Error::setting(
        "blend",
        format!("blend must be a length ≥ 0 mm, got {blend}"),
    ))
}

/// Refuses fewer than 4 voxels per cell.
pub fn check_resolution(resolution: u32) -> Result<()> {
    if resolution >= 4 {
        return Ok(());
    }
    Err(Error::setting(
        "resolution",
        format!("resolution must be at least 4 voxels per cell, got {resolution}"),
    ))
}

/// The finest resolution tried before a part is refused.
pub fn max_resolution(requested: u32) -> u32 {
    (4 * requested).max(64)
}

/// Searches the resolution for `request`: `attempt(r)` meshes the part at `r` voxels per cell
/// and returns what it found, or the closest density it could reach.
pub fn search<T>(
    request: &Request,
    attempt: &mut impl FnMut(u32) -> Result<std::result::Result<T, f64>>,
) -> Result<Resolved<T>> {
    let mut passed_over: Vec<String> = Vec::new();
    let mut start = request.requested;
    if let Some((needed, why)) = request.thin.as_ref().filter(|(n, _)| *n > start) {
        passed_over.push(why.clone());
        // Raised to whole 8-voxel blocks, so that cells can still be copied exactly; a refusal
        // names the smallest that works.
        start = if request.auto {
            needed.div_ceil(instance::BLOCK) * instance::BLOCK
        } else {
            *needed
        };
    }
    let limit = max_resolution(request.requested).max(start);
    let mut coarser = Vec::new();
    let mut tried = |r: u32| -> Result<Option<T>> {
        Ok(match attempt(r)? {
            Ok(found) => Some(found),
            Err(closest) => {
                coarser.push(ResolutionMiss {
                    resolution: r,
                    closest,
                });
                None
            }
        })
    };
    let Some((resolution, found)) = smallest_resolution(start, limit, &mut tried)? else {
        let closest = coarser.last().map_or(f64::NAN, |m| m.closest);
        return Err(Error::Resolution {
            requested: request.requested,
            needed: None,
            message: format!(
                "no level gives {} a density of {} within {PROMISE} at {} to {limit} voxels per {} (closest {closest:.4}); the box may cut the lattice into pieces",
                request.part,
                request.density.unwrap_or(f64::NAN),
                request.requested,
                request.per,
            ),
        });
    };
    coarser.sort_by_key(|m| m.resolution);
    if let Some(miss) = coarser.first().filter(|m| m.resolution == start) {
        let target = request.density.unwrap_or(f64::NAN);
        passed_over.push(if (miss.closest - target).abs() <= PROMISE {
            // The density was met, but the mesh had holes.
            format!(
                "at {} voxels per {} the part comes out with holes: the voxels are too coarse for the lattice's members",
                miss.resolution, request.per
            )
        } else {
            format!(
                "at {} voxels per {} no level gives density {target} (closest {:.4}): the voxels are too coarse for the lattice's members",
                miss.resolution, request.per, miss.closest
            )
        });
    }
    let raised = match passed_over.first() {
        Some(why) if !request.auto => {
            return Err(Error::Resolution {
                requested: request.requested,
                needed: Some(resolution),
                message: format!(
                    "{} at {}: {why}; use --resolution {resolution}, the smallest that works",
                    request.part, request.setting,
                ),
            })
        }
        Some(why) => Some(format!(
            "resolution raised from {} to {resolution} voxels per {}: {why}",
            request.requested, request.per
        )),
        None => None,
    };
    Ok(Resolved {
        resolution,
        found,
        coarser,
        raised,
    })
}

/// The smallest resolution from `start` up to `limit` at which `attempt` finds the part (its
/// result), or `None`: `start` first, then steps that double until one works, then bisection
/// between the last that failed and the first that worked — so the resolution returned works
/// and the one below it (when above `start`) does not.
pub fn smallest_resolution<T>(
    start: u32,
    limit: u32,
    attempt: &mut impl FnMut(u32) -> Result<Option<T>>,
) -> Result<Option<(u32, T)>> {
    if let Some(t) = attempt(start)? {
        return Ok(Some((start, t)));
    }
    let mut failed = start;
    let mut step = (start / 4).max(1);
    let mut worked = loop {
        if failed >= limit {
            return Ok(None);
        }
        let r = (failed + step).min(limit);
        match attempt(r)? {
            Some(t) => break (r, t),
            None => {
                failed = r;
                step *= 2;
            }
        }
    };
    while worked.0 - failed > 1 {
        let mid = failed + (worked.0 - failed) / 2;
        match attempt(mid)? {
            Some(t) => worked = (mid, t),
            None => failed = mid,
        }
    }
    Ok(Some(worked))
}
