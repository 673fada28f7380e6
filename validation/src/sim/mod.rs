//! Small simulation drivers shared by the cases and the `tests/` gates (no copies of the time loop).

pub mod incline;
pub mod rolling;
pub mod two_body;
