//! The volume fraction of a solid against its level, from samples: for each of a set of points
//! spread through the region, the smallest level at which the solid holds it (a distance to a
//! strut's axis or to a wall's mid-surface, for solids that grow by a distance); the fraction at
//! a level is the share of points held, interpolated between the sorted levels so that it
//! increases strictly. The pipeline steps the level through it and corrects it on the meshed part.

/// A solid's volume fraction against its level, sampled.
#[derive(Debug, Clone)]
pub struct LevelModel {
    /// The level at which each point is held, sorted.
    levels: Vec<f64>,
    /// A level at which every point is held.
    max_level: f64,
}

impl LevelModel {
    /// The model of points held from `levels` on (any order; infinite: never held); `beyond`
    /// is a level that holds every point when none is finite.
    pub fn new(mut levels: Vec<f64>, beyond: f64) -> LevelModel {
        levels.retain(|l| !l.is_nan());
        levels.sort_by(f64::total_cmp);
        let last = levels.iter().rev().find(|l| l.is_finite()).copied();
        let max_level = last.unwrap_or(beyond) * (1.0 + 1e-9) + 1e-12;
        LevelModel { levels, max_level }
    }

    /// The fraction of the points held at `level`.
    pub fn fraction(&self, level: f64) -> f64 {
        let n = self.levels.len();
        if level <= 0.0 {
            return 0.0;
        }
        if level >= self.max_level {
            return self.levels.partition_point(|x| x.is_finite()) as f64 / (n as f64).max(1.0);
        }
        // Points held at the level: levels[k] ≤ level for k < count; interpolate to the next.
        let count = self.levels.partition_point(|&x| x <= level);
        let below = if count == 0 {
            0.0
        } else {
            self.levels[count - 1]
        };
        let above = self
            .levels
            .get(count)
            .copied()
            .filter(|l| l.is_finite())
            .unwrap_or(self.max_level);
        let t = if above > below {
            (level - below) / (above - below)
        } else {
            0.0
        };
        ((count as f64 + t) / (n as f64 + 1.0)).clamp(0.0, 1.0)
    }

    /// The level at which the solid holds `fraction` of the points (the inverse of
    /// [`LevelModel::fraction`]).
    pub fn level(&self, fraction: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, self.max_level);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.fraction(mid) < fraction {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}
