//! Restitution: the measured coefficient of restitution of normal impacts equals the input
//! of the damping law, for sphere–sphere, sphere–wall and a cube face-on on a wall (through the contact
//! core), with the linear and the Hertz-type law, over a range of input e. A time-step sweep gates the
//! error against its bound, derived for velocity Verlet in [`super::restitution_bound`].

use std::sync::Arc;

use polydem::contact::{query, EpaScratch, PairCache, QueryCounters};
use polydem::dynamics::{Motion, PrincipalInertia, RigidBody};
use polydem::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
use polydem::math::{Point, Real, Rotation, Vector};
use polydem::shape::{ConvexPolyhedron, Plane, Shape};

use super::restitution_bound::restitution_error_bound;
use crate::case::{Case, CaseData, Profile, Target};
use crate::cases::single_contact_energy::{body_of, pose};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};
use crate::sim::two_body::{impact, sphere_sphere, wall_sphere};

const RADIUS: Real = 0.05;
const SIDE: Real = 0.2;
const DENSITY: Real = 2600.0;
const SPEED: Real = 1.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pair {
    SphereSphere,
    SphereWall,
    CubeFaceWall,
}

impl Pair {
    fn tag(self) -> &'static str {
        match self {
            Pair::SphereSphere => "sphere_sphere",
            Pair::SphereWall => "sphere_wall",
            Pair::CubeFaceWall => "cube_face_wall",
        }
    }
}

const PAIRS: [Pair; 3] = [Pair::SphereSphere, Pair::SphereWall, Pair::CubeFaceWall];

/// The input restitutions of the time-step sweep.
const SWEPT_RESTITUTIONS: [Real; 3] = [0.1, 0.3, 0.7];

/// (name, tag, normal law): linear k_n = 1e6 N/m, Hertz-type k_n = 1e9 N/m^1.5 (chosen by us; the
/// restitution does not depend on them).
fn laws() -> [(&'static str, &'static str, NormalLaw); 2] {
    [
        ("linear", "linear", NormalLaw::linear(1e6).expect("k > 0")),
        ("Hertz-type", "hertz", NormalLaw::hertz(1e9).expect("k > 0")),
    ]
}

fn sphere_body(z: Real, vz: Real) -> RigidBody {
    let mass = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
    let inertia =
        PrincipalInertia::new(Vector::repeat(0.4 * mass * RADIUS * RADIUS)).expect("I > 0");
    let mut b = RigidBody::new_dynamic(Point::new(0.0, 0.0, z), mass, inertia).expect("body");
    b.velocity = Vector::new(0.0, 0.0, vz);
    b
}

fn cube() -> Arc<ConvexPolyhedron> {
    let h = 0.5 * SIDE;
    let mut corners = Vec::new();
    for sx in [-h, h] {
        for sy in [-h, h] {
            for sz in [-h, h] {
                corners.push(Point::new(sx, sy, sz));
            }
        }
    }
    Arc::new(
        ConvexPolyhedron::from_points(&corners)
            .expect("cube hull")
            .0,
    )
}

/// Measured restitution of one normal impact at SPEED with input `restitution`, dt = t_c/`per_contact`.
pub fn measure(
    pair: Pair,
    law: NormalLaw,
    restitution: Real,
    per_contact: Real,
) -> Result<Real, String> {
    let model = ContactModel {
        normal: law,
        damping: DampingLaw::from_restitution(law.exponent, restitution)
            .map_err(|e| e.to_string())?,
        tangential: TangentialLaw::None,
    };
    let gap = 1e-3 * RADIUS;
    let outcome = match pair {
        Pair::SphereSphere => {
            let a = sphere_body(0.0, 0.5 * SPEED);
            let b = sphere_body(2.0 * RADIUS + gap, -0.5 * SPEED);
            let m_star = 0.5 * a.mass;
            let dt = law.elastic_contact_time(m_star, SPEED) / per_contact;
            impact(
                &model,
                a,
                b,
                m_star,
                dt,
                (20.0 * per_contact) as usize,
                |a, b| sphere_sphere(RADIUS, RADIUS, a, b),
            )
        }
        Pair::SphereWall => {
            let mut wall = sphere_body(0.0, 0.0);
            wall.motion = Motion::Fixed;
            let b = sphere_body(RADIUS + gap, -SPEED);
            let m_star = b.mass;
            let dt = law.elastic_contact_time(m_star, SPEED) / per_contact;
            impact(
                &model,
                wall,
                b,
                m_star,
                dt,
                (20.0 * per_contact) as usize,
                |_, b| wall_sphere(RADIUS, b),
            )
        }
        Pair::CubeFaceWall => {
            let shape_a = Shape::Plane(Plane::new(Vector::z(), 0.0).map_err(|e| e.to_string())?);
            let shape_b = Shape::Polyhedron(cube());
            let wall = body_of(&shape_a, Point::origin(), Rotation::identity());
            let mut b = body_of(
                &shape_b,
                Point::new(0.0, 0.0, 0.5 * SIDE + gap),
                Rotation::identity(),
            );
            b.velocity = Vector::new(0.0, 0.0, -SPEED);
            let m_star = b.mass;
            let dt = law.elastic_contact_time(m_star, SPEED) / per_contact;
            let (mut cache, mut scratch, mut counters) = (
                PairCache::default(),
                EpaScratch::default(),
                QueryCounters::default(),
            );
            let mut failure = None;
            let run = impact(
                &model,
                wall,
                b,
                m_star,
                dt,
                (20.0 * per_contact) as usize,
                |a, b| match query(
                    &pose(a),
                    &shape_a,
                    &pose(b),
                    &shape_b,
                    &mut cache,
                    &mut scratch,
                    &mut counters,
                ) {
                    Ok(g) => g,
                    Err(e) => {
                        failure = Some(e.to_string());
                        wall_sphere(0.0, b)
                    }
                },
            );
            if let Some(e) = failure {
                return Err(format!("contact query failed: {e}"));
            }
            run
        }
    };
    if !outcome.separated {
        return Err(format!(
            "{pair:?}, n = {}, e = {restitution}, dt = t_c/{per_contact}: the bodies did not separate",
            law.exponent
        ));
    }
    Ok((outcome.b.velocity - outcome.a.velocity).z / SPEED)
}

