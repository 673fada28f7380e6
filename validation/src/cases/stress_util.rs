//! Shared pieces of the stability stress cases (`stress_*`): scenes written as scene-file text (so that
//! every stress scene goes through the same parser, validation and time-step guard as a user's scene),
//! seeded random polyhedra, and the drift statistics of an energy-error history.

use std::fmt::Write;
use std::path::Path;

use polydem::math::{Point, Real, Vector};
use polydem::scene::{parse_scene, Simulation};
use polydem::world::tunnelling::{Crossing, CrossingCounts, TunnellingMonitor};
use polydem::world::{step, StepCounters, StepScratch};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::error::SuiteError;

/// A scene file under construction (TOML text in the format of `docs/scene-format.md`).
#[derive(Clone, Debug, Default)]
pub struct SceneText {
    text: String,
}

fn v3(v: &Vector) -> String {
    format!("[{:e}, {:e}, {:e}]", v.x, v.y, v.z)
}

impl SceneText {
    /// The `[simulation]` table; `time_step` is either `("time_step", Δt)` or `("steps_per_contact", N)`.
    pub fn new(
        gravity: Vector,
        end_time: Real,
        output_interval: Real,
        time_step: (&str, Real),
    ) -> Self {
        let mut text = String::new();
        let _ = writeln!(
            text,
            "[simulation]\ngravity = {}\nend_time = {end_time:e}\noutput_interval = {output_interval:e}\n{} = {:e}",
            v3(&gravity),
            time_step.0,
            time_step.1
        );
        Self { text }
    }

    /// An extra line in `[simulation]` (call before any other table), e.g. `characteristic_speed = 10.0`.
    pub fn simulation_line(&mut self, line: &str) -> &mut Self {
        self.text.push_str(line);
        self.text.push('\n');
        self
    }

    pub fn material(&mut self, name: &str, density: Real) -> &mut Self {
        let _ = writeln!(
            self.text,
            "\n[[material]]\nname = \"{name}\"\ndensity = {density:e}"
        );
        self
    }

    /// A frictionless interaction; `exponent` None = linear law.
    pub fn interaction(
        &mut self,
        a: &str,
        b: &str,
        stiffness: Real,
        exponent: Option<Real>,
        restitution: Real,
    ) -> &mut Self {
        let law = match exponent {
            None => "law = \"linear\"".to_string(),
            Some(n) => format!("law = \"power\"\nexponent = {n:e}"),
        };
        let _ = writeln!(
            self.text,
            "\n[[interaction]]\nmaterials = [\"{a}\", \"{b}\"]\n{law}\nnormal_stiffness = {stiffness:e}\nrestitution = {restitution:e}\nfriction = 0.0"
        );
        self
    }

    pub fn polyhedron(&mut self, name: &str, points: &[Point]) -> &mut Self {
        let pts: Vec<String> = points.iter().map(|p| v3(&p.coords)).collect();
        let _ = writeln!(
            self.text,
            "\n[[shape]]\nname = \"{name}\"\nkind = \"polyhedron\"\npoints = [{}]",
            pts.join(", ")
        );
        self
    }

    /// A dynamic body; `axis_angle` and `angular_velocity` in the world frame.
    #[allow(clippy::too_many_arguments)]
    pub fn body(
        &mut self,
        name: &str,
        shape: &str,
        material: &str,
        position: &Vector,
        axis_angle: &Vector,
        velocity: &Vector,
        angular_velocity: &Vector,
    ) -> &mut Self {
        let _ = writeln!(
            self.text,
            "\n[[body]]\nname = \"{name}\"\nshape = \"{shape}\"\nmaterial = \"{material}\"\nposition = {}\naxis_angle = {}\nvelocity = {}\nangular_velocity = {}",
            v3(position),
            v3(axis_angle),
            v3(velocity),
            v3(angular_velocity)
        );
        self
    }

    /// A fixed body (never moves; an obstacle like a wall, but a polyhedron).
    pub fn fixed_body(
        &mut self,
        name: &str,
        shape: &str,
        material: &str,
        position: &Vector,
    ) -> &mut Self {
        let _ = writeln!(
            self.text,
            "\n[[body]]\nname = \"{name}\"\nshape = \"{shape}\"\nmaterial = \"{material}\"\nposition = {}\nmotion = \"fixed\"",
            v3(position)
        );
        self
    }

