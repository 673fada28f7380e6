//! Single-contact energy conservation: elastic impacts of polyhedra through the contact
//! core (`polydem::contact::query`: GJK/EPA and the fast paths) and the body integrator, in every contact
//! type — vertex–face, edge–face, edge–edge, face–face — plus a box vertex on a wall and a sphere on a box,
//! with spin, for the linear and the Hertz-type law (paper eqs. 4–5). Measured: the total energy
//! E = kinetic (translational + rotational) + k_n δ^(n+1)/(n+1) during contact, and the kinetic energy after
//! separation against before, over a sweep of dt = t_c/N. The naive variant takes the normal along the line
//! of centres (the sphere rule) with the same overlap and point. (Applying the force at c1 or c2 instead of
//! c_M is not a naive variant: the three points differ by multiples of n, so a normal force has the same
//! torque about any centre.) The scene machinery is public: `tests/polyhedral_energy_gates.rs` uses it.
//!
//! The wall contacts include an edge and a face of a spinning box landing flat (two and four vertices
//! penetrate and the spin rocks them). They conserve energy through the smoothed wall depth
//! (`polydem::contact::wall_depth`); the former deepest-vertex law (`Variant::WallDeepestVertex`) is shown
//! beside them, not checked (first order: its force point jumps between the tied vertices), with the
//! sensitivity to the smoothing band.

use crate::stats::fitted_order;
use std::sync::Arc;

use polydem::contact::{
    query_with, ContactGeometry, ContactTolerances, EpaScratch, PairCache, PairSmoothing,
    QueryCounters, WallDepth,
};
use polydem::dynamics::{
    Integrator, Motion, PrincipalInertia, RigidBody, RotationScheme, TranslationParams,
    ViscousDamping,
};
use polydem::law::{
    ContactKinematics, ContactModel, DampingLaw, NormalLaw, TangentialHistory, TangentialLaw,
};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::{ConvexPolyhedron, Plane, Shape, Sphere};

use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};

pub const DENSITY: Real = 2600.0;
pub const SPEED: Real = 1.0;

/// A box of half extents 0.5 × 0.4 × 0.3 m (distinct principal moments), in its principal frame.
pub fn rock() -> Arc<ConvexPolyhedron> {
    let (a, b, c) = (0.5, 0.4, 0.3);
    let mut corners = Vec::new();
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                corners.push(Point::new(sx * a, sy * b, sz * c));
            }
        }
    }
    Arc::new(ConvexPolyhedron::from_points(&corners).expect("box hull").0)
}

pub fn body_of(shape: &Shape, position: Point, orientation: Rotation) -> RigidBody {
    let (mass, inertia) = match shape {
        Shape::Polyhedron(p) => {
            let props = p.mass_properties();
            (props.volume * DENSITY, props.principal_inertia(DENSITY))
        }
        Shape::Sphere(s) => {
            let r = s.radius();
            let mass = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
            (mass, Vector::repeat(0.4 * mass * r * r))
        }
        Shape::Plane(_) => (1.0, Vector::repeat(1.0)),
        other => other.convex().map_or((1.0, Vector::repeat(1.0)), |c| {
            let props = c.mass_properties();
            (props.volume * DENSITY, props.principal_inertia(DENSITY))
        }),
    };
    let mut body =
        RigidBody::new_dynamic(position, mass, PrincipalInertia::new(inertia).unwrap()).unwrap();
    body.orientation = orientation;
    if matches!(shape, Shape::Plane(_)) {
        body.motion = Motion::Fixed;
    }
    body
}

pub fn pose(body: &RigidBody) -> Pose {
    Pose::from_parts(body.position.coords.into(), body.orientation)
}

/// Rotation taking the body-frame direction `from` to the world direction `to`.
pub fn turn(from: &Vector, to: &Vector) -> Rotation {
    Rotation::rotation_between(from, to)
        .unwrap_or_else(|| Rotation::from_axis_angle(&Vector::x_axis(), std::f64::consts::PI))
}

