//! The registry of cases. Adding a case: a module here implementing [`Case`], its data file
//! `validation/cases/<name>.toml`, and one line in [`registry`].

use crate::case::Case;

pub mod chung_ooi;
pub mod contact;
pub mod ellipsoid_impact;
pub mod friction;
pub mod polyhedra_bed;
pub mod polyhedra_box;
pub mod precession;
pub mod projectile_history;
pub mod restitution;
mod restitution_bound;
pub mod rockfill;
mod rockfill_dt_spread;
pub mod single_contact_energy;
pub mod sphere_bed;
pub mod stress_impact;
pub mod stress_long_run;
pub mod stress_shapes;
pub mod stress_time_step;
pub mod stress_util;

/// Every case of the suite, in the order they run.
pub fn registry() -> Vec<&'static dyn Case> {
    vec![
        &contact::Contact,
        &precession::Precession,
        &single_contact_energy::SingleContactEnergy,
        &restitution::Restitution,
        &ellipsoid_impact::EllipsoidImpact,
        &chung_ooi::ChungOoi,
        &friction::Friction,
        &rockfill::Rockfill,
        &sphere_bed::SphereBed,
        &polyhedra_bed::PolyhedraBed,
        &polyhedra_box::PolyhedraBox,
        &stress_long_run::StressLongRun,
        &stress_impact::StressImpact,
        &stress_shapes::StressShapes,
        &stress_time_step::StressTimeStep,
    ]
}
