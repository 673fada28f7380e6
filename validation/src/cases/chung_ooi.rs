//! Chung & Ooi (2011) benchmark tests 1–4 with the Hertz–Mindlin law and the body
//! integrator. Tests 1–2: elastic normal impacts against Hertz theory; test 3: output against input
//! restitution; test 4: oblique impacts against the rigid-body impulse solution with Coulomb friction:
//! with J_n = m (1 + e) v_n, the sphere slides throughout when tan θ ≥ (7/2) μ (1 + e) ("gross sliding"):
//! v_t' = v_t − μ (1 + e) v_n, ω' R = (5/2) μ (1 + e) v_n; otherwise it leaves rolling: v_t' = ω' R = (5/7) v_t.
//! The rolling branch ignores tangential compliance (Maw, Barber & Fawcett 1976), which the Mindlin spring has,
//! so only the gross-sliding angles are checked; all angles are plotted. Inputs and their sources: the TOML.

use polydem::dynamics::{Motion, PrincipalInertia, RigidBody};
use polydem::law::hertz_mindlin::{
    effective, effective_young_modulus, hertz_mindlin, ElasticMaterial, SpherePair,
};
use polydem::math::{Point, Real, Vector};

use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};
use crate::sim::two_body::{hertz_theory, impact, sphere_sphere, wall_sphere, Impact};

pub struct ChungOoi;

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// Time step = elastic contact time / this.
    steps_per_contact: Real,
    /// Input restitutions of test 3.
    restitutions: Vec<Real>,
    /// Incident angles of test 4 (degrees from the normal).
    angles_deg: Vec<Real>,
}

/// A sphere material.
#[derive(Clone, Copy)]
struct Material {
    name: &'static str,
    young: Real,
    poisson: Real,
    density: Real,
}

fn sphere(m: &Material, radius: Real, position: Point, velocity: Vector) -> RigidBody {
    let mass = m.density * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    let inertia =
        PrincipalInertia::new(Vector::repeat(0.4 * mass * radius * radius)).expect("I > 0");
    let mut b = RigidBody::new_dynamic(position, mass, inertia).expect("body");
    b.velocity = velocity;
    b
}

fn elastic(m: &Material) -> Result<ElasticMaterial, String> {
    ElasticMaterial::new(m.young, m.poisson).map_err(|e| e.to_string())
}

/// A wall material: `factor` × stiffer than the sphere, same Poisson ratio (as in the YADE scripts).
fn wall_material(m: &Material, factor: Real) -> Material {
    Material {
        young: m.young * factor,
        ..*m
    }
}

/// Sphere B (radius `radius`) falling on the wall z = 0 with velocity (v_t, 0, −v_n); returns the impact.
#[allow(clippy::too_many_arguments)]
fn wall_impact(
    m: &Material,
    wall: &Material,
    radius: Real,
    v_n: Real,
    v_t: Real,
    restitution: Real,
    friction: Real,
    per_contact: Real,
) -> Result<(Impact, Real), String> {
    let pair = SpherePair {
        material_a: elastic(wall)?,
        material_b: elastic(m)?,
        radius_a: radius,
        radius_b: None,
        restitution,
        friction,
    };
    let model = hertz_mindlin(&pair).map_err(|e| e.to_string())?;
    let mut a = sphere(m, radius, Point::origin(), Vector::zeros());
    a.motion = Motion::Fixed;
    let b = sphere(
        m,
        radius,
        Point::new(0.0, 0.0, radius * (1.0 + 1e-4)),
        Vector::new(v_t, 0.0, -v_n),
    );
    let m_star = b.mass;
    let dt = model.normal.elastic_contact_time(m_star, v_n) / per_contact;
    let run = impact(
        &model,
        a,
        b,
        m_star,
        dt,
        (50.0 * per_contact) as usize,
        |_, b| wall_sphere(radius, b),
    );
    if !run.separated {
        return Err(format!(
            "{}: sphere did not leave the wall (v_n = {v_n}, v_t = {v_t}, e = {restitution})",
            m.name
        ));
    }
    Ok((run, m_star))
}

