//! The projectile (paper section 4.2): the paper's discretisation, and the hollow body's mass properties
//! (solid − cavity) against closed forms.

use polydem::math::{Point, Vector};
use polydem::shape::mass::polyhedron_mass_properties;
use polydem_rockfill::projectile::{hollow_mass_properties, prism, Projectile, ProjectileParams};
use std::f64::consts::PI;

/// Area and polar second moment of area of a regular n-gon of circumradius r:
/// A = n r² sin θ / 2, J = n r⁴ sin θ (2 + cos θ)/12, θ = 2π/n (sum of the n triangles about the centre).
fn polygon(n: usize, r: f64) -> (f64, f64) {
    let t = 2.0 * PI / n as f64;
    (
        0.5 * n as f64 * r * r * t.sin(),
        n as f64 * r.powi(4) * t.sin() * (2.0 + t.cos()) / 12.0,
    )
}

#[test]
fn hollow_prism_matches_the_closed_form() {
    // A hollow regular 36-gon tube (outer 75 mm, inner 55 mm, 0.4 m long) of steel with an explosive fill.
    let (n, ro, ri, len, rho, fill) = (36, 0.075, 0.055, 0.4, 7850.0, 1700.0);
    let (vo, fo) = prism(n, ro, -0.5 * len, 0.5 * len);
    let (vi, fi) = prism(n, ri, -0.5 * len, 0.5 * len);
    let outer = polyhedron_mass_properties(&vo, &fo);
    let inner = polyhedron_mass_properties(&vi, &fi);
    let (mass, com, inertia) = hollow_mass_properties(&outer, &inner, rho, fill);
    let ((ao, jo), (ai, ji)) = (polygon(n, ro), polygon(n, ri));
    // Per unit density: m = A L, axial I = J L, transverse I = (J/2) L + A L³/12 (regular polygons have
    // isotropic second moments of area, I_y = I_z = J/2).
    let m_exp = rho * ao * len - (rho - fill) * ai * len;
    let axial = |j: f64| j * len;
    let trans = |a: f64, j: f64| 0.5 * j * len + a * len.powi(3) / 12.0;
    let ix_exp = rho * axial(jo) - (rho - fill) * axial(ji);
    let it_exp = rho * trans(ao, jo) - (rho - fill) * trans(ai, ji);
    let checks = [
        ("mass", mass, m_exp),
        ("I_xx", inertia[(0, 0)], ix_exp),
        ("I_yy", inertia[(1, 1)], it_exp),
        ("I_zz", inertia[(2, 2)], it_exp),
    ];
    for (what, got, expected) in checks {
        assert!(
            (got - expected).abs() <= 1e-12 * expected,
            "{what}: {got}, closed form {expected}, rel tol 1e-12"
        );
    }
    assert!(com.coords.norm() <= 1e-14 * len, "centre of mass {com}");
    let off = inertia[(0, 1)]
        .abs()
        .max(inertia[(0, 2)].abs())
        .max(inertia[(1, 2)].abs());
    assert!(off <= 1e-12 * ix_exp, "off-diagonal {off}");
    // The polygonal tube against the circular one: the area ratio is n sin θ/(2π) exactly.
    let t = 2.0 * PI / n as f64;
    let circle = PI * (ro * ro - ri * ri) * len;
    let ratio = (ao - ai) * len / circle;
    assert!((ratio - n as f64 * t.sin() / (2.0 * PI)).abs() < 1e-14);
}

