//! Which tests this machine cannot run, decided when the package is built.
//!
//! The PostgreSQL tests need PostgreSQL's server binaries (or a server named by
//! `CHOCMODAL_TEST_DATABASE_URL`), the browser tests headless Chromium. libtest counts a
//! test as `ignored` only through an attribute, fixed at compile time, so this script
//! looks for that software and sets `chocmodal_skip_postgres_tests` and
//! `chocmodal_skip_browser_tests`, on which those tests carry
//! `#[cfg_attr(<cfg>, ignore = "<reason>")]`. A cfg is set when the software is missing
//! or when `CHOCMODAL_SKIP_POSTGRES_TESTS=1` / `CHOCMODAL_SKIP_BROWSER_TESTS=1` asks for
//! it, and never under CI (`CI` set to anything but empty, `0` or `false`): there a
//! missing tool fails its tests, saying how to install it.
//!
//! The probe runs with this script: on the first build, and again when this file or one
//! of the variables in `VARIABLES` changes; not when software is installed or removed
//! (`touch build.rs` then). Changing one of the variables rebuilds the package.

use std::path::{Path, PathBuf};

/// Everything the outcome depends on, besides the file system and `PATH` (watching
/// `PATH` would rebuild the package whenever a tool runs cargo with another one).
const VARIABLES: [&str; 5] = [
    "CI",
    "CHOCMODAL_SKIP_POSTGRES_TESTS",
    "CHOCMODAL_SKIP_BROWSER_TESTS",
    "CHOCMODAL_TEST_DATABASE_URL",
    "CHOCMODAL_CHROMIUM",
];

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    // sqlx embeds the migrations at compile time: a new one must rebuild the package.
    println!("cargo::rerun-if-changed=migrations");
    for variable in VARIABLES {
        println!("cargo::rerun-if-env-changed={variable}");
    }
    println!("cargo::rustc-check-cfg=cfg(chocmodal_skip_postgres_tests)");
    println!("cargo::rustc-check-cfg=cfg(chocmodal_skip_browser_tests)");
    if under_ci() {
        return;
    }
    if let Some(why) = skip(
        "CHOCMODAL_SKIP_POSTGRES_TESTS",
        has_postgres,
        "PostgreSQL server binaries",
    ) {
        println!("cargo::rustc-cfg=chocmodal_skip_postgres_tests");
        println!("cargo::warning=the PostgreSQL tests are ignored: {why}");
    }
    if let Some(why) = skip("CHOCMODAL_SKIP_BROWSER_TESTS", has_chromium, "headless Chromium") {
        println!("cargo::rustc-cfg=chocmodal_skip_browser_tests");
        println!("cargo::warning=the browser tests are ignored: {why}");
    }
}

fn under_ci() -> bool {
    std::env::var("CI").is_ok_and(|value| !matches!(value.trim(), "" | "0" | "false"))
}

/// Why the tests that need `software` are to be ignored, if they are.
fn skip(variable: &str, available: fn() -> bool, software: &str) -> Option<String> {
    if std::env::var(variable).as_deref() == Ok("1") {
        Some(format!("{variable}=1"))
    } else if !available() {
        Some(format!(
            "no {software} found (install them, then `touch build.rs`; see README)"
        ))
    } else {
        None
    }
}

/// A server to use, or the binaries to start one: as `tests/api/postgres.rs` looks for
/// them (`/usr/lib/postgresql/<version>/bin`, else `PATH`).
fn has_postgres() -> bool {
    if std::env::var_os("CHOCMODAL_TEST_DATABASE_URL").is_some_and(|url| !url.is_empty()) {
        return true;
    }
    let has_server = |dir: &Path| dir.join("initdb").is_file() && dir.join("postgres").is_file();
    let versions = std::fs::read_dir("/usr/lib/postgresql")
        .into_iter()
        .flatten()
        .flatten()
        .map(|entry| entry.path().join("bin"));
    let on_path = std::env::var_os("PATH")
        .map(|path| std::env::split_paths(&path).collect::<Vec<_>>())
        .unwrap_or_default();
    versions.chain(on_path).any(|dir| has_server(&dir))
}

/// Chromium where `tests/api/dashboard.rs` looks for it.
fn has_chromium() -> bool {
    std::env::var_os("CHOCMODAL_CHROMIUM")
        .map(PathBuf::from)
        .into_iter()
        .chain(
            [
                "/usr/bin/chromium",
                "/usr/bin/chromium-browser",
                "/usr/bin/google-chrome",
            ]
            .map(PathBuf::from),
        )
        .any(|path| path.is_file())
}
