//! Tests that need software a developer may not have: ignored, visibly, and never under CI.
//!
//! The browser tests need headless Chromium, the PostgreSQL tests PostgreSQL. The build
//! script (`build.rs`) looks for both when the package is built and, when one is missing
//! or `CHOCMODAL_SKIP_BROWSER_TESTS=1` / `CHOCMODAL_SKIP_POSTGRES_TESTS=1` asks for it,
//! sets `chocmodal_skip_browser_tests` / `chocmodal_skip_postgres_tests`, on which those
//! tests are `#[ignore]`d with the reason: cargo's summary counts them as ignored, never
//! as passed. Under CI (`CI` set to anything but empty, `0` or `false`) nothing is
//! ignored: a missing tool fails its tests, saying how to install it, and a skip
//! variable fails them too ([`refuse_under_ci`]).

/// Panics when `variable` is `1` under CI: `test`, which `needs` something ("needs
/// headless Chromium"), may not be skipped there.
pub fn refuse_under_ci(variable: &str, test: &str, needs: &str) {
    if std::env::var(variable).as_deref() == Ok("1") && under_ci() {
        panic!(
            "{variable}=1 under CI={}: no test may be skipped in CI ({test} {needs}: \
             provide it and unset {variable})",
            std::env::var("CI").unwrap_or_default()
        );
    }
}

fn under_ci() -> bool {
    std::env::var("CI").is_ok_and(|value| !matches!(value.trim(), "" | "0" | "false"))
}