/// The midpoint direction of one edge of the box (an edge is perpendicular to it for a centred box).
pub fn edge_midpoint(p: &ConvexPolyhedron) -> (Vector, Vector) {
    let [i, j] = p.edges()[0];
    let (a, b) = (
        p.vertices()[i as usize].coords,
        p.vertices()[j as usize].coords,
    );
    ((a + b) * 0.5, (b - a).normalize())
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setup {
    VertexFace,
    EdgeFace,
    EdgeEdge,
    FaceFace,
    /// A vertex of the box lands on the wall.
    BoxWallVertex,
    /// An edge of the box, parallel to the wall, lands on it (both end vertices penetrate).
    BoxWallEdge,
    /// A face of the box, parallel to the wall, lands on it (its four vertices penetrate; the spin rocks it).
    BoxWallFace,
    /// A face of B lands flat on the (level) top face of A, turned 0.3 rad about the normal: vertices and
    /// the Minkowski faces of both boxes tie (`polydem::contact::pair_smoothing`).
    PolyFaceFlat,
    /// An edge of B parallel to A's (level) top face lands on it: its two end vertices tie.
    PolyEdgeFlat,
    SphereBox,
}

/// Shapes and bodies (A below, B above moving down along −z with spin), just apart.
pub fn scene(setup: Setup) -> (Shape, RigidBody, Shape, RigidBody) {
    let r = rock();
    let poly = Shape::Polyhedron(r.clone());
    let lowest = |p: &ConvexPolyhedron, q: &Rotation| {
        p.vertices()
            .iter()
            .map(|v| q.transform_point(v).z)
            .fold(Real::INFINITY, Real::min)
    };
    let highest = |p: &ConvexPolyhedron, q: &Rotation| {
        p.vertices()
            .iter()
            .map(|v| q.transform_point(v).z)
            .fold(Real::NEG_INFINITY, Real::max)
    };
    let tilt = Rotation::from_scaled_axis(Vector::new(0.02, -0.015, 0.01));
    let (shape_a, q_a, top_a) = match setup {
        Setup::BoxWallVertex | Setup::BoxWallEdge | Setup::BoxWallFace => (
            Shape::Plane(Plane::new(Vector::z(), 0.0).unwrap()),
            Rotation::identity(),
            0.0,
        ),
        Setup::PolyFaceFlat | Setup::PolyEdgeFlat => {
            let q = Rotation::identity();
            let top = highest(&r, &q);
            (poly.clone(), q, top)
        }
        Setup::EdgeEdge => {
            let (m, _) = edge_midpoint(&r);
            let q = turn(&m, &Vector::z());
            let top = highest(&r, &q);
            (poly.clone(), q, top)
        }
        _ => {
            let q = tilt;
            let top = highest(&r, &q);
            (poly.clone(), q, top)
        }
    };
    let (shape_b, q_b) = match setup {
        Setup::VertexFace | Setup::BoxWallVertex => {
            let v = r.vertices()[0].coords;
            (
                poly.clone(),
                turn(&v, &-Vector::z()) * Rotation::from_scaled_axis(Vector::new(0.03, 0.0, 0.0)),
            )
        }
        Setup::EdgeFace | Setup::BoxWallEdge | Setup::PolyEdgeFlat => {
            let (m, _) = edge_midpoint(&r);
            (
                poly.clone(),
                Rotation::from_axis_angle(&Vector::z_axis(), 0.3) * turn(&m, &-Vector::z()),
            )
        }
        Setup::EdgeEdge => {
            let (m, d) = edge_midpoint(&r);
            let down = turn(&m, &-Vector::z());
            let up = turn(&m, &Vector::z());
            let (dir_a, dir_b) = (up.transform_vector(&d), down.transform_vector(&d));
            // Turn B about z so that its edge crosses A's at 90° (plus 5° to avoid symmetry).
            let angle = dir_b.y.atan2(dir_b.x) - dir_a.y.atan2(dir_a.x);
            let cross = std::f64::consts::FRAC_PI_2 + 0.087 - angle;
            (
                poly.clone(),
                Rotation::from_axis_angle(&Vector::z_axis(), cross) * down,
            )
        }
        Setup::FaceFace => (poly.clone(), tilt),
        Setup::BoxWallFace | Setup::PolyFaceFlat => (
            poly.clone(),
            Rotation::from_axis_angle(&Vector::z_axis(), 0.3),
        ),
        Setup::SphereBox => (
            Shape::Sphere(Sphere::new(0.25).unwrap()),
            Rotation::identity(),
        ),
    };
    let bottom_b = match &shape_b {
        Shape::Polyhedron(p) => lowest(p, &q_b),
        Shape::Sphere(s) => -s.radius(),
        Shape::Plane(_) => unreachable!("B is never a wall"),
        other => match other.convex() {
            Some(c) => {
                c.aabb(&Pose::from_parts(Vector::zeros().into(), q_b))
                    .mins
                    .z
            }
            None => unreachable!("B is never a wall"),
        },
    };
    let a = body_of(&shape_a, Point::origin(), q_a);
    // Offset B sideways a little so the contact is not on A's axis, and start 1e-4 m apart.
    let mut b = body_of(
        &shape_b,
        Point::new(0.05, -0.03, top_a - bottom_b + 1e-4),
        q_b,
    );
    b.velocity = Vector::new(0.02, 0.0, -SPEED);
    b.set_angular_velocity(&Vector::new(0.3, -0.2, 0.5));
    let mut a = a;
    if a.is_dynamic() {
        a.set_angular_velocity(&Vector::new(-0.1, 0.2, 0.1));
    }
    (shape_a, a, shape_b, b)
}

pub struct Outcome {
    /// max |E(t) − E₀| / E₀ while in contact.
    pub in_contact: Real,
    /// |KE_after − KE_before| / KE_before.
    pub after: Real,
    /// Number of steps with a positive overlap.
    pub steps_in_contact: usize,
}

/// How the contact features are taken.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Variant {
    /// As the contact core returns them.
    Minkowski,
    /// Naive: the normal along the line of centres.
    CentreLineNormal,
    /// Wall pairs only: the former polyhedron–plane law, overlap max_i d_i at the deepest vertex
    /// ([`WallDepth::DeepestVertex`]) instead of the smoothed depth.
    WallDeepestVertex,
    /// Wall pairs only: the smoothed depth with the band h = this factor × the peak overlap of the impact
    /// (the main runs use h = the peak overlap, the rule of `polydem::contact::wall_depth`).
    WallBand(Real),
    /// Polyhedron pairs only: the exact Minkowski overlap of EPA ([`PairSmoothing::Exact`]) instead of the
    /// smoothed one (the main runs smooth with h = the peak overlap, as the wall).
    PairExact,
}