pub struct Restitution;

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// Input coefficients of restitution.
    restitutions: Vec<Real>,
    /// Steps per elastic contact time at which the 1 % bound is checked.
    check_at: Real,
    /// Steps per contact time of the dt sweep.
    steps_per_contact: Vec<Real>,
}

impl Case for Restitution {
    fn name(&self) -> &'static str {
        "restitution"
    }

    fn data(&self) -> &'static str {
        include_str!("../../cases/restitution.toml")
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let inputs = Inputs {
            p: data.params(self.name(), profile)?,
            tol: data.tolerance(self.name(), "restitution_rel")?.value,
            bound: data.tolerance(self.name(), "first_order_bound")?.value,
            reference: data.reference(self.name(), "restitution")?.value,
        };
        let p = &inputs.p;
        ctx.progress().stage(
            "impacts",
            (PAIRS.len() * 2 * (p.restitutions.len() + p.steps_per_contact.len() * 2)) as u64,
        );
        let mut found = Found::default();
        for (law_name, law_tag, law) in laws() {
            for pair in PAIRS {
                let run = Run {
                    pair,
                    law_name,
                    law_tag,
                    law,
                };
                measure_against_input(ctx, &inputs, &run, &mut found)?;
                sweep_time_step(ctx, &inputs, &run, &mut found)?;
            }
        }
        report(ctx, &inputs, found)
    }
}

/// The case's parameters and gates.
struct Inputs {
    p: Params,
    /// Gate on |e_measured/e_input − reference|.
    tol: Real,
    /// Gate on the measured error over its derived bound.
    bound: Real,
    reference: Real,
}

/// One pair under one law.
struct Run {
    pair: Pair,
    law_name: &'static str,
    law_tag: &'static str,
    law: NormalLaw,
}

/// The tables and series of the report.
#[derive(Default)]
struct Found {
    rows: Vec<Vec<String>>,
    measured_series: Vec<Series>,
    sweep_rows: Vec<Vec<String>>,
    sweep_series: Vec<Series>,
    /// The derived bound of each law and e of the sweep, against Δt/t_c.
    bound_series: Vec<Series>,
}

fn fail(msg: String) -> SuiteError {
    SuiteError::case("restitution", msg)
}

/// The measured restitution at every input e, at the checked time step; the largest error gated.
fn measure_against_input(
    ctx: &mut CaseContext,
    inputs: &Inputs,
    run: &Run,
    found: &mut Found,
) -> Result<(), SuiteError> {
    let Run {
        pair,
        law_name,
        law_tag,
        law,
    } = *run;
    let mut points = Vec::new();
    let mut worst: Real = 0.0;
    for &e in &inputs.p.restitutions {
        let measured = measure(pair, law, e, inputs.p.check_at).map_err(fail)?;
        let error = (measured / e - inputs.reference).abs();
        worst = worst.max(error);
        found.rows.push(vec![
            format!("{pair:?}"),
            law_name.to_string(),
            format!("{e}"),
            format!("{measured:.6}"),
            CaseContext::fmt(error),
        ]);
        points.push((e, measured));
        ctx.progress().inc(1);
    }
    ctx.check(
        &format!("restitution_rel_error_max_{}_{law_tag}", pair.tag()),
        worst,
        Target::at_most(inputs.tol),
        "1",
    );
    found.measured_series.push(Series {
        label: format!("{pair:?}, {law_name}"),
        style: SeriesStyle::Points,
        points,
    });
    Ok(())
}

