//! Friction: a cube on an incline sticks for tan θ < μ and slides with
//! a = g (sin θ − μ cos θ) otherwise; a sphere launched without spin ends rolling at v = 5v₀/7.
//!
//! Close to the friction angle (tan θ = 0.75 μ, 0.9 μ) the sticking is gated too, with the smoothed wall
//! depth (`polydem::contact::wall_depth`, band = the static overlap). The former deepest-vertex wall law is
//! run beside it and shown, not gated: it creeps (12× the sticking bound at 0.9 μ) because its single force
//! point jumps between the corners of the resting face and the rocking about it is barely damped.

use polydem::law::hertz_mindlin::{hertz_mindlin, ElasticMaterial, SpherePair};
use polydem::math::Real;

use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};
use crate::sim::incline::{slide, slide_with, DENSITY, G, SIDE, STIFFNESS};
use crate::sim::rolling::roll;
use polydem::contact::WallDepth;

/// Duration of each incline run (s).
const DURATION: Real = 0.5;
/// Rolling sphere: radius (m), density (kg/m³), Young's modulus (Pa), Poisson ratio, launch speed (m/s);
/// chosen by us (aluminium-like, as in tests/sphere_gates.rs).
const BALL: (Real, Real, Real, Real, Real) = (0.1, 2700.0, 7.0e10, 0.3, 1.0);

pub struct Friction;

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// tan θ / μ of the sliding runs (> 1).
    sliding_ratios: Vec<Real>,
    /// tan θ / μ of the gated sticking runs.
    sticking_ratios: Vec<Real>,
    /// tan θ / μ of the sticking runs close to the friction angle (gated; the former deepest-vertex wall law
    /// is also run there, shown and not gated).
    creep_ratios: Vec<Real>,
    /// Friction coefficients of the rolling sphere.
    rolling_frictions: Vec<Real>,
}

impl Case for Friction {
    fn name(&self) -> &'static str {
        "friction"
    }

    fn data(&self) -> &'static str {
        include_str!("../../cases/friction.toml")
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(self.name(), profile)?;
        let name = self.name();
        let g = Gates {
            mu: data.reference(name, "friction")?.value,
            fraction: data.reference(name, "rolling_fraction")?.value,
            sliding_tol: data.tolerance(name, "sliding_rel")?.value,
            stretch_factor: data.tolerance(name, "sticking_stretch_factor")?.value,
            tilt_tol: data.tolerance(name, "tilt")?.value,
            rolling_tol: data.tolerance(name, "rolling_rel")?.value,
        };
        ctx.progress().stage(
            "runs",
            (p.sliding_ratios.len()
                + p.sticking_ratios.len()
                + p.creep_ratios.len()
                + p.rolling_frictions.len()) as u64,
        );
        let mut inc = Incline::default();
        sliding_runs(ctx, &p, &g, &mut inc);
        sticking_runs(ctx, &p, &g, &mut inc);
        incline_theory(&g, &mut inc);
        incline_report(ctx, &g, inc)?;
        rolling_runs(ctx, &p, &g)
    }
}

/// The case's references and tolerances.
struct Gates {
    /// The friction coefficient of the incline.
    mu: Real,
    /// The rolling sphere's final speed over its launch speed (5/7).
    fraction: Real,
    sliding_tol: Real,
    stretch_factor: Real,
    tilt_tol: Real,
    rolling_tol: Real,
}

/// The incline's table rows and plot points.
#[derive(Default)]
struct Incline {
    rows: Vec<Vec<String>>,
    creep_rows: Vec<Vec<String>>,
    a_ours: Vec<(Real, Real)>,
    a_theory: Vec<(Real, Real)>,
    disp: Vec<(Real, Real)>,
    bound_line: Vec<(Real, Real)>,
}

/// The cube above the friction angle: its acceleration against Coulomb's.
fn sliding_runs(ctx: &mut CaseContext, p: &Params, g: &Gates, inc: &mut Incline) {
    for &ratio in &p.sliding_ratios {
        let theta = (ratio * g.mu).atan();
        let run = slide(theta, g.mu, DURATION);
        let expected = G * (theta.sin() - g.mu * theta.cos());
        let error = (run.acceleration - expected).abs() / expected;
        ctx.check(
            &format!("sliding_acceleration_rel_error_tan_{ratio}_mu"),
            error,
            Target::at_most(g.sliding_tol),
            "1",
        );
        inc.rows.push(vec![
            format!("{ratio}"),
            format!("{:.3}", theta.to_degrees()),
            "slide (gated)".into(),
            format!("{:.6}", run.acceleration),
            format!("{expected:.6}"),
            CaseContext::fmt(run.displacement),
            "—".into(),
            CaseContext::fmt(run.max_tilt),
        ]);
        inc.a_ours.push((ratio, run.acceleration));
        ctx.progress().inc(1);
    }
}

