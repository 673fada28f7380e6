//! Issue 3, gate 1 as `cargo test` gates: single-contact energy conservation of the Minkowski-overlap normal
//! law for polyhedra. The scenes and the measurement live in the validation case
//! `polydem_validation::cases::single_contact_energy` (documented there); the case's report adds the plots.

use polydem::law::NormalLaw;
use polydem::math::Real;
use polydem_validation::cases::single_contact_energy::{collide, laws, Setup, Variant, SETUPS};
use polydem_validation::stats::fitted_order;

#[test]
fn elastic_polyhedral_impacts_conserve_energy_at_second_order() {
    let sweep = [50.0, 100.0, 200.0, 400.0, 800.0, 1600.0, 3200.0];
    for setup in SETUPS {
        for (name, law) in laws() {
            let mut errors = Vec::new();
            let mut afters = Vec::new();
            let mut steps = Vec::new();
            for per_contact in sweep {
                let o = collide(setup, law, per_contact, Variant::Minkowski);
                errors.push(o.in_contact);
                afters.push(o.after);
                steps.push(o.steps_in_contact);
            }
            println!("{setup:?} {name}: in-contact errors {errors:?}, after {afters:?}, steps in contact {steps:?}");
            let at_200 = errors[2].max(afters[2]);
            assert!(
                at_200 < 1e-4,
                "{setup:?}, {name} law: energy error {at_200:e} at dt = t_c/200, tolerance 1e-4; sweep {errors:?}"
            );
            let dts: Vec<Real> = sweep.iter().map(|s| 1.0 / s).collect();
            let order = fitted_order(&dts, &errors);
            assert!(
                (order - 2.0).abs() <= 0.2,
                "{setup:?}, {name} law: fitted order of the in-contact energy error {order}, expected 2 ± 0.2; errors {errors:?}"
            );
            assert!(
                errors[6] < 1e-6,
                "{setup:?}, {name} law: energy error {:e} at dt = t_c/3200, expected below 1e-6",
                errors[6]
            );
        }
    }
}

#[test]
fn normal_along_the_line_of_centres_does_not_conserve_energy() {
    // The naive variant: same overlap δ_M and point c_M, normal along x_B − x_A (the sphere rule). Its energy
    // error does not vanish as dt → 0 for an eccentric vertex–face contact with spin.
    let law = NormalLaw::linear(1e8).unwrap();
    let coarse = collide(Setup::VertexFace, law, 800.0, Variant::CentreLineNormal);
    let fine = collide(Setup::VertexFace, law, 3200.0, Variant::CentreLineNormal);
    let correct = collide(Setup::VertexFace, law, 3200.0, Variant::Minkowski);
    println!(
        "naive centre-line normal: {:e} (t_c/800), {:e} (t_c/3200); Minkowski normal: {:e}",
        coarse.in_contact, fine.in_contact, correct.in_contact
    );
    assert!(
        fine.in_contact > 100.0 * correct.in_contact && fine.in_contact > 0.5 * coarse.in_contact,
        "centre-line normal: energy error {:e} at t_c/3200 ({:e} at t_c/800) should stay far above the Minkowski error {:e}",
        fine.in_contact,
        coarse.in_contact,
        correct.in_contact
    );
}

/// Open problem: an edge of a spinning box landing flat on a wall (both end vertices penetrate). The
/// polyhedron–plane fast path (`contact_polyhedron_plane.rs`) first applied the force at the depth-weighted
/// centroid of the penetrating vertices: measured energy error 9.8 % (linear law), the same at every dt from
/// t_c/50 to t_c/3200. It now applies it at the deepest vertex (the gradient point of δ = max(d_i)), as the
/// `Variant::WallSupportPoint` check here does: 2.5e-3 at t_c/200 (and at t_c/800), converging only at first
/// order over the whole sweep (fitted 0.86 from t_c/50 to t_c/6400, 3.6e-4 at t_c/6400; report
/// `single_contact_energy`). δ = max(d₁, d₂) has a kink where the two vertices are equally deep, and the
/// spinning box rocks across it, so the force is discontinuous and velocity Verlet loses its second order. A single vertex landing first
/// (`BoxWallVertex`, main gate) conserves energy at second order. Kept as a failing gate until the wall
/// contact of a flat edge or face is made energy-consistent.
#[test]
#[ignore = "open problem: an edge landing flat on a wall is not energy-conserving (see the doc comment)"]
fn elastic_box_edge_on_wall_conserves_energy() {
    for (name, law) in laws() {
        for variant in [Variant::Minkowski, Variant::WallSupportPoint] {
            let o = collide(Setup::BoxWallEdge, law, 200.0, variant);
            assert!(
                o.in_contact.max(o.after) < 1e-4,
                "box edge on wall, {name} law, {variant:?}: energy error {:e} in contact, {:e} after, at dt = t_c/200, tolerance 1e-4",
                o.in_contact,
                o.after
            );
        }
    }
}