/// Runs the impact with dt = t_c / `per_contact` (t_c of the law for the normal approach at SPEED with the
/// masses' effective mass; a scale, not the exact duration of an eccentric impact).
pub fn collide(setup: Setup, law: NormalLaw, per_contact: Real, variant: Variant) -> Outcome {
    let (shape_a, mut a, shape_b, mut b) = scene(setup);
    let m_star = if a.is_dynamic() {
        a.mass * b.mass / (a.mass + b.mass)
    } else {
        b.mass
    };
    let dt = law.elastic_contact_time(m_star, SPEED) / per_contact;
    let model = ContactModel {
        normal: law,
        damping: DampingLaw::None,
        tangential: TangentialLaw::None,
    };
    let integrator = Integrator {
        translation: TranslationParams {
            gravity: Vector::zeros(),
            damping: ViscousDamping::None,
        },
        rotation: RotationScheme::default(),
    };
    // The band of the smoothed wall depth by the rule of `polydem::contact::wall_depth`: h = the scene's
    // characteristic overlap, here the peak overlap of the head-on impact at SPEED, ((n+1) m* V²/(2k))^(1/(n+1)).
    let peak_overlap = ((law.exponent + 1.0) * m_star * SPEED * SPEED / (2.0 * law.stiffness))
        .powf(1.0 / (law.exponent + 1.0));
    let size = shape_b
        .length_scale()
        .expect("B is a polyhedron or a sphere");
    let tolerances = ContactTolerances {
        wall_depth: match variant {
            Variant::WallDeepestVertex => WallDepth::DeepestVertex,
            Variant::WallBand(factor) => WallDepth::Smoothed {
                band: factor * peak_overlap / size,
            },
            _ => WallDepth::Smoothed {
                band: peak_overlap / size,
            },
        },
        pair_smoothing: match variant {
            Variant::PairExact => PairSmoothing::Exact,
            _ => PairSmoothing::Smoothed {
                band: peak_overlap / size,
            },
        },
        ..ContactTolerances::default()
    };
    let (mut cache, mut scratch, mut counters) = (
        PairCache::default(),
        EpaScratch::default(),
        QueryCounters::default(),
    );
    let mut history = TangentialHistory::default();
    let mut evaluate = |a: &RigidBody, b: &RigidBody| {
        let mut g: ContactGeometry = query_with(
            &pose(a),
            &shape_a,
            &pose(b),
            &shape_b,
            &tolerances,
            &mut cache,
            &mut scratch,
            &mut counters,
        )
        .expect("no plane pair");
        match variant {
            Variant::Minkowski => {}
            Variant::CentreLineNormal => g.normal = (b.position - a.position).normalize(),
            Variant::WallDeepestVertex | Variant::WallBand(_) | Variant::PairExact => {}
        }
        let kinematics = ContactKinematics {
            relative_velocity: b.velocity_at(&g.point) - a.velocity_at(&g.point),
            effective_mass: m_star,
            center_a: a.position,
            center_b: b.position,
            dt,
        };
        model.evaluate(&g, &kinematics, &mut history)
    };
    let kinetic = |a: &RigidBody, b: &RigidBody| {
        let ka = if a.is_dynamic() {
            a.translational_kinetic_energy() + a.rotational_kinetic_energy()
        } else {
            0.0
        };
        ka + b.translational_kinetic_energy() + b.rotational_kinetic_energy()
    };
    let e0 = kinetic(&a, &b);
    let mut response = evaluate(&a, &b);
    let (mut in_contact, mut steps_in_contact, mut touched) = (0.0 as Real, 0, false);
    for _ in 0..(50.0 * per_contact) as usize {
        integrator.first_half_kick(&mut a, &-response.force_on_b, &response.torque_on_a, dt);
        integrator.first_half_kick(&mut b, &response.force_on_b, &response.torque_on_b, dt);
        integrator.drift(&mut a, dt);
        integrator.drift(&mut b, dt);
        response = evaluate(&a, &b);
        integrator.second_half_kick(&mut a, &-response.force_on_b, &response.torque_on_a, dt);
        integrator.second_half_kick(&mut b, &response.force_on_b, &response.torque_on_b, dt);
        if response.normal_potential > 0.0 {
            touched = true;
            steps_in_contact += 1;
            in_contact =
                in_contact.max((kinetic(&a, &b) + response.normal_potential - e0).abs() / e0);
        } else if touched {
            break;
        }
    }
    assert!(touched, "{setup:?}: the bodies never touched");
    Outcome {
        in_contact,
        after: (kinetic(&a, &b) - e0).abs() / e0,
        steps_in_contact,
    }
}

