//! The `polydem` command line.
fn main() {
    println!("polydem {}", env!("CARGO_PKG_VERSION"));
}