/// The case's parameters, references and tolerances.
struct Inputs<'a> {
    data: &'a CaseData,
    p: Params,
    hertz_tol: Real,
    e_tol: Real,
    sliding_tol: Real,
    margin: Real,
    /// The wall's stiffness over the sphere's (its Young modulus factor).
    factor: Real,
}

impl Inputs<'_> {
    fn r(&self, key: &str) -> Result<Real, SuiteError> {
        self.data.reference("chung_ooi", key).map(|q| q.value)
    }

    fn material(&self, name: &'static str, prefix: &str) -> Result<Material, SuiteError> {
        Ok(Material {
            name,
            young: self.r(&format!("{prefix}_young"))?,
            poisson: self.r(&format!("{prefix}_poisson"))?,
            density: self.r(&format!("{prefix}_density"))?,
        })
    }
}

fn chung_ooi_error(msg: String) -> SuiteError {
    SuiteError::case("chung_ooi", msg)
}

impl Case for ChungOoi {
    fn name(&self) -> &'static str {
        "chung_ooi"
    }

    fn data(&self) -> &'static str {
        include_str!("../../cases/chung_ooi.toml")
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let name = self.name();
        let inp = Inputs {
            data,
            p: data.params(name, profile)?,
            hertz_tol: data.tolerance(name, "hertz_rel")?.value,
            e_tol: data.tolerance(name, "restitution_rel")?.value,
            sliding_tol: data.tolerance(name, "sliding_rel")?.value,
            margin: data.tolerance(name, "sliding_margin")?.value,
            factor: data.reference(name, "wall_stiffness_factor")?.value,
        };
        ctx.progress().stage(
            "impacts",
            (4 + 2 * inp.p.restitutions.len() + inp.p.angles_deg.len()) as u64,
        );
        hertz_impacts(ctx, &inp)?;
        restitution_impacts(ctx, &inp)?;
        oblique_impacts(ctx, &inp)
    }
}

/// Tests 1 and 2: elastic normal impacts, sphere on sphere and sphere on wall, against Hertz theory.
fn hertz_impacts(ctx: &mut CaseContext, inp: &Inputs) -> Result<(), SuiteError> {
    let mut hertz_rows = Vec::new();
    for m in [
        inp.material("glass", "t1_glass")?,
        inp.material("limestone", "t1_limestone")?,
    ] {
        let (run, theory) = sphere_on_sphere(inp, &m)?;
        hertz_check(ctx, inp, ("test1", &m), &run, theory, &mut hertz_rows);
        ctx.progress().inc(1);
    }
    for m in [
        inp.material("aluminium_alloy", "t2_al")?,
        inp.material("magnesium_alloy", "t2_mg")?,
    ] {
        let (run, theory) = sphere_on_wall(inp, &m)?;
        hertz_check(ctx, inp, ("test2", &m), &run, theory, &mut hertz_rows);
        ctx.progress().inc(1);
    }

    ctx.section("Tests 1–2: elastic normal impacts against Hertz theory");
    ctx.text(&format!(
        "dt = t_c/{} (t_c the elastic contact time of the law). Hertz theory (Johnson 1985 §11.4): \
         δ_max = (15 m* v²/(16 E* √R*))^(2/5), F_max = (4/3) E* √R* δ_max^(3/2), t_c = 2.9432 δ_max/v.",
        inp.p.steps_per_contact
    ));
    ctx.table(
        Some("hertz"),
        &[
            "test",
            "material",
            "quantity",
            "ours",
            "Hertz",
            "relative error",
        ],
        &hertz_rows,
    )?;
    Ok(())
}

/// Checks the peak force, peak overlap and contact duration of `run` against Hertz theory `theory` (in that
/// order) for `test` on material `m`, and adds their rows.
fn hertz_check(
    ctx: &mut CaseContext,
    inp: &Inputs,
    (test, m): (&str, &Material),
    run: &Impact,
    theory: (Real, Real, Real),
    rows: &mut Vec<Vec<String>>,
) {
    let tag = format!("{test}_{}", m.name);
    for (quantity, unit, measured, expected) in [
        ("peak_force", "N", run.peak_force, theory.0),
        ("peak_overlap", "m", run.peak_overlap, theory.1),
        ("contact_duration", "s", run.duration, theory.2),
    ] {
        let error = (measured - expected).abs() / expected;
        ctx.check(
            &format!("{tag}_{quantity}_rel_error"),
            error,
            Target::at_most(inp.hertz_tol),
            "1",
        );
        rows.push(vec![
            test.to_string(),
            m.name.to_string(),
            format!("{quantity} ({unit})"),
            CaseContext::fmt(measured),
            CaseContext::fmt(expected),
            CaseContext::fmt(error),
        ]);
    }
}

