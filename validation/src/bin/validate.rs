//! `cargo validate [--quick|--full] [CASE...]`.
fn main() {
    println!("polydem validation suite");
}