/// The setups of the main gate.
pub const SETUPS: [Setup; 9] = [
    Setup::VertexFace,
    Setup::EdgeFace,
    Setup::EdgeEdge,
    Setup::FaceFace,
    Setup::BoxWallVertex,
    Setup::BoxWallEdge,
    Setup::BoxWallFace,
    Setup::PolyEdgeFlat,
    Setup::SphereBox,
];

/// The polyhedron-pair setups with ties, shown with the smoothed and the exact Minkowski overlap. A face
/// landing flat on a face is not gated: besides tied vertices (smoothed) the lowest Minkowski face switches
/// between faces of A, of B and edge–edge facets, a kink the smoothing leaves (see
/// `polydem::contact::pair_smoothing`).
pub const FLAT_PAIR_SETUPS: [Setup; 2] = [Setup::PolyFaceFlat, Setup::PolyEdgeFlat];

/// Bands h / (peak overlap) of the smoothed wall depth compared in the report.
pub const BANDS: [Real; 5] = [0.1, 0.3, 1.0, 3.0, 10.0];

/// The wall setups where the former deepest-vertex law fails (shown against the smoothed depth).
pub const FLAT_WALL_SETUPS: [Setup; 2] = [Setup::BoxWallEdge, Setup::BoxWallFace];

pub fn laws() -> [(&'static str, NormalLaw); 2] {
    [
        ("linear", NormalLaw::linear(1e8).unwrap()),
        ("Hertz-type", NormalLaw::hertz(1e10).unwrap()),
    ]
}

pub struct SingleContactEnergy;

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// Steps per contact time t_c of the sweep (ascending).
    steps_per_contact: Vec<Real>,
    /// The resolution at which the 1e-4 bound is checked (must be in the sweep).
    check_at: Real,
}