/// Test 1: two equal spheres of `m` meeting head on; the run and Hertz theory (F_max, δ_max, t_c).
fn sphere_on_sphere(
    inp: &Inputs,
    m: &Material,
) -> Result<(Impact, (Real, Real, Real)), SuiteError> {
    let (radius, speed) = (inp.r("t1_radius")?, inp.r("t1_speed")?);
    let pair = SpherePair {
        material_a: elastic(m).map_err(chung_ooi_error)?,
        material_b: elastic(m).map_err(chung_ooi_error)?,
        radius_a: radius,
        radius_b: Some(radius),
        restitution: 1.0,
        friction: 0.0,
    };
    let model = hertz_mindlin(&pair).map_err(|e| chung_ooi_error(e.to_string()))?;
    let a = sphere(m, radius, Point::origin(), Vector::new(0.0, 0.0, speed));
    let b = sphere(
        m,
        radius,
        Point::new(0.0, 0.0, 2.0 * radius * (1.0 + 1e-4)),
        Vector::new(0.0, 0.0, -speed),
    );
    let m_star = 0.5 * a.mass;
    let approach = 2.0 * speed;
    let dt = model.normal.elastic_contact_time(m_star, approach) / inp.p.steps_per_contact;
    let run = impact(
        &model,
        a,
        b,
        m_star,
        dt,
        (50.0 * inp.p.steps_per_contact) as usize,
        |a, b| sphere_sphere(radius, radius, a, b),
    );
    let e_star = effective_young_modulus(&pair.material_a, &pair.material_b);
    let theory = hertz_theory(e_star, effective(radius, Some(radius)), m_star, approach);
    Ok((run, theory))
}

/// Test 2: a sphere of `m` on its wall; the run and Hertz theory (F_max, δ_max, t_c).
fn sphere_on_wall(inp: &Inputs, m: &Material) -> Result<(Impact, (Real, Real, Real)), SuiteError> {
    let (radius, speed) = (inp.r("t2_radius")?, inp.r("t2_speed")?);
    let wall = wall_material(m, inp.factor);
    let (run, m_star) = wall_impact(
        m,
        &wall,
        radius,
        speed,
        0.0,
        1.0,
        0.0,
        inp.p.steps_per_contact,
    )
    .map_err(chung_ooi_error)?;
    let e_star = effective_young_modulus(
        &elastic(&wall).map_err(chung_ooi_error)?,
        &elastic(m).map_err(chung_ooi_error)?,
    );
    Ok((run, hertz_theory(e_star, radius, m_star, speed)))
}

/// Test 3: output against input restitution, sphere on wall.
fn restitution_impacts(ctx: &mut CaseContext, inp: &Inputs) -> Result<(), SuiteError> {
    // Test 3: restitution.
    let (radius, speed) = (inp.r("t34_radius")?, inp.r("t34_speed")?);
    let mut e_rows = Vec::new();
    let mut e_series = Vec::new();
    for m in [
        inp.material("aluminium_oxide", "t34_alox")?,
        inp.material("cast_iron", "t3_iron")?,
    ] {
        let wall = wall_material(&m, inp.factor);
        let mut worst: Real = 0.0;
        let mut points = Vec::new();
        for &e in &inp.p.restitutions {
            let (run, _) = wall_impact(
                &m,
                &wall,
                radius,
                speed,
                0.0,
                e,
                0.0,
                inp.p.steps_per_contact,
            )
            .map_err(chung_ooi_error)?;
            let measured = run.b.velocity.z / speed;
            let error = (measured / e - 1.0).abs();
            worst = worst.max(error);
            e_rows.push(vec![
                m.name.to_string(),
                format!("{e}"),
                format!("{measured:.6}"),
                CaseContext::fmt(error),
            ]);
            points.push((e, measured));
            ctx.progress().inc(1);
        }
        ctx.check(
            &format!("test3_{}_restitution_rel_error_max", m.name),
            worst,
            Target::at_most(inp.e_tol),
            "1",
        );
        e_series.push(Series {
            label: m.name.to_string(),
            style: SeriesStyle::Points,
            points,
        });
    }

    ctx.section("Test 3: output against input restitution");
    ctx.table(
        Some("restitution"),
        &["material", "e input", "e output", "|e_out/e_in − 1|"],
        &e_rows,
    )?;
    e_series.push(Series {
        label: "e_out = e_in".into(),
        style: SeriesStyle::Line,
        points: inp.p.restitutions.iter().map(|&e| (e, e)).collect(),
    });
    ctx.plot(&Plot {
        name: "test3_restitution".into(),
        title: "Test 3: output against input restitution".into(),
        x_label: "input e (1)".into(),
        y_label: "output e (1)".into(),
        x_log: false,
        y_log: false,
        series: e_series,
        caption: format!("Sphere of radius {radius} m on a wall at {speed} m/s."),
    })?;
    Ok(())
}