    /// Six fixed slabs of thickness 2 `half_thickness` lining the box [lo, hi] from outside (they overlap
    /// at the edges, which no body reaches).
    pub fn slab_box(
        &mut self,
        material: &str,
        lo: &Vector,
        hi: &Vector,
        half_thickness: Real,
    ) -> &mut Self {
        let centre = (lo + hi) / 2.0;
        let half = (hi - lo) / 2.0;
        for axis in 0..3 {
            let mut h = half + Vector::repeat(2.0 * half_thickness);
            h[axis] = half_thickness;
            let name = format!("slab{axis}");
            self.polyhedron(&name, &box_points(&h));
            for (side, sign) in [("lo", -1.0), ("hi", 1.0)] {
                let mut pos = centre;
                pos[axis] += sign * (half[axis] + half_thickness);
                self.fixed_body(&format!("{side}{axis}"), &name, material, &pos);
            }
        }
        self
    }

    pub fn wall(
        &mut self,
        name: &str,
        material: &str,
        point: &Vector,
        normal: &Vector,
    ) -> &mut Self {
        let _ = writeln!(
            self.text,
            "\n[[wall]]\nname = \"{name}\"\nmaterial = \"{material}\"\npoint = {}\nnormal = {}",
            v3(point),
            v3(normal)
        );
        self
    }

    /// Six walls enclosing the box [lo, hi].
    pub fn closed_box(&mut self, material: &str, lo: &Vector, hi: &Vector) -> &mut Self {
        for axis in 0..3 {
            let mut n = Vector::zeros();
            n[axis] = 1.0;
            self.wall(&format!("lo{axis}"), material, lo, &n);
            self.wall(&format!("hi{axis}"), material, hi, &(-n));
        }
        self
    }

    pub fn text(&self) -> &str {
        &self.text
    }

    /// Parses and builds the scene (`name` is used in messages); a refusal is a case error naming it.
    pub fn build(&self, case: &str, name: &str) -> Result<Simulation, SuiteError> {
        self.try_build(name).map_err(|e| SuiteError::Case {
            case: case.into(),
            msg: format!("scene {name}: {e}"),
        })
    }

    /// Parses and builds the scene, returning the scene error as is.
    pub fn try_build(&self, name: &str) -> Result<Simulation, polydem::scene::SceneError> {
        parse_scene(&self.text, Path::new(name))
    }
}

/// What a monitored run observed.
#[derive(Clone, Debug, Default)]
pub struct MonitoredRun {
    pub steps: u64,
    pub counters: StepCounters,
    pub crossings: CrossingCounts,
    pub first_crossing: Option<Crossing>,
    /// The step error that stopped the run (non-finite state, failed query), if any.
    pub step_error: Option<String>,
    /// Largest |balance| / E0 (E0 the initial mechanical energy).
    pub energy_error_max: Real,
    /// Largest overlap / particle size at the end of any step.
    pub max_overlap_ratio: Real,
}

/// Runs `steps` steps of `sim` with the tunnelling monitor, calling `sample` at the start and every
/// `every` steps (and after a step error).
pub fn run_monitored(
    sim: &mut Simulation,
    steps: u64,
    every: u64,
    mut sample: impl FnMut(&Simulation),
) -> MonitoredRun {
    let mut run = MonitoredRun::default();
    let mut scratch = StepScratch::default();
    let mut monitor = TunnellingMonitor::new(&sim.world);
    let mut found = Vec::new();
    sample(sim);
    for n in 1..=steps {
        match step(&sim.params, &mut sim.world, &mut scratch) {
            Ok(report) => {
                run.counters.merge(&report.counters);
                run.max_overlap_ratio = run.max_overlap_ratio.max(report.max_overlap_ratio);
            }
            Err(e) => {
                run.step_error = Some(e.to_string());
                sample(sim);
                break;
            }
        }
        run.steps = n;
        found.clear();
        monitor.observe(&sim.world, &mut found);
        for c in &found {
            run.crossings.add(c);
            run.first_crossing.get_or_insert(*c);
        }
        // The ledger's initial energy includes the elastic energy of initial overlaps.
        let e0 = sim.world.ledger().initial_total().unwrap_or(Real::NAN);
        let err = (sim.world.energy().balance / e0).abs();
        run.energy_error_max =
            run.energy_error_max
                .max(if err.is_nan() { Real::INFINITY } else { err });
        if n % every.max(1) == 0 {
            sample(sim);
        }
    }
    run
}