impl Case for SingleContactEnergy {
    fn name(&self) -> &'static str {
        "single_contact_energy"
    }

    fn data(&self) -> &'static str {
        include_str!("../../cases/single_contact_energy.toml")
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(self.name(), profile)?;
        let tolerance = |key: &str| {
            data.tolerance("single_contact_energy", key)
                .map(|q| q.value)
        };
        let order_reference = data.reference(self.name(), "order")?.value;
        let check_index = p
            .steps_per_contact
            .iter()
            .position(|s| *s == p.check_at)
            .ok_or_else(|| SuiteError::Case {
                case: self.name().into(),
                msg: format!(
                    "check_at = {} is not in steps_per_contact {:?}",
                    p.check_at, p.steps_per_contact
                ),
            })?;
        let dts: Vec<Real> = p.steps_per_contact.iter().map(|s| 1.0 / s).collect();
        ctx.progress().stage(
            "impacts",
            (SETUPS.len() * 2 * p.steps_per_contact.len()) as u64,
        );
        let g = Sweep {
            energy_error: tolerance("energy_error")?,
            order_deviation: tolerance("order_deviation")?,
            finest_energy_error: tolerance("finest_energy_error")?,
            naive_ratio: tolerance("naive_ratio")?,
            order_reference,
            check_index,
            dts,
            p,
        };
        // (The rows of the former wall law and of the band sweep are not counted in the progress.)
        let mut rows = Vec::new();
        let mut plots: Vec<(String, Vec<Series>)> = Vec::new();
        for (law_name, law) in laws() {
            let mut series = setup_runs(ctx, &g, law_name, law, &mut rows);
            series.extend(reference_variants(ctx, &g, law_name, law, &mut rows));
            plots.push((law_name.to_string(), series));
        }
        report_energy(ctx, &g.p, rows, plots)?;
        band_sweep(ctx, &g.p)
    }
}

/// The sweep over the time step: its parameters, gates and the checked step's index.
struct Sweep {
    energy_error: Real,
    order_deviation: Real,
    finest_energy_error: Real,
    naive_ratio: Real,
    order_reference: Real,
    /// The index of `p.check_at` in `p.steps_per_contact`.
    check_index: usize,
    /// The steps of the sweep over t_c.
    dts: Vec<Real>,
    p: Params,
}

/// Every setup with the Minkowski features under one law, gated: the energy error at the checked step,
/// the fitted order and the error at the finest step. Returns the plot's series.
fn setup_runs(
    ctx: &mut CaseContext,
    g: &Sweep,
    law_name: &str,
    law: NormalLaw,
    rows: &mut Vec<Vec<String>>,
) -> Vec<Series> {
    let mut series = Vec::new();
    for setup in SETUPS {
        let mut errors = Vec::new();
        let mut afters = Vec::new();
        for &n in &g.p.steps_per_contact {
            let o = collide(setup, law, n, Variant::Minkowski);
            errors.push(o.in_contact);
            afters.push(o.after);
            ctx.progress().inc(1);
        }
        let order = fitted_order(&g.dts, &errors);
        let tag = format!(
            "{}_{}",
            setup.tag(),
            if law.exponent == 1.0 {
                "linear"
            } else {
                "hertz"
            }
        );
        ctx.check(
            &format!("energy_error_{tag}"),
            errors[g.check_index].max(afters[g.check_index]),
            Target::at_most(g.energy_error),
            "1",
        );
        ctx.check(
            &format!("order_deviation_{tag}"),
            (order - g.order_reference).abs(),
            Target::at_most(g.order_deviation),
            "1",
        );
        ctx.check(
            &format!("finest_energy_error_{tag}"),
            errors[errors.len() - 1],
            Target::at_most(g.finest_energy_error),
            "1",
        );
        rows.push(energy_row(
            format!("{setup:?}"),
            law_name,
            &errors,
            Some(afters[g.check_index]),
            g.check_index,
            order,
        ));
        series.push(Series {
            label: format!("{setup:?}"),
            style: SeriesStyle::LinePoints,
            points: g.dts.iter().copied().zip(errors).collect(),
        });
    }
    series
}

