//! Every example scene in `scenes/` loads: parsed, validated, shapes built, time step derived or accepted.
//!
//! The scenes are documentation users copy from; a change of the scene format that breaks one of them must
//! fail here, not in a user's first run.

use polydem::scene::load_scene;
use std::path::Path;

#[test]
fn every_example_scene_loads() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut scenes: Vec<_> = std::fs::read_dir(&dir)
        .expect("scenes/ exists")
        .map(|entry| entry.expect("readable entry").path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "toml"))
        .collect();
    scenes.sort();
    assert!(
        scenes.len() >= 6,
        "expected at least 6 example scenes in {}, found {scenes:?}",
        dir.display()
    );
    for path in &scenes {
        if let Err(error) = load_scene(path) {
            panic!("example scene {} does not load: {error}", path.display());
        }
    }
}
