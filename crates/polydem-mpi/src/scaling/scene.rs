//! The scenes of the scaling runs: a lattice of bodies in a box open at the top, thrown with seeded
//! random velocities so that they collide, settle under gravity and trigger list rebuilds (and with them
//! the cuts of a distributed run).
//!
//! The lattice is `nx × ny × nz` sites of spacing `s`; a weak-scaling run on P ranks takes `nx = P · nx₀`
//! so that recursive bisection cuts it along x into P slabs of the one-rank scene's size. Two kinds:
//! spheres (radius 5 mm, s = 2.1 r) and polyhedra (cubes of half side 5 mm given as 8 hull points, placed
//! face to face with the same gap, s = 2.2 h, so that they collide within the first steps). Both use the linear law
//! with Δt = t_c / 20 and no energy ledger (the runs time the step, not its audit).

use std::fmt::Write;

/// Which bodies fill the lattice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    /// Spheres of radius [`SIZE`].
    Spheres,
    /// Cubes of half side [`SIZE`] (polyhedra through GJK/EPA).
    Polyhedra,
}

/// The radius of a sphere, the half side of a cube (m).
pub const SIZE: f64 = 5.0e-3;

/// The largest initial speed along each axis (m/s).
const THROW_SPEED: f64 = 0.2;

impl SceneKind {
    /// The name used on the command line and in the CSV.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Spheres => "spheres",
            SceneKind::Polyhedra => "polyhedra",
        }
    }

    /// The kind named `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        [SceneKind::Spheres, SceneKind::Polyhedra]
            .into_iter()
            .find(|k| k.name() == name)
    }

    /// The lattice spacing (m).
    pub fn spacing(self) -> f64 {
        match self {
            SceneKind::Spheres => 2.1 * SIZE,
            SceneKind::Polyhedra => 2.2 * SIZE,
        }
    }

    fn shape_section(self) -> String {
        match self {
            SceneKind::Spheres => {
                format!("[[shape]]\nname = \"grain\"\nkind = \"sphere\"\nradius = {SIZE:e}\n\n")
            }
            SceneKind::Polyhedra => {
                let mut points = String::new();
                for k in 0..8 {
                    let c = |bit: usize| if k >> bit & 1 == 1 { SIZE } else { -SIZE };
                    let _ = writeln!(points, "  [{:e}, {:e}, {:e}],", c(0), c(1), c(2));
                }
                format!(
                    "[[shape]]\nname = \"grain\"\nkind = \"polyhedron\"\npoints = [\n{points}]\n\n"
                )
            }
        }
    }
}

/// The lattice sites along each axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lattice {
    /// Sites along x (the tiled axis).
    pub nx: usize,
    /// Sites along y.
    pub ny: usize,
    /// Sites along z.
    pub nz: usize,
}

impl Lattice {
    /// The number of bodies.
    pub fn bodies(&self) -> usize {
        self.nx * self.ny * self.nz
    }
}

/// SplitMix64: a small seeded generator, so the scenes depend on nothing but the seed.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e3779b97f4a7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58476d1ce4e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d049bb133111eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [-a, a].
    fn symmetric(&mut self, a: f64) -> f64 {
        a * (2.0 * self.next() - 1.0)
    }
}

const HEADER: &str = "[simulation]
gravity = [0.0, 0.0, -9.81]
end_time = 1.0
output_interval = 1.0
max_steps = 10000000
steps_per_contact = 20
energy_ledger = false

[[material]]
name = \"grain\"
density = 2500.0

[[interaction]]
materials = [\"grain\", \"grain\"]
law = \"linear\"
normal_stiffness = 1.0e4
restitution = 0.5
tangential_stiffness = 5.0e3
friction = 0.3

";

/// The scene's TOML text: the lattice `lattice` of `kind`, velocities drawn from `seed`.
pub fn scene_toml(kind: SceneKind, lattice: Lattice, seed: u64) -> String {
    let s = kind.spacing();
    let mut text = String::from(HEADER);
    text.push_str(&kind.shape_section());
    let top = (lattice.nz as f64 + 10.0) * s;
    let _ = write!(
        text,
        "[[box]]\nname = \"box\"\nmaterial = \"grain\"\nmin = [0.0, 0.0, 0.0]\nmax = [{:e}, {:e}, {top:e}]\nopen = [\"z+\"]\n\n",
        lattice.nx as f64 * s,
        lattice.ny as f64 * s,
    );
    let mut rng = SplitMix(seed);
    let mut index = 0;
    for k in 0..lattice.nz {
        for j in 0..lattice.ny {
            for i in 0..lattice.nx {
                let at = |n: usize| (n as f64 + 0.5) * s;
                let v: Vec<f64> = (0..3).map(|_| rng.symmetric(THROW_SPEED)).collect();
                let _ = write!(
                    text,
                    "[[body]]\nname = \"g{index}\"\nshape = \"grain\"\nmaterial = \"grain\"\n\
                     position = [{:e}, {:e}, {:e}]\nvelocity = [{:e}, {:e}, {:e}]\n\n",
                    at(i),
                    at(j),
                    at(k),
                    v[0],
                    v[1],
                    v[2]
                );
                index += 1;
            }
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_generated_scene_builds_with_one_body_per_site_inside_its_box() {
        for kind in [SceneKind::Spheres, SceneKind::Polyhedra] {
            let lattice = Lattice {
                nx: 3,
                ny: 2,
                nz: 2,
            };
            let text = scene_toml(kind, lattice, 7);
            let sim = polydem::scene::parse_scene(&text, std::path::Path::new("generated.toml"))
                .unwrap_or_else(|e| panic!("{}: {e}", kind.name()));
            assert_eq!(
                sim.world.body_count(),
                lattice.bodies(),
                "{}: bodies built, expected one per site",
                kind.name()
            );
            let s = kind.spacing();
            for (i, b) in sim.world.bodies().iter().enumerate() {
                let p = b.position;
                let inside = p.x > 0.0 && p.x < 3.0 * s && p.y > 0.0 && p.y < 2.0 * s && p.z > 0.0;
                assert!(
                    inside,
                    "{}: body {i} at {p:?} outside the box of spacing {s}",
                    kind.name()
                );
            }
        }
    }
}