/// One oblique impact of test 4, ours beside the rigid-body solution.
struct Oblique {
    angle: Real,
    /// The rigid-body solution's regime: gross sliding (else rolling at exit).
    sliding: bool,
    /// In gross sliding beyond the margin: checked.
    checked: bool,
    /// v_t'/v_t, ours and rigid.
    vt_ratio: [Real; 2],
    /// ω' (rad/s), ours and rigid.
    spin: [Real; 2],
    /// Relative errors of v_t' and ω'.
    errors: [Real; 2],
}

/// Test 4: oblique impacts against the rigid-body solution with Coulomb friction.
fn oblique_impacts(ctx: &mut CaseContext, inp: &Inputs) -> Result<(), SuiteError> {
    let margin = inp.margin;
    let (mu, e) = (inp.r("t4_friction")?, inp.r("t4_restitution")?);
    let threshold = 3.5 * mu * (1.0 + e);
    let mut impacts = Vec::new();
    for &angle in &inp.p.angles_deg {
        impacts.push(oblique_impact(inp, angle, threshold)?);
        ctx.progress().inc(1);
    }
    let checked: Vec<&Oblique> = impacts.iter().filter(|o| o.checked).collect();
    if checked.is_empty() {
        return Err(chung_ooi_error(format!(
            "no incident angle of {:?} is in gross sliding (tan θ ≥ {margin} × {threshold:.4})",
            inp.p.angles_deg
        )));
    }
    let worst = |k: usize| checked.iter().map(|o| o.errors[k]).fold(0.0, Real::max);
    ctx.check(
        "test4_gross_sliding_tangential_velocity_rel_error_max",
        worst(0),
        Target::at_most(inp.sliding_tol),
        "1",
    );
    ctx.check(
        "test4_gross_sliding_spin_rel_error_max",
        worst(1),
        Target::at_most(inp.sliding_tol),
        "1",
    );
    report_oblique(ctx, inp, &impacts, threshold, checked.len())
}

/// The aluminium oxide sphere on its wall at `angle` degrees from the normal, with the rigid-body
/// solution (gross sliding from tan θ ≥ `threshold`).
fn oblique_impact(inp: &Inputs, angle: Real, threshold: Real) -> Result<Oblique, SuiteError> {
    let (radius, speed) = (inp.r("t34_radius")?, inp.r("t34_speed")?);
    let m = inp.material("aluminium_oxide", "t34_alox")?;
    let wall = wall_material(&m, inp.factor);
    let (mu, e) = (inp.r("t4_friction")?, inp.r("t4_restitution")?);
    let theta = angle.to_radians();
    let (v_n, v_t) = (speed * theta.cos(), speed * theta.sin());
    let (run, _) = wall_impact(&m, &wall, radius, v_n, v_t, e, mu, inp.p.steps_per_contact)
        .map_err(chung_ooi_error)?;
    let (vt_after, spin) = (run.b.velocity.x, run.b.angular_velocity().y);
    let sliding = theta.tan() >= threshold;
    let (vt_rigid, spin_rigid) = if sliding {
        (
            v_t - mu * (1.0 + e) * v_n,
            2.5 * mu * (1.0 + e) * v_n / radius,
        )
    } else {
        (5.0 / 7.0 * v_t, 5.0 / 7.0 * v_t / radius)
    };
    Ok(Oblique {
        angle,
        sliding,
        checked: theta.tan() >= inp.margin * threshold,
        vt_ratio: [vt_after / v_t, vt_rigid / v_t],
        spin: [spin, spin_rigid],
        errors: [
            (vt_after - vt_rigid).abs() / vt_rigid.abs(),
            (spin - spin_rigid).abs() / spin_rigid.abs(),
        ],
    })
}

