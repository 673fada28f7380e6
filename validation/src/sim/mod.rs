//! Small simulation drivers shared by the cases and the `tests/` gates (no copies of the time loop).

pub mod two_body;
