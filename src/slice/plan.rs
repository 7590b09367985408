//! Layer heights: uniform, or adaptive — by the change of cross-section area between layers
//! (keep a layer when `|S_n − S_{n−1}| / S_n ≤ C`, else halve it, down to a minimum; the rule of
//! area-based adaptive slicing, C ≈ 0.1) or by the stair-step cusp (Dolenc and Mäkelä, "Slicing
//! procedures for layered manufacturing techniques", Computer-Aided Design 26, 1994: a layer of
//! height h on a surface whose normal makes angle θ with the build direction leaves a cusp
//! h·|cos θ|, kept under E; the rule PrusaSlicer's variable layer height starts from).

use crate::error::{Error, Result};

/// One layer: its mid-height along the build direction (where it is cut) and its thickness, mm.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Layer {
    /// Mid-height, mm.
    pub z: f64,
    /// Thickness, mm.
    pub thickness: f64,
}

impl Layer {
    /// Height of the layer's bottom.
    pub fn bottom(&self) -> f64 {
        self.z - 0.5 * self.thickness
    }

    /// Height of the layer's top.
    pub fn top(&self) -> f64 {
        self.z + 0.5 * self.thickness
    }
}

/// How layers are chosen.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(tag = "rule", rename_all = "lowercase")]
pub enum Rule {
    /// Every layer `layer` thick (the first `first` thick).
    Uniform {
        /// Thickness, mm.
        layer: f64,
        /// First layer's thickness, mm.
        first: f64,
    },
    /// Area change between layers within `c` (relative), layers from `min` to `max`.
    Area {
        /// Largest relative change of area kept.
        c: f64,
        /// Thinnest layer, mm.
        min: f64,
        /// Thickest layer, mm.
        max: f64,
    },
    /// Cusp height within `cusp`, layers from `min` to `max`.
    Cusp {
        /// Largest cusp, mm.
        cusp: f64,
        /// Thinnest layer, mm.
        min: f64,
        /// Thickest layer, mm.
        max: f64,
    },
}

impl Rule {
    /// Refuses settings that cannot make layers.
    pub fn validate(&self) -> Result<()> {
        let pos = |v: f64, what: &str| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(Error::invalid(format!(
                    "{what} must be a positive length in mm, got {v}"
                )))
            }
        };
        match *self {
            Rule::Uniform { layer, first } => {
                pos(layer, "the layer thickness")?;
                pos(first, "the first layer's thickness")
            }
            Rule::Area { c, min, max } | Rule::Cusp { cusp: c, min, max } => {
                pos(
                    c,
                    if matches!(self, Rule::Area { .. }) {
                        "C"
                    } else {
                        "the cusp height"
                    },
                )?;
                pos(min, "the minimum layer")?;
                pos(max, "the maximum layer")?;
                if min > max {
                    return Err(Error::invalid(format!(
                        "the minimum layer ({min} mm) is thicker than the maximum ({max} mm)"
                    )));
                }
                Ok(())
            }
        }
    }
}

/// What adaptive rules need to know of the part.
pub trait Profile {
    /// Cross-section area at height `z`, mm².
    fn area(&self, z: f64) -> f64;
    /// The largest `|cos θ|` (normal against build direction) of the surface between heights
    /// `z0` and `z1`; 0 where there is none.
    fn steepest_cos(&self, z0: f64, z1: f64) -> f64;
}

/// Most layers a plan may have (a 1 m part at 1 µm).
pub const MAX_LAYERS: usize = 1_000_000;

