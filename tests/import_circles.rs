//! The layout rule "no file imports a file that imports it back", checked on every crate of the
//! workspace: for each source file, the module files its `use` declarations and `crate::`/`super::`
//! paths name are collected, and no two files may name each other.
//!
//! A file is a module: `a/b.rs` and `a/b/mod.rs` are `a::b`. A path names the longest module prefix
//! it has (`crate::world::step::StepError` names `world::step`). Comments are left out, so a doc link
//! is not an import. `mod` declarations are not imports (a parent declares its children; a child that
//! `use`s its parent's items is the one direction).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Module = Vec<String>;

/// Every `.rs` file below `root`, as its module path.
fn modules(root: &Path) -> BTreeMap<Module, PathBuf> {
    let mut found = BTreeMap::new();
    let mut dirs = vec![root.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        for entry in entries {
            let path = entry.expect("a directory entry").path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path
                    .strip_prefix(root)
                    .expect("below the root")
                    .with_extension("");
                let mut module: Module = rel
                    .iter()
                    .map(|c| c.to_string_lossy().into_owned())
                    .collect();
                if matches!(
                    module.last().map(String::as_str),
                    Some("mod" | "lib" | "main")
                ) {
                    module.pop();
                }
                found.insert(module, path);
            }
        }
    }
    found
}

/// The text without `//` comments (line and doc comments; a `//` inside a string literal cuts the rest
/// of its line, which can only drop paths, never invent one) and without its unit tests (a
/// `#[cfg(test)]` module, by convention the file's last item: test code may use what uses the file).
fn without_comments(text: &str) -> String {
    let code = text.find("#[cfg(test)]\nmod ").map_or(text, |i| &text[..i]);
    code.lines()
        .map(|line| line.find("//").map_or(line, |i| &line[..i]))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The `crate::`, `super::` and `self::` paths of `text`: every such path written out, and the prefix
/// of every `use` group (`use super::{a, b::c}` names `super::a` and `super::b::c`).
fn paths(text: &str) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    for stmt in text.split(';') {
        let Some(at) = stmt.find("use ") else {
            continue;
        };
        let body: String = stmt[at + 4..].split_whitespace().collect();
        if let Some(open) = body.find("::{") {
            let prefix = &body[..open];
            let items = body[open + 3..].trim_end_matches('}');
            for item in items.split(',') {
                let head = item
                    .split(['{', ' '])
                    .next()
                    .unwrap_or("")
                    .trim_end_matches("::");
                if !head.is_empty() && head != "self" {
                    found.push(split(&format!("{prefix}::{head}")));
                }
            }
        }
    }
    let bytes = text.as_bytes();
    for start in ["crate::", "super::", "self::"] {
        for (i, _) in text.match_indices(start) {
            if i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || b"_:".contains(&bytes[i - 1])) {
                continue;
            }
            let end = text[i..]
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                .map_or(text.len(), |n| i + n);
            found.push(split(&text[i..end]));
        }
    }
    found
}

fn split(path: &str) -> Vec<String> {
    path.split("::")
        .filter(|s| !s.is_empty())
        .map(str::to_string)
        .collect()
}

/// The module file a path written in `from` names, if it names one of `known`.
fn resolve(from: &Module, path: &[String], known: &BTreeMap<Module, PathBuf>) -> Option<Module> {
    let (mut base, mut rest) = match path.first()?.as_str() {
        "crate" => (Vec::new(), &path[1..]),
        "self" => (from.clone(), &path[1..]),
        "super" => (from.clone(), path),
        _ => return None,
    };
    while rest.first().is_some_and(|s| s == "super") {
        base.pop();
        rest = &rest[1..];
    }
    base.extend(rest.iter().cloned());
    (0..=base.len())
        .rev()
        .map(|k| base[..k].to_vec())
        .find(|m| known.contains_key(m))
}

/// The pairs of files of the crate at `root` that import each other.
fn circles(root: &Path) -> Vec<(String, String)> {
    let known = modules(root);
    let mut imports: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (module, path) in &known {
        let text =
            std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let named = paths(&without_comments(&text))
            .iter()
            .filter_map(|p| resolve(module, p, &known))
            .filter(|m| m != module)
            .collect();
        imports.insert(module.clone(), named);
    }
    let mut pairs = Vec::new();
    for (a, named) in &imports {
        for b in named.iter().filter(|b| a < *b) {
            if imports.get(b).is_some_and(|back| back.contains(a)) {
                pairs.push((a.join("/"), b.join("/")));
            }
        }
    }
    pairs
}

#[test]
fn no_file_imports_a_file_that_imports_it_back() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let crates = [
        "src",
        "crates/polydem-cli/src",
        "crates/rockfill/src",
        "crates/polydem-mpi/src",
        "validation/src",
        "python/src",
    ];
    let mut found = Vec::new();
    for dir in crates {
        for (a, b) in circles(&repo.join(dir)) {
            found.push(format!("{dir}: {a} <-> {b}"));
        }
    }
    assert!(
        found.is_empty(),
        "files that import each other (expected none):\n{}",
        found.join("\n")
    );
}

#[test]
fn the_check_finds_a_circle() {
    let dir = std::env::temp_dir().join(format!("polydem_import_circles_{}", std::process::id()));
    std::fs::create_dir_all(dir.join("world")).unwrap();
    std::fs::write(dir.join("lib.rs"), "pub mod world;\n").unwrap();
    std::fs::write(dir.join("world/mod.rs"), "mod a;\nmod b;\n").unwrap();
    std::fs::write(dir.join("world/a.rs"), "use super::b::{Thing, other::X};\n").unwrap();
    std::fs::write(
        dir.join("world/b.rs"),
        "// use super::a::Y; (a comment)\npub struct Thing;\n",
    )
    .unwrap();
    assert!(circles(&dir).is_empty(), "a comment is not an import");
    let test_only =
        "pub struct Thing;\n#[cfg(test)]\nmod tests {\n    use super::super::a::Y;\n}\n";
    std::fs::write(dir.join("world/b.rs"), test_only).unwrap();
    assert!(
        circles(&dir).is_empty(),
        "a unit test module is not the file's import"
    );
    std::fs::write(
        dir.join("world/b.rs"),
        "pub struct Thing(crate::world::a::Y);\n",
    )
    .unwrap();
    let found = circles(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(found, vec![("world/a".to_string(), "world/b".to_string())]);
}
