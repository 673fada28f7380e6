//! Ellipsoid impacts: the shape seam checked end to end. Ellipsoids come from a scene file, their contacts
//! from the generic support-map arm (and the convex–plane closed form against a wall), their forces from
//! the same laws as every other shape. Checked: kinetic-energy conservation of an elastic oblique impact
//! (bounded by (ω_max Δt)²), and the restitution of central impacts against the input e (the bound derived
//! for velocity Verlet in [`super::restitution_bound`]). The energy error at 2N steps per contact is reported beside N's, not gated: it
//! does not fall with Δt (see the data file). Parameters and sources in `validation/cases/ellipsoid_impact.toml`.

use std::path::Path;

use polydem::law::NormalLaw;
use polydem::math::{Real, Rotation, Vector};
use polydem::scene::{parse_scene, Simulation};

use super::restitution_bound::restitution_error_bound;
use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;

pub struct EllipsoidImpact;

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    steps_per_contact: Real,
    restitution_steps_per_contact: Real,
    restitutions: Vec<Real>,
}

const SEMI_AXES: [Real; 3] = [0.03, 0.02, 0.015];
const DENSITY: Real = 2500.0;
const SPEED: Real = 0.5;
/// The normal law f = k δ^n of every contact.
const STIFFNESS: Real = 1.0e8;
const EXPONENT: Real = 1.5;
/// The rotation vector (rad) of the oblique impact's first body.
const TURN: [Real; 3] = [0.3, 0.5, -0.4];

fn case_error(msg: String) -> SuiteError {
    SuiteError::case("ellipsoid_impact", msg)
}

/// One impact: the scene's bodies, its restitution, steps per contact; `wall` puts a wall at x = 0 instead
/// of the second ellipsoid.
struct Impact {
    restitution: Real,
    steps_per_contact: Real,
    oblique: bool,
    wall: bool,
}

impl Impact {
    fn scene(&self) -> String {
        let [a, b, c] = SEMI_AXES;
        let mut s = format!(
            "[simulation]\ngravity = [0.0, 0.0, 0.0]\nend_time = 1.0\noutput_interval = 1.0\n\
             steps_per_contact = {n}\ncharacteristic_speed = {v}\n\n\
             [[material]]\nname = \"grain\"\ndensity = {DENSITY}\n\n\
             [[interaction]]\nmaterials = [\"grain\", \"grain\"]\nlaw = \"power\"\nexponent = {EXPONENT:?}\n\
             normal_stiffness = {STIFFNESS:e}\nrestitution = {e}\nfriction = 0.0\n\n\
             [[shape]]\nname = \"egg\"\nkind = \"ellipsoid\"\nsemi_axes = [{a}, {b}, {c}]\n\n",
            n = self.steps_per_contact,
            v = 2.0 * SPEED,
            e = self.restitution,
        );
        // Body a moves along +x; the gap before contact is 1 mm: its extent along +x, turned or not, is its
        // support h(x̂) = |diag(a, b, c) Rᵀ x̂|.
        let (turn, extent) = if self.oblique {
            let r = Rotation::from_scaled_axis(Vector::from(TURN));
            let n = r.inverse_transform_vector(&Vector::x());
            let h = Vector::new(a * n.x, b * n.y, c * n.z).norm();
            (format!("axis_angle = {TURN:?}\n"), h)
        } else {
            (String::new(), a)
        };
        s += &format!(
            "[[body]]\nname = \"a\"\nshape = \"egg\"\nmaterial = \"grain\"\nposition = [{x}, 0.0, 0.0]\n\
             {turn}velocity = [{SPEED}, 0.0, 0.0]\n\n",
            x = -(extent + 0.001)
        );
        if self.wall {
            s += "[[wall]]\nname = \"floor\"\nmaterial = \"grain\"\npoint = [0.0, 0.0, 0.0]\nnormal = [-1.0, 0.0, 0.0]\n";
        } else {
            // Off-centre by a third of b when oblique, so that both bodies spin.
            let y = if self.oblique { b / 3.0 } else { 0.0 };
            s += &format!(
                "[[body]]\nname = \"b\"\nshape = \"egg\"\nmaterial = \"grain\"\nposition = [{a}, {y}, 0.0]\n\
                 velocity = [{v}, 0.0, 0.0]\n",
                v = -SPEED
            );
        }
        s
    }

    /// Runs the impact to well after separation; returns the simulation at the end.
    fn run(&self) -> Result<Simulation, SuiteError> {
        let text = self.scene();
        let mut sim = parse_scene(&text, Path::new("ellipsoid_impact.toml"))
            .map_err(|e| case_error(format!("scene: {e}")))?;
        // Up to 5 mm of closing at the relative speed (the off-centre surfaces meet later than the 1 mm
        // gap along the axis), the contact, then apart.
        let relative = if self.wall { SPEED } else { 2.0 * SPEED };
        let end = 0.005 / relative + 3.0 * sim.time_step.contact_time;
        sim.set_end_time(end)
            .map_err(|e| case_error(format!("end time: {e}")))?;
        sim.run(|_| Ok(()), |_, _| Ok(()))
            .map_err(|e| case_error(format!("run: {e}")))?;
        Ok(sim)
    }
}

fn kinetic_energy(sim: &Simulation) -> Real {
    sim.world
        .bodies()
        .iter()
        .map(|b| b.translational_kinetic_energy() + b.rotational_kinetic_energy())
        .sum()
}

fn active_contacts(sim: &Simulation) -> usize {
    sim.world
        .contacts()
        .states()
        .iter()
        .filter(|s| s.is_active())
        .count()
}

