//! Overlap bounds of the polyhedral bed's checks, for the contact law of the variant's scene: Hertz–Mindlin
//! (variants a, b: stiffness from Young's moduli) or linear spring–dashpot (variant c: one k_n per pair).
//!
//! Two bounds, each the overlap at which one contact of the softest pair would hold a whole budget:
//! - static: the bed's whole weight on one contact of the two smallest grains (no contact of a settled bed
//!   carries more);
//! - dynamic: the projectile's whole initial kinetic energy stored in one contact (no contact of the run can
//!   be deeper without energy coming from nowhere; the settled bed's own potential-energy drop is orders of
//!   magnitude smaller).

use polydem::law::hertz_mindlin::{effective_young_modulus, ElasticMaterial};
use polydem::math::Real;

/// The normal law of the bed's contacts, read from the scene text.
#[derive(Clone, Debug, PartialEq)]
pub enum BedLaw {
    /// Hertz: f = (4/3) E* √R* δ^(3/2); `e_bed` of a bed–bed pair, `e_min` the smallest E* of the bed's pairs.
    Hertz { e_bed: Real, e_min: Real },
    /// Linear: f = k_n δ; `k_bed` of a bed–bed pair, `k_min` the smallest k_n of the bed's pairs.
    Linear { k_bed: Real, k_min: Real },
}

impl BedLaw {
    /// Reads the `bed`–`bed` and `bed`–`steel` interactions (and the materials' elastic constants for
    /// Hertz–Mindlin) of a scene file's text.
    pub fn from_scene(text: &str) -> Result<Self, String> {
        let table: toml::Table =
            toml::from_str(text).map_err(|e| format!("scene template: {e}"))?;
        let interactions = table
            .get("interaction")
            .and_then(toml::Value::as_array)
            .ok_or("scene template: no [[interaction]]")?;
        let find = |a: &str, b: &str| -> Result<&toml::Table, String> {
            interactions
                .iter()
                .filter_map(toml::Value::as_table)
                .find(|t| {
                    let names: Vec<&str> = t
                        .get("materials")
                        .and_then(toml::Value::as_array)
                        .map(|m| m.iter().filter_map(toml::Value::as_str).collect())
                        .unwrap_or_default();
                    names == [a, b] || names == [b, a]
                })
                .ok_or_else(|| format!("scene template: no interaction of {a} and {b}"))
        };
        let (bed_bed, bed_steel) = (find("bed", "bed")?, find("bed", "steel")?);
        match (law_name(bed_bed), law_name(bed_steel)) {
            ("hertz_mindlin", "hertz_mindlin") => {
                let bed = elastic(&table, "bed")?;
                let steel = elastic(&table, "steel")?;
                let e_bed = effective_young_modulus(&bed, &bed);
                let e_min = e_bed.min(effective_young_modulus(&bed, &steel));
                Ok(Self::Hertz { e_bed, e_min })
            }
            ("linear", "linear") => {
                let k = |t: &toml::Table| {
                    t.get("normal_stiffness")
                        .and_then(toml::Value::as_float)
                        .ok_or_else(|| "scene template: linear interaction lacks normal_stiffness".to_owned())
                };
                let (k_bed, k_steel) = (k(bed_bed)?, k(bed_steel)?);
                Ok(Self::Linear { k_bed, k_min: k_bed.min(k_steel) })
            }
            (a, b) => Err(format!(
                "scene template: laws '{a}' (bed–bed) and '{b}' (bed–steel): expected both hertz_mindlin or both linear"
            )),
        }
    }

    /// Overlap of one bed–bed contact of effective radius `r_star` carrying the force `weight` (N).
    pub fn static_overlap(&self, weight: Real, r_star: Real) -> Real {
        match *self {
            Self::Hertz { e_bed, .. } => {
                (weight / (4.0 / 3.0 * e_bed * r_star.sqrt())).powf(2.0 / 3.0)
            }
            Self::Linear { k_bed, .. } => weight / k_bed,
        }
    }