#[test]
fn hollow_prism_with_offset_cavity_uses_the_parallel_axis_theorem() {
    // A solid 8-gon bar of length 1 with a cavity of length 0.2 at x ∈ [0.1, 0.3]: the centre of mass moves
    // to −V_c ρ d/m and the transverse moment picks up the parallel-axis terms.
    let (n, r, rc) = (8, 0.1, 0.05);
    let (vo, fo) = prism(n, r, -0.5, 0.5);
    let (vi, fi) = prism(n, rc, 0.1, 0.3);
    let outer = polyhedron_mass_properties(&vo, &fo);
    let inner = polyhedron_mass_properties(&vi, &fi);
    let (mass, com, inertia) = hollow_mass_properties(&outer, &inner, 1.0, 0.0);
    let ((ao, jo), (ai, ji)) = (polygon(n, r), polygon(n, rc));
    let (vo_, vi_) = (ao * 1.0, ai * 0.2);
    let m = vo_ - vi_;
    let x = -vi_ * 0.2 / m;
    let it = (0.5 * jo + ao / 12.0 + vo_ * x * x)
        - (0.5 * ji * 0.2 + ai * 0.2f64.powi(3) / 12.0 + vi_ * (0.2 - x).powi(2));
    assert!((mass - m).abs() <= 1e-13 * m, "mass {mass} vs {m}");
    assert!((com.x - x).abs() <= 1e-13, "com.x {} vs {x}", com.x);
    assert!(
        (inertia[(1, 1)] - it).abs() <= 1e-12 * it,
        "I_yy {} vs {it}, rel tol 1e-12",
        inertia[(1, 1)]
    );
}

#[test]
fn paper_projectile_discretisation_and_hollow_mass() {
    let p = ProjectileParams::paper();
    let proj = Projectile::new(p).unwrap();
    // 12 head divisions × 36 around: the base ring, the shoulder ring, 11 ogive rings and the tip.
    assert_eq!(proj.shape.vertices().len(), 36 * 13 + 1);
    // Faces: base cap, 36 cylinder quads, 11 × 36 ogive quads, 36 tip triangles.
    assert_eq!(proj.shape.num_faces(), 1 + 36 + 11 * 36 + 36);
    // Length and diameter of the hull.
    let axis = proj.axis_body;
    let (lo, hi) = proj
        .shape
        .vertices()
        .iter()
        .map(|v| v.coords.dot(&axis))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    assert!(((hi - lo) - p.length).abs() < 1e-12, "length {}", hi - lo);
    // Mass: ρ (V_hull − V_cavity) with the cavity a 36-gon prism of circumradius D/2 − t.
    let v_hull = proj.shape.mass_properties().volume;
    let (a_c, j_c) = polygon(36, p.diameter / 2.0 - p.wall_thickness);
    let l_c = proj.cavity_x.1 - proj.cavity_x.0;
    let m_exp = p.density * (v_hull - a_c * l_c);
    assert!(
        (proj.mass - m_exp).abs() <= 1e-12 * m_exp,
        "mass {}, expected {m_exp}",
        proj.mass
    );
    // Axial moment: the hull's minus the cavity's closed form ρ J_c L_c.
    let j_axial = |d: Vector| d.component_mul(&d).dot(&proj.inertia.0);
    let hull_axial = p.density * j_axial_of(&proj.shape.mass_properties().principal_moments, &axis);
    let expected = hull_axial - p.density * j_c * l_c;
    let got = j_axial(axis);
    assert!(
        (got - expected).abs() <= 1e-10 * expected,
        "axial moment {got}, expected {expected}"
    );
    // The cavity sits inside the cylindrical part, behind the solid nose, with the base plate kept.
    let shoulder = p.length - p.nose_length();
    assert!(proj.cavity_x.0 >= p.base_thickness - 1e-12 && proj.cavity_x.1 <= shoulder + 1e-12);
    assert!(proj.mass < proj.solid_mass);
    eprintln!(
        "projectile: mass {:.3} kg (solid {:.3} kg), cavity length {l_c:.4} m, moments {:?}",
        proj.mass, proj.solid_mass, proj.inertia.0
    );
    // Tip placement: the tip lands where asked, the axis along the direction.
    let tip = Point::new(-0.6, 1.35, 1.75);
    let pose = proj.pose_with_tip_at(&tip, &Vector::x());
    let tip_world = proj
        .shape
        .vertices()
        .iter()
        .map(|v| pose * v)
        .max_by(|a, b| a.x.total_cmp(&b.x))
        .unwrap();
    assert!(
        (tip_world - tip).norm() < 1e-12,
        "tip at {tip_world}, asked {tip}"
    );
}

fn j_axial_of(moments: &Vector, axis: &Vector) -> f64 {
    axis.component_mul(axis).dot(moments)
}
