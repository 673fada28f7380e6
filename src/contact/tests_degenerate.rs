//! The degenerate set: configurations where GJK/EPA implementations are known to break (aligned and
//! identical boxes, concentric shapes, ties between optimal directions, parallel edges, vertex on vertex,
//! face exactly on face), each checked against the exact SAT answer with the gate of `tests_oracle`.

use super::testing::{random_rotation, TestPolytope};
use super::tests_oracle::{check_pair, random_tetrahedron, Stats};
use crate::math::{Point, Pose, Real, Rotation, Vector};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

struct Case {
    name: String,
    a: TestPolytope,
    pos1: Pose,
    b: TestPolytope,
    pos2: Pose,
}

/// Places a pair given in a common frame (poses `p1`, `p2`) under the global pose `g`.
fn place(name: String, a: &TestPolytope, p1: Pose, b: &TestPolytope, p2: Pose, g: &Pose) -> Case {
    Case {
        name,
        a: a.clone(),
        pos1: g * p1,
        b: b.clone(),
        pos2: g * p2,
    }
}

fn cases(size: Real, g: &Pose, tag: &str) -> Vec<Case> {
    let mut out = Vec::new();
    let id = Pose::identity();
    let at = |x: Real, y: Real, z: Real| Pose::translation(x, y, z);
    let overlaps = [0.0, 1e-9, 1e-6, 1e-3, 0.1, 0.3];
    // 1. Identical axis-aligned boxes stacked face to face, with lateral shifts (none, partial, edge-aligned).
    let h = Vector::new(1.0, 0.7, 0.5) * size;
    let bx = TestPolytope::cuboid(h);
    for &d in &overlaps {
        for (sx, sy) in [(0.0, 0.0), (0.3, 0.1), (1.0, 0.0), (1.0, 1.0), (2.0, 0.0)] {
            let p2 = at(sx * h.x, sy * h.y, 2.0 * h.z - d * size);
            out.push(place(
                format!("{tag} stacked boxes d={d} shift=({sx},{sy})"),
                &bx,
                id,
                &bx,
                p2,
                g,
            ));
        }
    }
    // A cube on a cube: ties between the face normal and other directions.
    let cube = TestPolytope::cuboid(Vector::repeat(size));
    for &d in &overlaps {
        out.push(place(
            format!("{tag} stacked cubes d={d}"),
            &cube,
            id,
            &cube,
            at(0.0, 0.0, (2.0 - d) * size),
            g,
        ));
    }
    // 2. Concentric shapes: identical cubes (six tied optimal axes), identical boxes, nested boxes,
    // identical and rotated tetrahedra.
    out.push(place(
        format!("{tag} concentric cubes"),
        &cube,
        id,
        &cube,
        id,
        g,
    ));
    out.push(place(
        format!("{tag} concentric boxes"),
        &bx,
        id,
        &bx,
        id,
        g,
    ));
    let small = TestPolytope::cuboid(Vector::new(0.2, 0.3, 0.1) * size);
    out.push(place(format!("{tag} nested boxes"), &bx, id, &small, id, g));
    let rot = Pose::from_parts(
        Vector::zeros().into(),
        Rotation::from_euler_angles(0.3, 0.2, 0.1),
    );
    out.push(place(
        format!("{tag} concentric rotated boxes"),
        &bx,
        id,
        &bx,
        rot,
        g,
    ));
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let reg = TestPolytope::tetrahedron([
        Point::new(1.0, 1.0, 1.0) * size,
        Point::new(1.0, -1.0, -1.0) * size,
        Point::new(-1.0, 1.0, -1.0) * size,
        Point::new(-1.0, -1.0, 1.0) * size,
    ]);
    out.push(place(
        format!("{tag} concentric regular tetrahedra"),
        &reg,
        id,
        &reg,
        id,
        g,
    ));
    let flip = Pose::from_parts(
        Vector::zeros().into(),
        Rotation::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
    );
    out.push(place(
        format!("{tag} concentric dual tetrahedra"),
        &reg,
        id,
        &reg,
        flip,
        g,
    ));
    for k in 0..4 {
        let t = random_tetrahedron(&mut rng, size);
        out.push(place(
            format!("{tag} concentric tetrahedra {k}"),
            &t,
            id,
            &t,
            id,
            g,
        ));
        // 3. Same-orientation tetrahedra, translated along a face normal, an edge and a vertex direction.
        for (j, dir) in [
            Vector::x(),
            Vector::new(1.0, 1.0, 0.0),
            Vector::new(1.0, 1.0, 1.0),
        ]
        .iter()
        .enumerate()
        {
            for &f in &[0.0, 0.5, 1.0] {
                let off = dir.normalize() * f * size;
                out.push(place(
                    format!("{tag} same-orientation tetrahedra {k} dir {j} f={f}"),
                    &t,
                    id,
                    &t,
                    at(off.x, off.y, off.z),
                    g,
                ));
            }
        }
    }
    // 4. Parallel edge–edge: two boxes rotated 45° about x, edges along x meeting (touching and overlapping).
    let r45 = Rotation::from_euler_angles(std::f64::consts::FRAC_PI_4, 0.0, 0.0);
    let e = size * (h.y * h.y + h.z * h.z).sqrt() / size;
    let top = (h.y + h.z) / std::f64::consts::SQRT_2; // half height of the rotated box along z
    let _ = e;
    for &d in &overlaps {
        for sx in [0.0, 0.5, 2.0] {
            let p1 = Pose::from_parts(Vector::zeros().into(), r45);
            let p2 = Pose::from_parts(Vector::new(sx * h.x, 0.0, 2.0 * top - d * size).into(), r45);
            out.push(place(
                format!("{tag} parallel edges d={d} sx={sx}"),
                &bx,
                p1,
                &bx,
                p2,
                g,
            ));
        }
    }
    // 5. Vertex on vertex: cube diagonals along z, apex to apex.
    let diag = Rotation::rotation_between(&Vector::new(1.0, 1.0, 1.0), &Vector::z())
        .expect("non-opposite");
    let diag_down = Rotation::rotation_between(&Vector::new(1.0, 1.0, 1.0), &-Vector::z())
        .expect("non-opposite");
    for &d in &overlaps {
        let p1 = Pose::from_parts(Vector::zeros().into(), diag);
        let p2 = Pose::from_parts(
            Vector::new(0.0, 0.0, (2.0 * 3f64.sqrt() - d) * size).into(),
            diag_down,
        );
        out.push(place(
            format!("{tag} vertex on vertex d={d}"),
            &cube,
            p1,
            &cube,
            p2,
            g,
        ));
    }
    // 6. A face resting exactly on a face: a tetrahedron with a face in z = 0 on a box's top face.
    let base = TestPolytope::tetrahedron([
        Point::new(0.0, 0.0, 0.0),
        Point::new(size, 0.0, 0.0),
        Point::new(0.0, size, 0.0),
        Point::new(0.2 * size, 0.3 * size, 0.8 * size),
    ]);
    let zmin = base
        .verts
        .iter()
        .map(|p| p.z)
        .fold(Real::INFINITY, Real::min);
    for &d in &overlaps {
        for sx in [0.0, 0.4, 0.9] {
            let p2 = at(sx * h.x, 0.1 * h.y, h.z - zmin - d * size);
            out.push(place(
                format!("{tag} face on face d={d} sx={sx}"),
                &bx,
                id,
                &base,
                p2,
                g,
            ));
        }
    }
    out
}

#[test]
fn degenerate_set_matches_sat() {
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    let mut stats = Stats::default();
    let mut failures = Vec::new();
    for size in [1e-3, 1.0, 1e3] {
        let mut globals = vec![("aligned".to_string(), Pose::identity())];
        for k in 0..3 {
            let t = Vector::new(0.3, -1.2, 2.5) * size * (k as Real);
            globals.push((
                format!("rotated{k}"),
                Pose::from_parts(t.into(), random_rotation(&mut rng)),
            ));
        }
        for (tag, g) in &globals {
            for c in cases(size, g, &format!("size {size:e} {tag}")) {
                if let Err(e) = check_pair(&c.name, &c.pos1, &c.a, &c.pos2, &c.b, &mut stats) {
                    failures.push(e);
                }
            }
        }
    }
    println!("{stats:?}");
    assert!(
        failures.is_empty(),
        "{} of {} degenerate pairs failed; first ones:\n{}",
        failures.len(),
        stats.pairs,
        failures
            .iter()
            .take(4)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n\n")
    );
}