/// The variants shown beside the gated runs under one law: the normal along the centre line (its
/// ratio to the Minkowski normal gated for the linear law), the former deepest-vertex wall law and the
/// exact pair overlap. Returns their series.
fn reference_variants(
    ctx: &mut CaseContext,
    g: &Sweep,
    law_name: &str,
    law: NormalLaw,
    rows: &mut Vec<Vec<String>>,
) -> Vec<Series> {
    let (p, mut series) = (&g.p, Vec::new());
    // The naive variant and the open problem, on the same axes.
    let naive: Vec<(Real, Real)> = p
        .steps_per_contact
        .iter()
        .map(|&n| {
            (
                1.0 / n,
                collide(Setup::VertexFace, law, n, Variant::CentreLineNormal).in_contact,
            )
        })
        .collect();
    let former: Vec<(Setup, Vec<Real>)> = FLAT_WALL_SETUPS
        .iter()
        .map(|&setup| {
            let errors = p
                .steps_per_contact
                .iter()
                .map(|&n| collide(setup, law, n, Variant::WallDeepestVertex).in_contact)
                .collect();
            (setup, errors)
        })
        .collect();
    let exact_pair: Vec<(String, Vec<Real>)> = FLAT_PAIR_SETUPS
        .iter()
        .flat_map(|&setup| {
            [
                (Variant::Minkowski, "smoothed pair overlap"),
                (Variant::PairExact, "exact Minkowski overlap"),
            ]
            .map(|(variant, label)| {
                let errors = p
                    .steps_per_contact
                    .iter()
                    .map(|&n| collide(setup, law, n, variant).in_contact)
                    .collect();
                (format!("{setup:?}, {label}"), errors)
            })
        })
        .collect();
    if law.exponent == 1.0 {
        let ratio = naive[naive.len() - 1].1
            / collide(
                Setup::VertexFace,
                law,
                g.p.steps_per_contact[g.p.steps_per_contact.len() - 1],
                Variant::Minkowski,
            )
            .in_contact;
        ctx.check(
            "naive_centre_line_normal_ratio",
            ratio,
            Target::at_least(g.naive_ratio),
            "1",
        );
    }
    let unchecked = |label: String, errors: &[Real]| {
        let order = fitted_order(&g.dts, errors);
        energy_row(label, law_name, errors, None, g.check_index, order)
    };
    let naive_errors: Vec<Real> = naive.iter().map(|x| x.1).collect();
    rows.push(unchecked(
        "VertexFace, normal along the centre line (naive)".into(),
        &naive_errors,
    ));
    for (setup, errors) in &former {
        let label = format!("{setup:?}, former deepest-vertex wall law (not checked)");
        rows.push(unchecked(label, errors));
    }
    for (label, errors) in &exact_pair {
        rows.push(unchecked(format!("{label} (not checked)"), errors));
    }
    series.push(Series {
        label: "VertexFace, centre-line normal (naive)".into(),
        style: SeriesStyle::LinePoints,
        points: naive,
    });
    for (label, errors) in exact_pair {
        series.push(Series {
            label,
            style: SeriesStyle::LinePoints,
            points: g.dts.iter().copied().zip(errors).collect(),
        });
    }
    for (setup, errors) in former {
        series.push(Series {
            label: format!("{setup:?}, deepest-vertex wall law"),
            style: SeriesStyle::LinePoints,
            points: g.dts.iter().copied().zip(errors).collect(),
        });
    }
    series
}

/// One row of the energy table: the error at the checked time step, the error after the contact (gated
/// runs only), the error at the finest step and the fitted order.
fn energy_row(
    label: String,
    law_name: &str,
    errors: &[Real],
    after: Option<Real>,
    check_index: usize,
    order: Real,
) -> Vec<String> {
    vec![
        label,
        law_name.to_string(),
        CaseContext::fmt(errors[check_index]),
        after.map_or_else(|| "—".into(), CaseContext::fmt),
        CaseContext::fmt(errors[errors.len() - 1]),
        format!("{order:.3}"),
    ]
}