/// The time-step sweep: the measured error over its first-order bound, gated at 1.
fn sweep_time_step(
    ctx: &mut CaseContext,
    inputs: &Inputs,
    run: &Run,
    found: &mut Found,
) -> Result<(), SuiteError> {
    let Run {
        pair,
        law_name,
        law_tag,
        law,
    } = *run;
    let mut ratio: Real = 0.0;
    for e in SWEPT_RESTITUTIONS {
        let mut points = Vec::new();
        let mut bounds = Vec::new();
        for &n in &inputs.p.steps_per_contact {
            let measured = measure(pair, law, e, n).map_err(fail)?;
            let error = (measured / e - 1.0).abs();
            let bound = restitution_error_bound(law.exponent, e, 1.0 / n).map_err(fail)?;
            ratio = ratio.max(error / bound);
            found.sweep_rows.push(vec![
                format!("{pair:?}"),
                law_name.to_string(),
                format!("{e}"),
                format!("{n}"),
                format!("{measured:.6}"),
                CaseContext::fmt(error),
                CaseContext::fmt(bound),
                format!("{:.3}", error / bound),
            ]);
            points.push((1.0 / n, error));
            bounds.push((1.0 / n, bound));
            ctx.progress().inc(1);
        }
        found.sweep_series.push(Series {
            label: format!("{pair:?}, {law_name}, e = {e}"),
            style: SeriesStyle::LinePoints,
            points,
        });
        // The bound depends on the law and e only: one line per law, drawn with its first pair.
        if pair == PAIRS[0] {
            found.bound_series.push(Series {
                label: format!("bound, {law_name}, e = {e}"),
                style: SeriesStyle::Line,
                points: bounds,
            });
        }
    }
    ctx.check(
        &format!("error_over_bound_max_{}_{law_tag}", pair.tag()),
        ratio,
        Target::at_most(inputs.bound),
        "1",
    );
    Ok(())
}

/// The two tables and plots.
fn report(ctx: &mut CaseContext, inputs: &Inputs, found: Found) -> Result<(), SuiteError> {
    let p = &inputs.p;
    let Found {
        rows,
        mut measured_series,
        sweep_rows,
        mut sweep_series,
        bound_series,
    } = found;
    ctx.section("Measured against input restitution");
    ctx.text(&format!(
            "Impact speed {SPEED} m/s, density {DENSITY} kg/m³, spheres of radius {RADIUS} m, cube of side {SIDE} m \
             face-on (contact core: plane–polyhedron path); dt = t_c/{} with t_c the elastic contact time.",
            p.check_at
        ));
    ctx.table(
        Some("restitution"),
        &["pair", "law", "e input", "e measured", "|e_meas/e_in − 1|"],
        &rows,
    )?;
    let diagonal: Vec<(Real, Real)> = p.restitutions.iter().map(|&e| (e, e)).collect();
    measured_series.push(Series {
        label: "input (e_measured = e_input)".into(),
        style: SeriesStyle::Line,
        points: diagonal,
    });
    ctx.plot(&Plot {
        name: "measured_vs_input".into(),
        title: "Measured against input coefficient of restitution".into(),
        x_label: "input e (1)".into(),
        y_label: "measured e (1)".into(),
        x_log: false,
        y_log: false,
        series: measured_series,
        caption: format!(
            "All pairs and laws at dt = t_c/{}; the line is e_measured = e_input.",
            p.check_at
        ),
    })?;
    ctx.section("Error against the time step");
    ctx.text(
            "Velocity Verlet errs on the restitution in two ways (derivation: \
             `validation/src/cases/restitution_bound.rs`). The forces at the end of a step see the velocity of \
             its middle, so the damping lags half a step: a systematic first-order loss, computed by integrating \
             the continuous impact with that lag. And each end of the contact falls inside a step whose force acts \
             up to a step early or late: for the linear law the damping force jumps there (c v₀ at the start, \
             c e v₀ at the end), ζ̂ π (Δt/t_c)(1 + e)/e; for the Hertz-type law it vanishes with δ^(1/4), a term of \
             order (Δt/t_c)^(5/4). Both grow against e as the damping grows (small e). The bound is their sum, \
             for every law and e; checked as max(error/bound) ≤ 1 (lines: the bound of each law and e).",
        );
    ctx.table(
        Some("dt_sweep"),
        &[
            "pair",
            "law",
            "e input",
            "t_c/Δt",
            "e measured",
            "|e_meas/e_in − 1|",
            "bound",
            "error/bound",
        ],
        &sweep_rows,
    )?;
    sweep_series.extend(bound_series);
    let swept: Vec<String> = SWEPT_RESTITUTIONS.iter().map(|e| e.to_string()).collect();
    ctx.plot(&Plot {
        name: "error_vs_dt".into(),
        title: "Restitution error against the time step".into(),
        x_label: "Δt / t_c".into(),
        y_label: "|e_measured/e_input − 1|".into(),
        x_log: true,
        y_log: true,
        series: sweep_series,
        caption: format!(
            "Each pair and law at e = {}, with the bound of each law and e. Errors of exactly 0 cannot be \
             shown on the log axis.",
            swept.join(", ")
        ),
    })?;
    Ok(())
}