/// The layers covering heights `lo..hi` by `rule`. The last layer may reach past `hi`
/// (uniform) or is cut short at `hi` (adaptive, never below the minimum).
pub fn plan(rule: &Rule, lo: f64, hi: f64, profile: &dyn Profile) -> Result<Vec<Layer>> {
    rule.validate()?;
    let mut layers = Vec::new();
    let mut b = lo;
    let push = |layers: &mut Vec<Layer>, b: f64, t: f64| -> Result<()> {
        if layers.len() >= MAX_LAYERS {
            return Err(Error::invalid(format!(
                "more than {MAX_LAYERS} layers over {:.4} mm: use thicker layers",
                hi - lo
            )));
        }
        layers.push(Layer {
            z: b + 0.5 * t,
            thickness: t,
        });
        Ok(())
    };
    match *rule {
        Rule::Uniform { layer, first } => {
            let n_est = ((hi - lo - first) / layer).max(0.0) + 2.0;
            if n_est > MAX_LAYERS as f64 {
                return Err(Error::invalid(format!(
                    "{layer} mm layers over {:.4} mm make more than {MAX_LAYERS} layers",
                    hi - lo
                )));
            }
            let mut t = first;
            let mut k = 0usize;
            // A bottom within rounding of the top starts no layer.
            let end = hi - 1e-9 * (hi - lo).abs().max(1.0);
            while b < end || layers.is_empty() {
                push(&mut layers, b, t)?;
                k += 1;
                // Bottoms from the start and a count, not by summing: no drift over many layers.
                b = lo + first + (k - 1) as f64 * layer;
                t = layer;
            }
        }
        Rule::Area { c, min, max } => {
            let mut prev = profile.area(lo + 0.5 * min.min(hi - lo));
            while b < hi {
                let room = hi - b;
                let mut t = max.min(room.max(min));
                let s = loop {
                    let s = profile.area(b + 0.5 * t);
                    if t <= min || (s - prev).abs() <= c * s {
                        break s;
                    }
                    t = (0.5 * t).max(min);
                };
                push(&mut layers, b, t)?;
                prev = s;
                b += t;
            }
        }
        Rule::Cusp { cusp, min, max } => {
            while b < hi {
                let room = hi - b;
                let mut t = max.min(room.max(min));
                loop {
                    let cos = profile.steepest_cos(b, b + t);
                    let allowed = if cos > 0.0 { cusp / cos } else { f64::INFINITY };
                    if allowed >= t {
                        break;
                    }
                    t = allowed.max(min);
                    if t <= min {
                        break;
                    }
                }
                push(&mut layers, b, t)?;
                b += t;
            }
        }
    }
    Ok(layers)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere of radius 1 at the origin, analytically.
    struct Ball;
    impl Profile for Ball {
        fn area(&self, z: f64) -> f64 {
            std::f64::consts::PI * (1.0 - z * z).max(0.0)
        }
        fn steepest_cos(&self, z0: f64, z1: f64) -> f64 {
            z0.abs().max(z1.abs()).min(1.0)
        }
    }

    #[test]
    fn uniform_layers_tile_the_height_without_drift() {
        let r = Rule::Uniform {
            layer: 0.1,
            first: 0.3,
        };
        let l = plan(&r, 0.0, 10.0, &Ball).unwrap();
        assert_eq!(l.len(), 98);
        assert!((l[0].z - 0.15).abs() < 1e-12 && (l[1].z - 0.35).abs() < 1e-12);
        for w in l.windows(2) {
            assert!((w[0].top() - w[1].bottom()).abs() < 1e-9);
        }
        assert!(l.last().unwrap().top() >= 10.0 - 1e-9);
    }

    #[test]
    fn adaptive_layers_are_thin_at_the_poles_and_thick_at_the_equator() {
        for rule in [
            Rule::Area {
                c: 0.1,
                min: 0.01,
                max: 0.16,
            },
            Rule::Cusp {
                cusp: 0.01,
                min: 0.01,
                max: 0.16,
            },
        ] {
            let l = plan(&rule, -1.0, 1.0, &Ball).unwrap();
            let mid = l
                .iter()
                .min_by(|a, b| a.z.abs().total_cmp(&b.z.abs()))
                .unwrap();
            assert!(
                l[0].thickness < 0.03 && l.last().unwrap().thickness < 0.03,
                "{rule:?}"
            );
            assert!(mid.thickness > 0.1, "{rule:?} {mid:?}");
        }
        assert!(plan(
            &Rule::Area {
                c: 0.1,
                min: 0.2,
                max: 0.1
            },
            0.0,
            1.0,
            &Ball
        )
        .is_err());
    }
}
