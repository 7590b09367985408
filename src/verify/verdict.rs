//! The verdict every command gives on a mesh: is it a valid closed, outward solid? One type, one
//! rule, one exit code, whichever check (latvox's own, CGAL's, or both) made the findings.

use crate::verify::cgal::Verification;

/// What a check found on the properties that make a mesh a printable solid.
///
/// Each property is `true` when it holds. A check that does not look at a property leaves it
/// `true` (CGAL does not look at stored normals, so its verdict has `sound_facets`), and
/// [`Verdict::and`] joins the verdicts of two checks on the same mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Verdict {
    /// No boundary edge: no hole.
    pub closed: bool,
    /// Every edge in exactly two facets, every vertex in one fan.
    pub manifold: bool,
    /// Wound consistently, every shell facing out of the material (a cavity into it).
    pub outward: bool,
    /// Whether self-intersections were looked for.
    pub self_intersection_checked: bool,
    /// Some two facets intersect.
    pub self_intersecting: bool,
    /// At least one facet, none degenerate or repeated, no T-junction, and stored normals that
    /// agree with the winding.
    pub sound_facets: bool,
    /// One connected piece, for parts that must be one (`None`: not asked).
    pub one_piece: Option<bool>,
    /// The volume fraction asked for, within 0.002, for parts made to a density (`None`: not
    /// asked).
    pub density_met: Option<bool>,
    /// No feature thinner than the printer's minimum, no island and no point contact, for parts
    /// cleaned to a printer's limits (`None`: not asked).
    pub features_printable: Option<bool>,
}

impl Verdict {
    /// The verdict of beams (3MF capsules, valid by definition: no surface to check), whose
    /// radius was found on a meshed part that met its density or not (`None`: no density
    /// asked).
    pub fn of_beams(density_met: Option<bool>) -> Verdict {
        Verdict {
            closed: true,
            manifold: true,
            outward: true,
            self_intersection_checked: false,
            self_intersecting: false,
            sound_facets: true,
            one_piece: None,
            density_met,
            features_printable: None,
        }
    }

    /// A valid closed, outward solid: every property holds (self-intersections count only when
    /// they were looked for).
    pub fn is_valid_solid(&self) -> bool {
        self.closed
            && self.manifold
            && self.outward
            && !self.self_intersecting
            && self.sound_facets
            && self.one_piece != Some(false)
            && self.density_met != Some(false)
            && self.features_printable != Some(false)
    }

    /// The process exit code for this verdict: 0 for a valid solid, 1 when defects were found.
    pub fn exit_code(&self) -> i32 {
        if self.is_valid_solid() {
            0
        } else {
            1
        }
    }

    /// The verdict of two checks of the same mesh: a property holds only if it holds for both.
    pub fn and(self, o: Verdict) -> Verdict {
        Verdict {
            closed: self.closed && o.closed,
            manifold: self.manifold && o.manifold,
            outward: self.outward && o.outward,
            self_intersection_checked: self.self_intersection_checked
                || o.self_intersection_checked,
            self_intersecting: self.self_intersecting || o.self_intersecting,
            sound_facets: self.sound_facets && o.sound_facets,
            one_piece: both(self.one_piece, o.one_piece),
            density_met: both(self.density_met, o.density_met),
            features_printable: both(self.features_printable, o.features_printable),
        }
    }
}

/// A property two checks may each have looked at: it holds if it holds for every check that did.
fn both(a: Option<bool>, b: Option<bool>) -> Option<bool> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a && b),
        (a, None) => a,
        (None, b) => b,
    }
}

impl From<&Verification> for Verdict {
    /// CGAL's findings.
    fn from(v: &Verification) -> Verdict {
        Verdict {
            closed: v.closed,
            manifold: v.manifold,
            outward: v.outward,
            self_intersection_checked: v.self_intersection_checked,
            self_intersecting: v.self_intersecting,
            sound_facets: true,
            one_piece: None,
            density_met: None,
            features_printable: None,
        }
    }
}

/// Serialises a verdict as the one `valid_solid` flag that reports carry.
pub(crate) fn valid_solid<S: serde::Serializer>(v: &Verdict, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_bool(v.is_valid_solid())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn valid() -> Verdict {
        Verdict {
            closed: true,
            manifold: true,
            outward: true,
            self_intersection_checked: true,
            self_intersecting: false,
            sound_facets: true,
            one_piece: None,
            density_met: None,
            features_printable: None,
        }
    }

    #[test]
    fn every_property_counts_and_joined_checks_agree_on_both() {
        let ok = valid();
        assert!(ok.is_valid_solid() && ok.exit_code() == 0);
        let unchecked = Verdict {
            self_intersection_checked: false,
            ..ok
        };
        assert!(unchecked.is_valid_solid());
        for bad in [
            Verdict {
                closed: false,
                ..ok
            },
            Verdict {
                manifold: false,
                ..ok
            },
            Verdict {
                outward: false,
                ..ok
            },
            Verdict {
                self_intersecting: true,
                ..ok
            },
            Verdict {
                sound_facets: false,
                ..ok
            },
            Verdict {
                one_piece: Some(false),
                ..ok
            },
            Verdict {
                density_met: Some(false),
                ..ok
            },
            Verdict {
                features_printable: Some(false),
                ..ok
            },
        ] {
            assert!(!bad.is_valid_solid() && bad.exit_code() == 1, "{bad:?}");
            assert!(!ok.and(bad).is_valid_solid() && !bad.and(ok).is_valid_solid());
        }
        let joined = unchecked.and(Verdict {
            one_piece: Some(true),
            ..ok
        });
        assert!(joined.self_intersection_checked && joined.one_piece == Some(true));
        assert!(joined.is_valid_solid());
    }
}
