"""The client is versioned with the service: one number, in Cargo.toml."""

from __future__ import annotations

import importlib.metadata
import re

import chocmodal
from conftest import REPO_ROOT


def cargo_version() -> str:
    text = (REPO_ROOT / "Cargo.toml").read_text()
    package = text.split("[package]", 1)[1]
    match = re.search(r'^version\s*=\s*"([^"]+)"', package, re.MULTILINE)
    assert match, "Cargo.toml [package] has no version"
    return match.group(1)


def test_the_package_version_is_the_services_cargo_version() -> None:
    assert chocmodal.__version__ == cargo_version(), (
        f"clients/python/src/chocmodal/_version.py says {chocmodal.__version__}, "
        f"Cargo.toml says {cargo_version()}: bump them together"
    )


def test_the_installed_distribution_has_that_version() -> None:
    assert importlib.metadata.version("chocmodal") == cargo_version()


def test_the_running_server_reports_the_same_version(client: chocmodal.Client) -> None:
    versions = {p["id"]: p.get("version") for p in client.processes()}
    assert versions and set(versions.values()) == {cargo_version()}, versions