/// The cube below the friction angle: it sticks within the tangential spring's stretch; close to the
/// angle, beside the former deepest-vertex wall law.
fn sticking_runs(ctx: &mut CaseContext, p: &Params, g: &Gates, inc: &mut Incline) {
    let mass = DENSITY * SIDE.powi(3);
    for (near, ratios) in [(false, &p.sticking_ratios), (true, &p.creep_ratios)] {
        for &ratio in ratios {
            let theta = (ratio * g.mu).atan();
            let run = slide(theta, g.mu, DURATION);
            let stretch = g.mu * mass * G * theta.cos() / STIFFNESS;
            let bound = g.stretch_factor * stretch;
            {
                ctx.check(
                    &format!("sticking_displacement_tan_{ratio}_mu"),
                    run.displacement.abs(),
                    Target::at_most(bound),
                    "m",
                );
                ctx.check(
                    &format!("sticking_tilt_tan_{ratio}_mu"),
                    run.max_tilt,
                    Target::at_most(g.tilt_tol),
                    "rad",
                );
            }
            if near {
                let former = slide_with(theta, g.mu, DURATION, Some(WallDepth::DeepestVertex));
                for (law, r) in [
                    ("smoothed depth (gated)", &run),
                    ("deepest vertex (former, not gated)", &former),
                ] {
                    inc.creep_rows.push(vec![
                        format!("{ratio}"),
                        law.into(),
                        CaseContext::fmt(r.displacement),
                        CaseContext::fmt(bound),
                        format!("{:.2}", r.displacement.abs() / bound),
                        CaseContext::fmt(r.max_tilt),
                        if r.displacement.abs() <= bound {
                            "within"
                        } else {
                            "exceeds"
                        }
                        .into(),
                    ]);
                }
            }
            inc.rows.push(vec![
                format!("{ratio}"),
                format!("{:.3}", theta.to_degrees()),
                if near {
                    "stick, close to the friction angle (gated)"
                } else {
                    "stick (gated)"
                }
                .into(),
                format!("{:.6}", run.acceleration),
                "0".into(),
                CaseContext::fmt(run.displacement),
                CaseContext::fmt(bound),
                CaseContext::fmt(run.max_tilt),
            ]);
            inc.a_ours.push((ratio, run.acceleration));
            inc.disp.push((ratio, run.displacement.abs()));
            inc.bound_line.push((ratio, bound));
            ctx.progress().inc(1);
        }
    }
}

/// Coulomb's acceleration at every ratio run, and at the friction angle.
fn incline_theory(g: &Gates, inc: &mut Incline) {
    inc.a_ours.sort_by(|a, b| a.0.total_cmp(&b.0));
    inc.disp.sort_by(|a, b| a.0.total_cmp(&b.0));
    inc.bound_line.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut ratios: Vec<Real> = inc.a_ours.iter().map(|x| x.0).collect();
    ratios.push(1.0);
    ratios.sort_by(|a, b| a.total_cmp(b));
    for r in ratios {
        let theta = (r * g.mu).atan();
        inc.a_theory
            .push((r, (G * (theta.sin() - g.mu * theta.cos())).max(0.0)));
    }
}

