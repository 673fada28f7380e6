//! A projectile's sampled history in a bed penetration and the quantities both bed cases compare
//! (`sphere_bed`: polydem against YADE and LIGGGHTS; `polyhedra_bed`: spheres against polyhedra).
//!
//! One definition serves both pages so that "final depth" or "vertical contact impulse" means the same
//! thing wherever it is tabulated.

use polydem::math::Real;

/// The projectile's samples (one per output interval).
#[derive(Clone, Debug, Default)]
pub struct History {
    /// Time (s).
    pub t: Vec<Real>,
    /// Height of the centre (m).
    pub z: Vec<Real>,
    /// Vertical velocity (m/s).
    pub vz: Vec<Real>,
    /// Vertical resultant contact force (N).
    pub fz: Vec<Real>,
    /// Bodies in contact with the projectile; empty when the source does not record it (the reference
    /// codes' outputs).
    pub contacts: Vec<Real>,
}

impl History {
    /// Appends one sample without a contact count.
    pub fn push(&mut self, t: Real, z: Real, vz: Real, fz: Real) {
        self.t.push(t);
        self.z.push(z);
        self.vz.push(vz);
        self.fz.push(fz);
    }
}

/// The compared quantities of one history.
#[derive(Clone, Copy, Debug)]
pub struct Metrics {
    pub final_depth: Real,
    pub max_depth: Real,
    pub final_vz: Real,
    pub peak_force: Real,
    pub peak_time: Real,
    pub first_contact: Real,
    pub slow_time: Real,
    pub impulse: Real,
    /// Mean number of bodies touching the projectile from the first contact on (`None` without counts).
    pub mean_contacts: Option<Real>,
}

/// Vertical force (N) above which the projectile counts as touching: the reference outputs carry round-off
/// of their gravity subtraction (~1e-16 N) before contact.
const CONTACT_FORCE: Real = 1e-6;

/// The metrics over the samples with t ≤ `t_end` (`Real::INFINITY` for all of them); depth is measured
/// from the start height `z0`, and the slow-down time is the first sample below 10 % of the impact speed
/// `v0`. `None` for a history without samples up to `t_end`.
pub fn metrics(h: &History, z0: Real, v0: Real, t_end: Real) -> Option<Metrics> {
    let n =
        h.t.iter()
            .take_while(|&&t| t <= t_end * (1.0 + 1e-9))
            .count();
    if n == 0 {
        return None;
    }
    let depth = |i: usize| z0 - h.z[i];
    let (mut peak_force, mut peak_time) = (Real::NEG_INFINITY, Real::NAN);
    let (mut first_contact, mut slow_time) = (Real::NAN, Real::NAN);
    let (mut impulse, mut max_depth) = (0.0, Real::NEG_INFINITY);
    let (mut contact_sum, mut contact_samples) = (0.0, 0usize);
    for i in 0..n {
        if h.fz[i] > peak_force {
            peak_force = h.fz[i];
            peak_time = h.t[i];
        }
        if first_contact.is_nan() && h.fz[i] > CONTACT_FORCE {
            first_contact = h.t[i];
        }
        if !first_contact.is_nan() {
            if let Some(c) = h.contacts.get(i) {
                contact_sum += c;
                contact_samples += 1;
            }
        }
        if slow_time.is_nan() && h.vz[i].abs() < 0.1 * v0 {
            slow_time = h.t[i];
        }
        if i > 0 {
            impulse += 0.5 * (h.fz[i] + h.fz[i - 1]) * (h.t[i] - h.t[i - 1]);
        }
        max_depth = max_depth.max(depth(i));
    }
    Some(Metrics {
        final_depth: depth(n - 1),
        max_depth,
        final_vz: h.vz[n - 1],
        peak_force,
        peak_time,
        first_contact,
        slow_time,
        impulse,
        mean_contacts: (!h.contacts.is_empty())
            .then(|| contact_sum / contact_samples.max(1) as Real),
    })
}

/// One tabulated quantity: label, unit, the value in SI units and the factor to the unit shown.
pub struct Quantity {
    pub label: &'static str,
    pub unit: &'static str,
    pub value: fn(&Metrics) -> Real,
    pub scale: Real,
}

/// The quantities every bed page tabulates, in their order on the page.
pub const QUANTITIES: [Quantity; 8] = [
    Quantity::new("final depth", "mm", |m| m.final_depth, 1e3),
    Quantity::new("max depth", "mm", |m| m.max_depth, 1e3),
    Quantity::new("final vertical velocity", "m/s", |m| m.final_vz, 1.0),
    Quantity::new("peak contact force", "N", |m| m.peak_force, 1.0),
    Quantity::new("time of peak force", "ms", |m| m.peak_time, 1e3),
    Quantity::new("first contact", "ms", |m| m.first_contact, 1e3),
    Quantity::new("speed below 10 % of v0 at", "ms", |m| m.slow_time, 1e3),
    Quantity::new("vertical contact impulse", "N s", |m| m.impulse, 1.0),
];

impl Quantity {
    const fn new(
        label: &'static str,
        unit: &'static str,
        value: fn(&Metrics) -> Real,
        scale: Real,
    ) -> Self {
        Self {
            label,
            unit,
            value,
            scale,
        }
    }

    /// The row label with its unit, as the tables print it.
    pub fn heading(&self) -> String {
        format!("{} [{}]", self.label, self.unit)
    }

    /// The value of `m` in the unit shown.
    pub fn of(&self, m: &Metrics) -> Real {
        (self.value)(m) * self.scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A projectile at constant deceleration a from v0 under a constant force F from t = 0: depth, impulse
    /// and slow-down time have closed forms (trapezoid impulse is exact for a constant force).
    #[test]
    fn constant_deceleration_has_closed_form_metrics() {
        let (v0, a, force, dt) = (2.0, 40.0, 3.0, 1e-3);
        let mut h = History::default();
        for i in 0..=40 {
            let t = i as Real * dt;
            h.push(t, 1.0 - (v0 * t - 0.5 * a * t * t), -(v0 - a * t), force);
        }
        let m = metrics(&h, 1.0, v0, Real::INFINITY).expect("samples");
        let t_end = 0.04;
        let depth = v0 * t_end - 0.5 * a * t_end * t_end;
        let rel = |x: Real, y: Real| (x - y).abs() / y.abs();
        assert!(
            rel(m.final_depth, depth) < 1e-12,
            "final depth {} expected {depth}",
            m.final_depth
        );
        assert!(
            rel(m.impulse, force * t_end) < 1e-12,
            "impulse {} expected {}",
            m.impulse,
            force * t_end
        );
        // |v| < 0.2 first when 2 − 40 t < 0.2, i.e. t > 0.045: never within 0.04 s.
        assert!(
            m.slow_time.is_nan(),
            "slow time {} expected none",
            m.slow_time
        );
        assert!(m.mean_contacts.is_none());
        // Cut at t_end = 0.02 s: the last sample is the one at 0.02 s.
        let cut = metrics(&h, 1.0, v0, 0.02).expect("samples");
        let depth_cut = v0 * 0.02 - 0.5 * a * 0.02 * 0.02;
        assert!(
            rel(cut.final_depth, depth_cut) < 1e-12,
            "cut depth {} expected {depth_cut}",
            cut.final_depth
        );
        assert!(metrics(&h, 1.0, v0, -1.0).is_none());
    }
}
