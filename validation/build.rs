//! Builds the C/C++ shims of the peer collision libraries when the `peers` feature is on.
//!
//! libccd and Bullet are looked up with `pkg-config` (libccd: `ccd`; Bullet: `bullet-float64`, Debian's
//! double precision build). coal is looked up in the prefix named by `POLYDEM_COAL_PREFIX` (the
//! `cmeel.prefix` directory of its `libcoal` wheel, with `cmeel-eigen` installed beside it: headers under
//! `include/`, Eigen under `include/eigen3/`, `libcoal.so` under `lib/`); the binaries find `libcoal.so`
//! through an rpath to that directory, and its version is passed on as `POLYDEM_COAL_VERSION`. A library
//! that is found is compiled in and announced to the crate as the cfg `peer_ccd` / `peer_bullet` /
//! `peer_coal`; one that is missing is left out with a build warning, and the contact case says so in its
//! report. Without the feature nothing is built or linked.

use std::process::Command;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(peer_ccd)");
    println!("cargo::rustc-check-cfg=cfg(peer_bullet)");
    println!("cargo::rustc-check-cfg=cfg(peer_coal)");
    println!("cargo::rerun-if-changed=peers");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=PKG_CONFIG_PATH");
    println!("cargo::rerun-if-env-changed=PKG_CONFIG_LIBDIR");
    println!("cargo::rerun-if-env-changed=POLYDEM_COAL_PREFIX");
    #[cfg(feature = "peers")]
    peers::build();
}

/// `pkg-config --cflags --libs NAME` split into include dirs, defines, link dirs and libraries; `None` when
/// pkg-config or the package is missing.
#[allow(dead_code)]
struct PkgConfig {
    include: Vec<String>,
    defines: Vec<String>,
    link_dirs: Vec<String>,
    libs: Vec<String>,
}

#[allow(dead_code)]
fn pkg_config(name: &str) -> Option<PkgConfig> {
    let out = Command::new("pkg-config")
        .args(["--cflags", "--libs", name])
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let mut p = PkgConfig {
        include: Vec::new(),
        defines: Vec::new(),
        link_dirs: Vec::new(),
        libs: Vec::new(),
    };
    for flag in String::from_utf8_lossy(&out.stdout).split_whitespace() {
        if let Some(v) = flag.strip_prefix("-I") {
            p.include.push(v.to_string());
        } else if let Some(v) = flag.strip_prefix("-D") {
            p.defines.push(v.to_string());
        } else if let Some(v) = flag.strip_prefix("-L") {
            p.link_dirs.push(v.to_string());
        } else if let Some(v) = flag.strip_prefix("-l") {
            p.libs.push(v.to_string());
        }
    }
    Some(p)
}

#[cfg(feature = "peers")]
mod peers {
    use super::{pkg_config, PkgConfig};
    use std::path::Path;

    fn link(p: &PkgConfig) {
        for d in &p.link_dirs {
            println!("cargo::rustc-link-search=native={d}");
        }
        for l in &p.libs {
            println!("cargo::rustc-link-lib={l}");
        }
    }

    fn configure(build: &mut cc::Build, p: &PkgConfig) {
        for i in &p.include {
            build.include(i);
        }
        for d in &p.defines {
            match d.split_once('=') {
                Some((k, v)) => build.define(k, v),
                None => build.define(d, None),
            };
        }
    }

    pub fn build() {
        match pkg_config("ccd") {
            Some(p) => {
                let mut b = cc::Build::new();
                configure(&mut b, &p);
                b.file("peers/ccd_shim.c")
                    .opt_level(2)
                    .compile("pd_ccd_shim");
                link(&p);
                println!("cargo::rustc-cfg=peer_ccd");
            }
            None => println!(
                "cargo::warning=libccd not found by pkg-config (ccd): the libccd peer is left out"
            ),
        }
        match pkg_config("bullet-float64") {
            Some(p) => {
                let mut b = cc::Build::new();
                configure(&mut b, &p);
                b.cpp(true)
                    .file("peers/bullet_shim.cpp")
                    .opt_level(2)
                    .compile("pd_bullet_shim");
                link(&p);
                println!("cargo::rustc-cfg=peer_bullet");
            }
            None => println!(
                "cargo::warning=Bullet (double precision) not found by pkg-config (bullet-float64): the Bullet peer is left out"
            ),
        }
        match std::env::var("POLYDEM_COAL_PREFIX") {
            Ok(prefix) => build_coal(Path::new(&prefix)),
            Err(_) => println!(
                "cargo::warning=POLYDEM_COAL_PREFIX is not set (the cmeel.prefix of the libcoal wheel): the coal peer is left out"
            ),
        }
    }

    /// coal's version from its `config.hh` (`# define COAL_VERSION "3.0.3"`).
    fn coal_version(prefix: &Path) -> Option<String> {
        let text = std::fs::read_to_string(prefix.join("include/coal/config.hh")).ok()?;
        let line = text.lines().find(|l| l.contains("define COAL_VERSION "))?;
        Some(line.split('"').nth(1)?.to_string())
    }

    fn build_coal(prefix: &Path) {
        let lib = prefix.join("lib");
        // Rebuilt when the wheel is installed, replaced or removed (a missing file reruns every build).
        println!(
            "cargo::rerun-if-changed={}",
            lib.join("libcoal.so").display()
        );
        let (include, eigen) = (prefix.join("include"), prefix.join("include/eigen3"));
        let found = lib.join("libcoal.so").is_file() && eigen.join("Eigen/Core").is_file();
        let Some(version) = coal_version(prefix).filter(|_| found) else {
            println!(
                "cargo::warning=coal not found under POLYDEM_COAL_PREFIX={} (include/coal, include/eigen3, lib/libcoal.so): the coal peer is left out",
                prefix.display()
            );
            return;
        };
        cc::Build::new()
            .cpp(true)
            .std("c++17")
            .include(&include)
            .include(&eigen)
            // The library is a release build; the header templates compiled here follow it.
            .define("NDEBUG", None)
            .flag_if_supported("-Wno-deprecated-declarations")
            .file("peers/coal_shim.cpp")
            .opt_level(2)
            .compile("pd_coal_shim");
        println!("cargo::rustc-link-search=native={}", lib.display());
        println!("cargo::rustc-link-lib=coal");
        println!("cargo::rustc-link-arg=-Wl,-rpath,{}", lib.display());
        println!("cargo::rustc-env=POLYDEM_COAL_VERSION={version}");
        println!("cargo::rustc-cfg=peer_coal");
    }
}