/// The incline's sections: the runs, the creep comparison and the two plots.
fn incline_report(ctx: &mut CaseContext, g: &Gates, inc: Incline) -> Result<(), SuiteError> {
    let (mu, stretch_factor) = (g.mu, g.stretch_factor);
    let mass = DENSITY * SIDE.powi(3);
    ctx.section("Cube on an incline");
    ctx.text(&format!(
        "μ = {mu}, cube of side {SIDE} m and mass {mass:.1} kg, run for {DURATION} s; the acceleration is fitted \
         over the second half of the run; the sticking bound is {stretch_factor} × the tangential spring's \
         elastic stretch μ m g cos θ / k_t (k_t = {STIFFNESS:e} N/m)."
    ));
    ctx.table(
        Some("incline"),
        &[
            "tan θ / μ",
            "θ (deg)",
            "regime",
            "a measured (m/s²)",
            "a expected (m/s²)",
            "displacement in 0.5 s (m)",
            "sticking bound (m)",
            "max tilt (rad)",
        ],
        &inc.rows,
    )?;
    ctx.section(
        "Close to the friction angle: smoothed wall depth against the former deepest-vertex law",
    );
    ctx.text(
        "The wall contact hands the law the smoothed depth D of the vertex depths \
         (src/contact/wall_depth.rs) with the band h equal to the static overlap m g cos θ / k_n (the rule \
         of that module); the force acts at the gradient point of D, which moves continuously over the \
         resting face as it tilts, and the cube sticks. With the former law the force acted at the deepest \
         vertex, which jumps between the corners of the resting face: the cube rocked about a single \
         point, barely damped (the normal dashpot acts on the normal velocity at c_M, which rocking hardly \
         changes), the normal force oscillated, the tangential force reached the Coulomb cap μF_n in its \
         dips and the cube crept down the slope.",
    );
    ctx.table(
        Some("creep"),
        &[
            "tan θ / μ",
            "wall law",
            "displacement in 0.5 s (m)",
            "sticking bound (m)",
            "displacement/bound",
            "max tilt (rad)",
            "verdict",
        ],
        &inc.creep_rows,
    )?;
    ctx.plot(&Plot {
        name: "incline_acceleration".into(),
        title: "Cube on an incline: acceleration along the slope".into(),
        x_label: "tan θ / μ (1)".into(),
        y_label: "acceleration (m/s²)".into(),
        x_log: false,
        y_log: false,
        series: vec![
            Series {
                label: "polydem".into(),
                style: SeriesStyle::Points,
                points: inc.a_ours,
            },
            Series {
                label: "Coulomb: max(0, g(sin θ − μ cos θ))".into(),
                style: SeriesStyle::Line,
                points: inc.a_theory,
            },
        ],
        caption: format!("μ = {mu}; the friction angle is at tan θ/μ = 1."),
    })?;
    ctx.plot(&Plot {
        name: "incline_sticking_displacement".into(),
        title: "Cube below the friction angle: displacement in 0.5 s".into(),
        x_label: "tan θ / μ (1)".into(),
        y_label: "|displacement| (m)".into(),
        x_log: false,
        y_log: true,
        series: vec![
            Series {
                label: "polydem".into(),
                style: SeriesStyle::LinePoints,
                points: inc.disp,
            },
            Series {
                label: "sticking bound (10 × spring stretch)".into(),
                style: SeriesStyle::Line,
                points: inc.bound_line,
            },
        ],
        caption: "Smoothed wall depth; every sticking run is gated.".into(),
    })?;
    Ok(())
}

/// The sphere launched without spin on a level wall: it ends rolling at 5/7 of its launch speed.
fn rolling_runs(ctx: &mut CaseContext, p: &Params, g: &Gates) -> Result<(), SuiteError> {
    // Rolling sphere.
    let (radius, density, young, poisson, v0) = BALL;
    let ball_mass = density * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    let material = ElasticMaterial::new(young, poisson).map_err(|e| SuiteError::Case {
        case: "friction".into(),
        msg: e.to_string(),
    })?;
    let mut rolling_rows = Vec::new();
    for &friction in &p.rolling_frictions {
        let model = hertz_mindlin(&SpherePair {
            material_a: material,
            material_b: material,
            radius_a: radius,
            radius_b: None,
            restitution: 0.5,
            friction,
        })
        .map_err(|e| SuiteError::Case {
            case: "friction".into(),
            msg: format!("μ = {friction}: {e}"),
        })?;
        let run = roll(&model, radius, ball_mass, v0, friction, G, 3.0);
        if run.lost_contact > 0 {
            return Err(SuiteError::Case {
                case: "friction".into(),
                msg: format!(
                    "rolling sphere, μ = {friction}: left the wall in {} steps",
                    run.lost_contact
                ),
            });
        }
        let expected = g.fraction * v0;
        let error = (run.velocity - expected).abs() / expected;
        let slip = (run.rolling_speed - run.velocity).abs() / expected;
        ctx.check(
            &format!("rolling_speed_rel_error_mu_{friction}"),
            error,
            Target::at_most(g.rolling_tol),
            "1",
        );
        ctx.check(
            &format!("rolling_slip_mu_{friction}"),
            slip,
            Target::at_most(g.rolling_tol),
            "1",
        );
        rolling_rows.push(vec![
            format!("{friction}"),
            format!("{:.6}", run.velocity / v0),
            format!("{:.6}", run.rolling_speed / v0),
            format!("{:.6}", g.fraction),
            CaseContext::fmt(error),
            format!("{:.4}", run.sliding_time),
        ]);
        ctx.progress().inc(1);
    }

    ctx.section("Sphere rolling without slip");
    ctx.text(&format!(
        "Hertz–Mindlin sphere (radius {radius} m, {density} kg/m³, E = {young:e} Pa, ν = {poisson}, e = 0.5) \
         launched at v₀ = {v0} m/s without spin on a level wall under gravity, run for 3 sliding times \
         2v₀/(7μg)."
    ));
    ctx.table(
        Some("rolling"),
        &[
            "μ",
            "v/v₀",
            "ωR/v₀",
            "5/7",
            "|v/(5v₀/7) − 1|",
            "sliding time (s)",
        ],
        &rolling_rows,
    )?;
    Ok(())
}
