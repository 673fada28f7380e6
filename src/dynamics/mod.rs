//! Rigid-body dynamics: body state, translation (velocity Verlet with gravity and viscous damping, paper
//! eq. 6), rotation (the DLM symplectic splitting of paper eqs. 18–25, plus simpler schemes for comparison),
//! the per-body kick–drift–kick step, and exact torque-free solutions used as references.

pub mod analytic;
pub mod body;
pub mod integrator;
pub mod rotation;
pub mod translation;

pub use body::{BodyError, Motion, PrincipalInertia, RigidBody};
pub use integrator::Integrator;
pub use rotation::{RotationScheme, SubRotation};
pub use translation::{TranslationParams, ViscousDamping};