/// A random unit vector.
pub fn random_unit(rng: &mut ChaCha8Rng) -> Vector {
    loop {
        let v = Vector::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
}

/// `n` points on an ellipsoid of semi-axes `axes` (m): a random convex polyhedron.
pub fn ellipsoid_points(rng: &mut ChaCha8Rng, n: usize, axes: &Vector) -> Vec<Point> {
    (0..n)
        .map(|_| Point::from(random_unit(rng).component_mul(axes)))
        .collect()
}

/// The corners of a box of half extents `h` (m).
pub fn box_points(h: &Vector) -> Vec<Point> {
    (0..8)
        .map(|i| {
            let s = |b: usize| if i & (1 << b) != 0 { 1.0 } else { -1.0 };
            Point::new(s(0) * h.x, s(1) * h.y, s(2) * h.z)
        })
        .collect()
}

/// Least-squares line y = a + b t through a history, and the scatter of the residuals about it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriftFit {
    /// Slope b (units of y per unit of t).
    pub slope: Real,
    /// Intercept a.
    pub intercept: Real,
    /// Standard deviation of the residuals y − (a + b t).
    pub residual_std: Real,
    /// b × (t_last − t_first): the change the fitted trend accounts for over the whole history.
    pub fitted_change: Real,
}

/// Fits a straight line to (t, y) by least squares (at least two distinct t).
pub fn drift_fit(points: &[(Real, Real)]) -> DriftFit {
    let n = points.len() as Real;
    let mt = points.iter().map(|p| p.0).sum::<Real>() / n;
    let my = points.iter().map(|p| p.1).sum::<Real>() / n;
    let stt: Real = points.iter().map(|p| (p.0 - mt) * (p.0 - mt)).sum();
    let sty: Real = points.iter().map(|p| (p.0 - mt) * (p.1 - my)).sum();
    let slope = sty / stt;
    let intercept = my - slope * mt;
    let ss: Real = points
        .iter()
        .map(|p| (p.1 - intercept - slope * p.0).powi(2))
        .sum();
    let span = points.last().map_or(0.0, |p| p.0) - points.first().map_or(0.0, |p| p.0);
    DriftFit {
        slope,
        intercept,
        residual_std: (ss / n).sqrt(),
        fitted_change: slope * span,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn drift_fit_recovers_a_line_and_its_noise() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let pts: Vec<(Real, Real)> = (0..10_000)
            .map(|i| {
                let t = i as Real * 1e-3;
                let noise = if rng.random_bool(0.5) { 1e-3 } else { -1e-3 };
                (t, 2.0 + 0.5 * t + noise)
            })
            .collect();
        let f = drift_fit(&pts);
        assert!((f.slope - 0.5).abs() < 1e-4, "slope {}", f.slope);
        assert!(
            (f.intercept - 2.0).abs() < 1e-3,
            "intercept {}",
            f.intercept
        );
        assert!(
            (f.residual_std - 1e-3).abs() < 1e-5,
            "residual std {} expected 1e-3",
            f.residual_std
        );
        assert!((f.fitted_change - 0.5 * 9.999).abs() < 1e-3);
    }

    #[test]
    fn a_scene_text_builds_through_the_parser() {
        let mut s = SceneText::new(Vector::zeros(), 0.1, 0.01, ("steps_per_contact", 50.0));
        s.material("rock", 2600.0)
            .interaction("rock", "rock", 1e6, None, 1.0)
            .polyhedron("cube", &box_points(&Vector::repeat(0.05)))
            .body(
                "a",
                "cube",
                "rock",
                &Vector::new(0.2, 0.2, 0.2),
                &Vector::zeros(),
                &Vector::new(1.0, 0.0, 0.0),
                &Vector::zeros(),
            )
            .closed_box("rock", &Vector::zeros(), &Vector::repeat(0.4));
        let sim = s.build("t", "test").unwrap();
        assert_eq!(sim.world.bodies().len(), 1);
        assert_eq!(sim.world.walls().len(), 6);
        assert!(sim.time_step.derived);
    }
}