/// The energy table and one plot per law.
fn report_energy(
    ctx: &mut CaseContext,
    p: &Params,
    rows: Vec<Vec<String>>,
    plots: Vec<(String, Vec<Series>)>,
) -> Result<(), SuiteError> {
    ctx.section("Energy error against the time step");
    ctx.text(&format!(
        "Box 1.0 × 0.8 × 0.6 m and sphere of radius 0.25 m, density {DENSITY} kg/m³, approach speed {SPEED} m/s \
         with spin; linear law k_n = 1e8 N/m, Hertz-type k_n = 1e10 N/m^1.5; t_c = the law's elastic contact time \
         for the normal approach. Errors are max |E(t) − E₀|/E₀ during contact and |ΔKE|/KE after separation."
    ));
    ctx.table(
        Some("energy"),
        &[
            "setup",
            "law",
            &format!("in-contact error at t_c/{}", p.check_at),
            &format!("after/before error at t_c/{}", p.check_at),
            "in-contact error at the finest step",
            "fitted order",
        ],
        &rows,
    )?;
    for (law_name, series) in plots {
        let stem = if law_name == "linear" {
            "energy_error_linear"
        } else {
            "energy_error_hertz"
        };
        ctx.plot(&Plot {
            name: stem.into(),
            title: format!("Energy error of elastic single contacts, {law_name} law"),
            x_label: "dt / t_c".into(),
            y_label: "max |E − E₀| / E₀ during contact".into(),
            x_log: true,
            y_log: true,
            series,
            caption: "Minkowski features (all contact types; walls with the smoothed depth): slope 2. Normal along \
                      the centre line: no convergence. Edge or face landing flat on a wall with the former \
                      deepest-vertex law: first order."
                .into(),
        })?;
    }
    Ok(())
}

/// Sensitivity of the flat wall landings to the band h of the smoothed depth.
fn band_sweep(ctx: &mut CaseContext, p: &Params) -> Result<(), SuiteError> {
    let finest = p.steps_per_contact[p.steps_per_contact.len() - 1];
    let mut band_rows = Vec::new();
    for band in BANDS {
        for setup in FLAT_WALL_SETUPS {
            for (law_name, law) in laws() {
                let at = collide(setup, law, p.check_at, Variant::WallBand(band));
                let fine = collide(setup, law, finest, Variant::WallBand(band));
                band_rows.push(vec![
                    format!("{band}"),
                    format!("{setup:?}"),
                    law_name.to_string(),
                    CaseContext::fmt(at.in_contact.max(at.after)),
                    CaseContext::fmt(fine.in_contact),
                    format!(
                        "{:.3}",
                        (at.in_contact / fine.in_contact).ln() / (finest / p.check_at).ln()
                    ),
                ]);
            }
        }
    }
    ctx.section("Band of the smoothed wall depth");
    ctx.text(
        "The wall law's overlap is D = 2 S_h − S_2h, a smoothed maximum of the vertex depths \
         (src/contact/wall_depth.rs). The gated runs above use the rule of that module, h = the scene's \
         characteristic overlap, here the peak overlap δ_peak of the head-on impact \
         (2.5e-3 L for the linear law, 1.4e-3 L for the Hertz-type law, L = 1.41 m the box's bounding \
         diameter); below, h = factor × δ_peak. A band far below the overlap makes rocking stiff (the \
         error at t_c/200 grows, the order stays 2); far above, a resting face is soft in rocking \
         (friction report: creep on an incline).",
    );
    ctx.table(
        Some("band"),
        &[
            "h / δ_peak",
            "setup",
            "law",
            &format!("energy error at t_c/{}", p.check_at),
            &format!("in-contact error at t_c/{finest}"),
            "order between the two",
        ],
        &band_rows,
    )?;
    Ok(())
}

impl Setup {
    fn tag(&self) -> &'static str {
        match self {
            Setup::VertexFace => "vertex_face",
            Setup::EdgeFace => "edge_face",
            Setup::EdgeEdge => "edge_edge",
            Setup::FaceFace => "face_face",
            Setup::BoxWallVertex => "box_wall_vertex",
            Setup::BoxWallEdge => "box_wall_edge",
            Setup::BoxWallFace => "box_wall_face",
            Setup::PolyFaceFlat => "poly_face_flat",
            Setup::PolyEdgeFlat => "poly_edge_flat",
            Setup::SphereBox => "sphere_box",
        }
    }
}
