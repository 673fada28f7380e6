//! The isotropic-rotation fast path (`Skips::isotropic_rotation`): a body with equal principal moments (a
//! sphere) turns once about its angular momentum instead of going through the five sub-rotations of the
//! splitting, and its ω is L/J.
//!
//! - Exactness: a free spinning sphere stepped with the fast path (exact sub-rotation form) follows the
//!   closed-form rotation q(t) = exp(t L/J) q₀ to round-off, while the splitting deviates at second order
//!   in Δt (`dynamics::rotation::isotropic` proves the order on a single drift).
//! - Equivalence on a bed: spheres with friction (spinning, colliding) over 300 steps, fast path on vs off.
//!   A sphere's contact geometry does not depend on its orientation, so the fast path changes the forces
//!   only through ω (round-off: L/J against R J̄⁻¹ Rᵀ L); a granular bed amplifies that round-off, as for
//!   the query skips (`tests/world_skips.rs`), so positions and velocities are held to the same 1e-12 of
//!   the size and of the initial speed. Orientations differ by the splitting's own error: held to 1e-6 rad
//!   (a surface displacement of 1e-6 of the radius), the bound of its local error (ω Δt)³ ≈ 1.6e-8 (ω Δt ≈
//!   2.5e-3 at the bed's spins: 2 m/s over 0.045 m at Δt = t_c/40) summed over 300 steps, 5e-6, with the
//!   typical cancellation; the measured value is printed.

#[path = "support/bed.rs"]
mod bed;

use polydem::dynamics::{PrincipalInertia, RigidBody, RotationScheme, SubRotation};
use polydem::math::{Point, Real, Rotation, Vector};
use polydem::shape::{Shape, Sphere};
use polydem::world::{step, MaterialTable, Skips, StepParams, StepScratch, World};

const STEPS: usize = 300;

fn run_bed(skips: Skips) -> (World, Real, Real) {
    let spec = bed::BedSpec {
        gap: 0.0,
        speed: 2.0,
        ..bed::BedSpec::rocks([5, 5, 6], 1, 21)
    };
    let mut bed = bed::build(&spec);
    bed.params.skips = skips;
    let mut scratch = StepScratch::default();
    for _ in 0..STEPS {
        step(&bed.params, &mut bed.world, &mut scratch).expect("step");
    }
    (bed.world, bed.diameter, spec.speed)
}

#[test]
fn sphere_bed_with_and_without_the_isotropic_fast_path_agree_within_tolerance() {
    let (on, d, v0) = run_bed(Skips::all(true));
    let off_skips = Skips {
        isotropic_rotation: false,
        ..Skips::all(true)
    };
    let (off, _, _) = run_bed(off_skips);
    assert!(
        (0..on.bodies().len()).all(|i| matches!(on.shape(i), Shape::Sphere(_))),
        "the bed must be all spheres"
    );
    let spinning = on
        .bodies()
        .iter()
        .filter(|b| b.angular_momentum.norm() > 0.0)
        .count();
    assert!(
        spinning > on.bodies().len() / 2,
        "only {spinning} of {} spheres spin: the fast path would not be exercised",
        on.bodies().len()
    );
    let (mut dx, mut dv, mut angle) = (0.0f64, 0.0f64, 0.0f64);
    for (a, b) in on.bodies().iter().zip(off.bodies()) {
        assert!(
            matches!(a.motion, polydem::dynamics::Motion::Dynamic),
            "bed bodies are dynamic"
        );
        dx = dx.max((a.position - b.position).norm());
        dv = dv.max((a.velocity - b.velocity).norm());
        angle = angle.max(a.orientation.angle_to(&b.orientation));
    }
    eprintln!(
        "isotropic fast path on vs off after {STEPS} steps: max |Δx|/d = {:e}, max |Δv|/v0 = {:e}, max orientation difference {angle:e} rad",
        dx / d,
        dv / v0
    );
    assert!(
        dx / d <= 1e-12,
        "max position difference {dx:e} m = {:e} d, tolerance 1e-12 d (d = {d} m)",
        dx / d
    );
    assert!(
        dv / v0 <= 1e-12,
        "max velocity difference {dv:e} m/s = {:e} v0, tolerance 1e-12 v0 (v0 = {v0} m/s)",
        dv / v0
    );
    assert!(
        angle <= 1e-6 && angle > 0.0,
        "max orientation difference {angle:e} rad, expected in (0, 1e-6] (the splitting's error; 0 would mean the fast path was not taken)"
    );
}

#[test]
fn free_sphere_follows_the_closed_form_rotation_with_the_fast_path_only() {
    // One sphere, no gravity, no contact: the torque-free rotation is q(t) = exp(t ω) q₀ with ω = L/J.
    let sphere = Sphere::new(0.05).expect("sphere");
    let props = sphere.mass_properties();
    let mass = 2500.0 * props.volume;
    let moments = props.principal_moments * 2500.0;
    let q0 = Rotation::from_scaled_axis(Vector::new(0.3, -0.1, 0.8));
    let l = Vector::new(0.4, 1.1, -0.7) * moments.x;
    let run = |skips: Skips| {
        let mut world = World::new(Vector::zeros(), MaterialTable::default(), 0.001);
        let shape = world.add_shape(Shape::Sphere(sphere));
        let mut materials = MaterialTable::default();
        let m = materials.add_material("m");
        materials.set_model(m, m, bed::model_of(&bed::BedSpec::rocks([1, 1, 1], 1, 0)));
        world.set_materials(materials).expect("no body yet");
        let mut body = RigidBody::new_dynamic(
            Point::origin(),
            mass,
            PrincipalInertia::new(moments).expect("inertia"),
        )
        .expect("body");
        body.orientation = q0;
        body.angular_momentum = l;
        world.add_body("ball", shape, m, body).expect("add");
        let mut params = StepParams::new(1e-3);
        params.rotation = RotationScheme::Splitting {
            sub_rotation: SubRotation::Exact,
        };
        params.skips = skips;
        let mut scratch = StepScratch::default();
        for _ in 0..1000 {
            step(&params, &mut world, &mut scratch).expect("step");
        }
        world.bodies()[0].orientation
    };
    let t = 1.0;
    let exact = Rotation::from_scaled_axis(l * (t / moments.x)) * q0;
    let fast = run(Skips::all(true)).angle_to(&exact);
    let split = run(Skips {
        isotropic_rotation: false,
        ..Skips::all(true)
    })
    .angle_to(&exact);
    eprintln!("after 1000 steps (|ω| t = {:.3} rad): fast path {fast:e} rad from the closed form, splitting {split:e} rad", l.norm() / moments.x * t);
    assert!(
        fast <= 1e-12,
        "fast path: {fast:e} rad from the closed-form rotation, tolerance 1e-12 (round-off over 1000 steps)"
    );
    assert!(
        split > 100.0 * fast.max(1e-15),
        "the splitting ({split:e} rad) should be visibly off the closed form compared with the fast path ({fast:e} rad)"
    );
}