/// |T_end − T_0| / T_0 of the elastic oblique impact, and its bound (ω_max Δt)² (see the data file).
fn energy_error(steps_per_contact: Real) -> Result<(Real, Real, usize), SuiteError> {
    let impact = Impact {
        restitution: 1.0,
        steps_per_contact,
        oblique: true,
        wall: false,
    };
    let initial = impact.run_initial_energy()?;
    let sim = impact.run()?;
    let body = &sim.world.bodies()[0];
    let radius = SEMI_AXES.iter().cloned().fold(0.0, Real::max);
    let j_min = body.inertia.0.min();
    // Two equal bodies: m* = m/2; the eccentric lever arm adds R²/J per body.
    let m_eff = 1.0 / (2.0 / body.mass + 2.0 * radius * radius / j_min);
    let m_star = body.mass / 2.0;
    // The contact time is set by m*; the fastest oscillation by m_eff: ω_max = ω* √(m*/m_eff).
    let omega_star = std::f64::consts::PI / sim.time_step.contact_time;
    let omega_max = omega_star * (m_star / m_eff).sqrt();
    let bound = (omega_max * sim.params.dt).powi(2);
    Ok((
        (kinetic_energy(&sim) - initial).abs() / initial,
        bound,
        active_contacts(&sim),
    ))
}

impl Impact {
    fn run_initial_energy(&self) -> Result<Real, SuiteError> {
        let sim = parse_scene(&self.scene(), Path::new("ellipsoid_impact.toml"))
            .map_err(|e| case_error(format!("scene: {e}")))?;
        Ok(kinetic_energy(&sim))
    }
}

/// The measured restitution of a central impact (the relative normal velocity after over before), Δt over
/// the impact's own elastic contact time, and the contacts left at the end.
fn restitution(
    e: Real,
    steps_per_contact: Real,
    wall: bool,
) -> Result<(Real, Real, usize), SuiteError> {
    let impact = Impact {
        restitution: e,
        steps_per_contact,
        oblique: false,
        wall,
    };
    let sim = impact.run()?;
    let bodies = sim.world.bodies();
    let (after, before, m_star) = if wall {
        (-bodies[0].velocity.x, SPEED, bodies[0].mass)
    } else {
        let m_star = bodies[0].mass * bodies[1].mass / (bodies[0].mass + bodies[1].mass);
        (
            bodies[1].velocity.x - bodies[0].velocity.x,
            2.0 * SPEED,
            m_star,
        )
    };
    // The scene's time step is set at its characteristic speed for the lightest pair; the bound needs the
    // contact time of this impact.
    let law = NormalLaw::new(STIFFNESS, EXPONENT).map_err(|err| case_error(err.to_string()))?;
    let contact_time = law.elastic_contact_time(m_star, before);
    Ok((
        after / before,
        sim.params.dt / contact_time,
        active_contacts(&sim),
    ))
}

impl Case for EllipsoidImpact {
    fn name(&self) -> &'static str {
        "ellipsoid_impact"
    }

    fn data(&self) -> &'static str {
        include_str!("../../cases/ellipsoid_impact.toml")
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(self.name(), profile)?;
        let bound_factor = data.tolerance(self.name(), "energy_bound")?.value;
        let over_bound = data.tolerance(self.name(), "first_order_bound")?.value;
        ctx.progress()
            .stage("impacts", 2 + 2 * p.restitutions.len() as u64);
        let mut rows = Vec::new();
        let (coarse, bound, left) = energy_error(p.steps_per_contact)?;
        ctx.progress().inc(1);
        let (fine, _, _) = energy_error(2.0 * p.steps_per_contact)?;
        ctx.progress().inc(1);
        ctx.check(
            "elastic_energy_error",
            coarse,
            Target::at_most(bound_factor * bound),
            "1",
        );
        ctx.check(
            "elastic_separated_at_end",
            (left == 0) as u8 as f64,
            Target::equal(1.0),
            "1",
        );
        rows.push(vec![
            "elastic, oblique".into(),
            format!("{}", p.steps_per_contact),
            "1".into(),
            format!(
                "|ΔT|/T = {} (2N: {}; bound {})",
                CaseContext::fmt(coarse),
                CaseContext::fmt(fine),
                CaseContext::fmt(bound_factor * bound)
            ),
        ]);
        for &e in &p.restitutions {
            for wall in [false, true] {
                let (measured, dt_over_tc, left) =
                    restitution(e, p.restitution_steps_per_contact, wall)?;
                ctx.progress().inc(1);
                let against = if wall { "wall" } else { "ellipsoid" };
                let tag = format!("{against}_e_{e}");
                let bound = restitution_error_bound(EXPONENT, e, dt_over_tc).map_err(case_error)?;
                ctx.check(
                    &format!("restitution_error_{tag}"),
                    (measured - e).abs() / e,
                    Target::at_most(over_bound * bound),
                    "1",
                );
                ctx.check(
                    &format!("separated_at_end_{tag}"),
                    (left == 0) as u8 as f64,
                    Target::equal(1.0),
                    "1",
                );
                rows.push(vec![
                    format!("central, against {against}"),
                    format!("{}", p.restitution_steps_per_contact),
                    format!("{e}"),
                    format!(
                        "e = {measured:.6} (bound ±{})",
                        CaseContext::fmt(over_bound * bound * e)
                    ),
                ]);
            }
        }
        ctx.section("Impacts");
        ctx.text(&data.description);
        ctx.table(
            Some("impacts"),
            &["impact", "steps per contact", "input e", "measured"],
            &rows,
        )?;
        Ok(())
    }
}
