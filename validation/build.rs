//! Builds the C/C++ shims of the peer collision libraries when the `peers` feature is on.
//!
//! Each library is looked up with `pkg-config` (libccd: `ccd`; Bullet: `bullet-float64`, Debian's double
//! precision build). A library that is found is compiled in and announced to the crate as the cfg
//! `peer_ccd` / `peer_bullet`; one that is missing is left out with a build warning, and the contact case
//! says so in its report. Without the feature nothing is built or linked.

use std::process::Command;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(peer_ccd)");
    println!("cargo::rustc-check-cfg=cfg(peer_bullet)");
    println!("cargo::rerun-if-changed=peers");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=PKG_CONFIG_PATH");
    println!("cargo::rerun-if-env-changed=PKG_CONFIG_LIBDIR");
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
    }
}
