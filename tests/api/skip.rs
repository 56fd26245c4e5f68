//! Skipping a test on request, visibly, and never under CI.
//!
//! The browser and PostgreSQL tests need software a developer may not have, so a
//! variable (`CHOCMODAL_SKIP_BROWSER_TESTS=1`, `CHOCMODAL_SKIP_POSTGRES_TESTS=1`) skips
//! them. A skipped test still ends as `ok` in libtest's summary (there is no way to
//! ignore a test at run time), so the skip prints `SKIPPED: <test> (<reason>)` straight
//! to the process's stderr, past libtest's output capture: it shows among the results
//! without `--nocapture`. Under CI (`CI` set to anything but empty, `0` or `false`)
//! nothing may be skipped: a skip variable there fails the test, saying so.

use std::io::Write;

/// True when `test`, which `needs` something ("needs headless Chromium"), must be
/// skipped because `variable` is `1`: prints the SKIPPED line. Panics when `variable`
/// is `1` under CI.
pub fn requested(variable: &str, test: &str, needs: &str) -> bool {
    if std::env::var(variable).as_deref() != Ok("1") {
        return false;
    }
    if under_ci() {
        panic!(
            "{variable}=1 under CI={}: no test may be skipped in CI ({test} {needs}: \
             provide it and unset {variable})",
            std::env::var("CI").unwrap_or_default()
        );
    }
    // Not `eprintln!`: libtest captures it and shows it only for failed tests.
    let _ = writeln!(
        std::io::stderr().lock(),
        "SKIPPED: {test} ({variable}=1; it {needs})"
    );
    true
}

fn under_ci() -> bool {
    std::env::var("CI").is_ok_and(|value| !matches!(value.trim(), "" | "0" | "false"))
}