    /// Overlap at which one contact of the softest pair (effective radius `r_star`) stores the energy `w` (J):
    /// w = (8/15) E* √R* δ^(5/2) for Hertz, w = ½ k_n δ² for the linear law.
    pub fn energy_overlap(&self, w: Real, r_star: Real) -> Real {
        match *self {
            Self::Hertz { e_min, .. } => (15.0 * w / (8.0 * e_min * r_star.sqrt())).powf(0.4),
            Self::Linear { k_min, .. } => (2.0 * w / k_min).sqrt(),
        }
    }

    /// How the two bounds are computed, for the report's units column.
    pub fn describe(&self) -> &'static str {
        match self {
            Self::Hertz { .. } => "Hertz",
            Self::Linear { .. } => "linear spring",
        }
    }
}

/// The `law` key of an interaction table ("" when missing: the match above then reports it).
fn law_name(t: &toml::Table) -> &str {
    t.get("law").and_then(toml::Value::as_str).unwrap_or("")
}

/// Young's modulus and Poisson's ratio of material `name` of a scene table.
fn elastic(table: &toml::Table, name: &str) -> Result<ElasticMaterial, String> {
    let m = table
        .get("material")
        .and_then(toml::Value::as_array)
        .and_then(|a| {
            a.iter()
                .find(|m| m.get("name").and_then(toml::Value::as_str) == Some(name))
        })
        .ok_or_else(|| format!("scene template: no material '{name}'"))?;
    let f = |key: &str| {
        m.get(key)
            .and_then(toml::Value::as_float)
            .ok_or_else(|| format!("scene template: material '{name}' lacks {key}"))
    };
    ElasticMaterial::new(f("young_modulus")?, f("poisson_ratio")?)
        .map_err(|e| format!("material '{name}': {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each bound is the overlap that stores/carries its budget: check by putting it back into the law.
    #[test]
    fn bounds_invert_their_laws() {
        let r = 1.0e-3;
        let hertz = BedLaw::Hertz {
            e_bed: 5.0e8,
            e_min: 4.0e8,
        };
        let linear = BedLaw::Linear {
            k_bed: 2.0e5,
            k_min: 1.5e5,
        };
        let (w, f) = (0.3, 2.0);
        let d = hertz.static_overlap(f, r);
        let back = 4.0 / 3.0 * 5.0e8 * r.sqrt() * d.powf(1.5);
        assert!(
            (back / f - 1.0).abs() < 1e-12,
            "Hertz static: force {back} for {f} (δ = {d})"
        );
        let d = hertz.energy_overlap(w, r);
        let back = 8.0 / 15.0 * 4.0e8 * r.sqrt() * d.powf(2.5);
        assert!(
            (back / w - 1.0).abs() < 1e-12,
            "Hertz energy: {back} J for {w} J (δ = {d})"
        );
        let d = linear.static_overlap(f, r);
        assert!(
            (2.0e5 * d / f - 1.0).abs() < 1e-12,
            "linear static: δ = {d}"
        );
        let d = linear.energy_overlap(w, r);
        assert!(
            (0.5 * 1.5e5 * d * d / w - 1.0).abs() < 1e-12,
            "linear energy: δ = {d}"
        );
    }

    #[test]
    fn reads_the_laws_of_the_sphere_bed_scenes() {
        let root = crate::provenance::workspace_root();
        for (file, linear) in [
            ("scenes/sphere_bed_a_hertz_5ms.toml", false),
            ("scenes/sphere_bed_b_hertz_200ms.toml", false),
            ("scenes/sphere_bed_c_linear_5ms.toml", true),
        ] {
            let text = std::fs::read_to_string(root.join(file)).expect(file);
            let law = BedLaw::from_scene(&text).unwrap_or_else(|e| panic!("{file}: {e}"));
            assert_eq!(
                matches!(law, BedLaw::Linear { .. }),
                linear,
                "{file}: {law:?}"
            );
        }
    }
}
