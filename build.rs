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
//! It also records the git commit the package is built from, for the `provenance.build`
//! of every results document (`src/provenance.rs`): `CHOCMODAL_BUILD_COMMIT` when set
//! (a Docker build or a tarball build that knows its commit), else `git rev-parse HEAD`
//! of the source tree when it is a git checkout with `git` on the `PATH`; nothing
//! otherwise (the build still succeeds, and results say `"build": null`). In a checkout
//! the script reruns when `HEAD` or the branch it names moves, so the recorded commit is
//! never stale.
//!
//! The probe runs with this script: on the first build, and again when this file or one
//! of the variables in `VARIABLES` changes; not when software is installed or removed
//! (`touch build.rs` then). Changing one of the variables rebuilds the package.

use std::path::{Path, PathBuf};

/// Everything the outcome depends on, besides the file system and `PATH` (watching
/// `PATH` would rebuild the package whenever a tool runs cargo with another one).
const VARIABLES: [&str; 6] = [
    "CHOCMODAL_BUILD_COMMIT",
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
    record_build_commit();
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

/// The package's directory, as cargo gives it to this run of the script: not `env!`,
/// which would be the directory of whichever checkout compiled the script (cargo reuses
/// one compiled script for every checkout of the same sources sharing a target
/// directory, and a removed worktree then left every build without its commit).
fn manifest_dir() -> PathBuf {
    PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_else(|| ".".into()))
}

/// Sets `CHOCMODAL_BUILD_COMMIT` for the compiler (see the module documentation).
fn record_build_commit() {
    if let Some(commit) = std::env::var("CHOCMODAL_BUILD_COMMIT")
        .ok()
        .filter(|c| !c.trim().is_empty())
    {
        println!("cargo::rustc-env=CHOCMODAL_BUILD_COMMIT={}", commit.trim());
        return;
    }
    let git = |args: &[&str]| -> Option<String> {
        let output = std::process::Command::new("git")
            .args(args)
            .current_dir(manifest_dir())
            .output()
            .ok()?;
        let text = String::from_utf8(output.stdout).ok()?;
        (output.status.success() && !text.trim().is_empty()).then(|| text.trim().to_owned())
    };
    // Only for the package's own checkout (not a parent repository it was unpacked in).
    let toplevel = git(&["rev-parse", "--show-toplevel"]).map(PathBuf::from);
    let here = manifest_dir().canonicalize().ok();
    if toplevel.and_then(|t| t.canonicalize().ok()) != here || here.is_none() {
        return;
    }
    let Some(commit) = git(&["rev-parse", "HEAD"]) else {
        return;
    };
    println!("cargo::rustc-env=CHOCMODAL_BUILD_COMMIT={commit}");
    // A commit or a checkout moves HEAD or the branch it names (a worktree has its own HEAD).
    for name in ["HEAD", "packed-refs"] {
        if let Some(path) = git(&["rev-parse", "--git-path", name]) {
            watch(&path);
        }
    }
    if let Some(branch) = git(&["symbolic-ref", "-q", "HEAD"])
        && let Some(path) = git(&["rev-parse", "--git-path", &branch])
    {
        watch(&path);
    }
}

/// `path` as git printed it (relative to the package's directory, or absolute). Only a
/// file that exists is watched: cargo reruns a script whose watched file is missing on
/// every build.
fn watch(path: &str) {
    let path = manifest_dir().join(path);
    if path.exists() {
        println!("cargo::rerun-if-changed={}", path.display());
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