/// Test 4's section: the text, the table and the two plots.
fn report_oblique(
    ctx: &mut CaseContext,
    inp: &Inputs,
    impacts: &[Oblique],
    threshold: Real,
    checked: usize,
) -> Result<(), SuiteError> {
    let (margin, speed) = (inp.margin, inp.r("t34_speed")?);
    let (mu, e) = (inp.r("t4_friction")?, inp.r("t4_restitution")?);
    ctx.section("Test 4: oblique impacts against the rigid-body solution");
    ctx.text(&format!(
        "Aluminium oxide sphere, resultant speed {speed} m/s, μ = {mu}, e = {e}. Rigid-body impulse solution \
         with Coulomb friction: gross sliding for tan θ ≥ (7/2) μ (1 + e) = {threshold:.4} (θ ≥ {:.1}°): \
         v_t'/v_t = 1 − μ (1 + e)/tan θ, ω' R = (5/2) μ (1 + e) v_n; below, the sphere leaves rolling, \
         v_t' = ω' R = (5/7) v_t. The rolling branch ignores tangential compliance (Maw et al. 1976; the Mindlin \
         spring stores tangential energy and returns part of it), so it is plotted, not checked; the gross \
         sliding branch is checked for tan θ ≥ {margin} × {threshold:.4} ({checked} angles).",
        threshold.atan().to_degrees()
    ));
    let rows: Vec<Vec<String>> = impacts
        .iter()
        .map(|o| {
            vec![
                format!("{}", o.angle),
                if o.sliding {
                    "gross sliding"
                } else {
                    "rolling at exit (rigid)"
                }
                .into(),
                if o.checked { "yes" } else { "no" }.into(),
                format!("{:.5}", o.vt_ratio[0]),
                format!("{:.5}", o.vt_ratio[1]),
                format!("{:.3}", o.spin[0]),
                format!("{:.3}", o.spin[1]),
            ]
        })
        .collect();
    ctx.table(
        Some("oblique"),
        &[
            "θ (deg)",
            "rigid-body regime",
            "checked",
            "v_t'/v_t ours",
            "v_t'/v_t rigid",
            "ω' ours (rad/s)",
            "ω' rigid (rad/s)",
        ],
        &rows,
    )?;
    let series = |pick: fn(&Oblique) -> [Real; 2]| -> Vec<Series> {
        let points = |k: usize| impacts.iter().map(|o| (o.angle, pick(o)[k])).collect();
        vec![
            Series {
                label: "polydem (Hertz–Mindlin)".into(),
                style: SeriesStyle::Points,
                points: points(0),
            },
            Series {
                label: "rigid-body solution".into(),
                style: SeriesStyle::Line,
                points: points(1),
            },
        ]
    };
    ctx.plot(&Plot {
        name: "test4_tangential_restitution".into(),
        title: "Test 4: tangential coefficient of restitution".into(),
        x_label: "incident angle θ (deg)".into(),
        y_label: "v_t'/v_t (1)".into(),
        x_log: false,
        y_log: false,
        series: series(|o| o.vt_ratio),
        caption: "Below the sliding threshold the Mindlin spring's compliance lowers v_t'/v_t under 5/7 (Maw et al.)."
            .into(),
    })?;
    ctx.plot(&Plot {
        name: "test4_spin".into(),
        title: "Test 4: rebound angular velocity".into(),
        x_label: "incident angle θ (deg)".into(),
        y_label: "ω' (rad/s)".into(),
        x_log: false,
        y_log: false,
        series: series(|o| o.spin),
        caption: "Spin about the axis n × t (the rolling sense).".into(),
    })?;
    Ok(())
}
