//! The layers of the crate, checked on its sources: data flows one way (HTTP/CLI →
//! request parsing → processes → physics; sweeps and the service above the processes),
//! so no top-level module may reach back into one that depends on it. The physics is its
//! own crate (`crates/physics`), held to numerics-only dependencies.
//!
//! Edges are the `crate::<module>` paths in each top-level module's files, test modules
//! left out (`*tests.rs` files and inline `#[cfg(test)] mod … {` blocks, which may use
//! any layer to build their cases).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const SOURCES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/src");

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable source tree").flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a source file belongs to (`processes` for
/// `src/processes/common_inputs.rs`), `None` for the crate root and the binary.
fn top_level(path: &Path) -> Option<String> {
    let relative = path.strip_prefix(SOURCES).ok()?;
    let first = relative.components().next()?.as_os_str().to_str()?;
    let name = first.strip_suffix(".rs").unwrap_or(first);
    (!matches!(name, "lib" | "main")).then(|| name.to_owned())
}

/// The source without its inline test modules.
fn without_tests(source: &str) -> &str {
    let mut end = source.len();
    let mut from = 0;
    while let Some(at) = source[from..].find("#[cfg(test)]") {
        let at = from + at;
        let rest = source[at + "#[cfg(test)]".len()..].trim_start();
        if rest.starts_with("mod ") && rest.lines().next().is_some_and(|l| l.trim_end().ends_with('{')) {
            end = at;
            break;
        }
        from = at + 1;
    }
    &source[..end]
}

/// `crate::a` and `crate::{a, b::c}` paths: the modules named first.
fn referenced(source: &str) -> BTreeSet<String> {
    named_after(source, "crate::")
}

/// The names that follow `prefix` in paths (`<prefix>a`, `<prefix>{a, b::c}`).
fn named_after(source: &str, prefix: &str) -> BTreeSet<String> {
    let mut modules = BTreeSet::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    for (at, _) in source.match_indices(prefix) {
        let rest = &source[at + prefix.len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let inner = &group[..group.find('}').unwrap_or(group.len())];
            modules.extend(
                inner
                    .split(',')
                    .map(|item| ident(item.trim()))
                    .filter(|m| !m.is_empty()),
            );
        } else {
            let name = ident(rest);
            if !name.is_empty() {
                modules.insert(name);
            }
        }
    }
    modules
}

fn dependencies() -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(Path::new(SOURCES), &mut files);
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in files {
        let Some(module) = top_level(&file) else { continue };
        let name = file.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        if name.ends_with("tests.rs") {
            continue;
        }
        let source = std::fs::read_to_string(&file).expect("readable source");
        let edges = graph.entry(module.clone()).or_default();
        edges.extend(
            referenced(without_tests(&source))
                .into_iter()
                .filter(|m| *m != module),
        );
    }
    graph
}

/// A cycle through `start`, if any (depth-first).
fn cycle_from(graph: &BTreeMap<String, BTreeSet<String>>, start: &str) -> Option<Vec<String>> {
    fn visit(
        graph: &BTreeMap<String, BTreeSet<String>>,
        start: &str,
        node: &str,
        path: &mut Vec<String>,
        seen: &mut BTreeSet<String>,
    ) -> bool {
        for next in graph.get(node).into_iter().flatten() {
            if next == start {
                path.push(next.clone());
                return true;
            }
            if seen.insert(next.clone()) {
                path.push(next.clone());
                if visit(graph, start, next, path, seen) {
                    return true;
                }
                path.pop();
            }
        }
        false
    }
    let mut path = vec![start.to_owned()];
    visit(graph, start, start, &mut path, &mut BTreeSet::new()).then_some(path)
}

#[test]
fn no_top_level_module_reaches_back_into_one_that_depends_on_it() {
    let graph = dependencies();
    assert!(graph.len() >= 5, "too few modules found: {graph:?}");
    assert!(
        graph["service"].contains("processes"),
        "the scan must see the service's use of the processes: {graph:?}"
    );
    for module in graph.keys() {
        if let Some(cycle) = cycle_from(&graph, module) {
            panic!("import cycle {}: {graph:#?}", cycle.join(" → "));
        }
    }
}

/// The physics core is its own crate: the compiler keeps it from importing the service,
/// and its manifest is held here to numerics (no IO, async, HTTP, database or JSON crate).
#[test]
fn the_physics_crate_depends_on_numerics_only_and_does_no_io() {
    let physics = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/physics");
    let manifest = std::fs::read_to_string(physics.join("Cargo.toml")).expect("physics manifest");
    let mut section = "";
    let mut dependencies = BTreeSet::new();
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            section = line;
        } else if section.ends_with("dependencies]") && !line.is_empty() && !line.starts_with('#') {
            dependencies.insert(line.split(['=', ' ', '.']).next().unwrap_or_default().to_owned());
        }
    }
    // utoipa: optional (feature `schema`), the report types' OpenAPI schemas. rayon:
    // fork-join of a step shared between threads, on the caller's pool (no IO).
    let allowed: BTreeSet<String> = ["faer", "rustfft", "pulp", "rayon", "serde", "thiserror", "utoipa"]
        .into_iter()
        .map(String::from)
        .collect();
    assert!(!dependencies.is_empty(), "no dependency found in {manifest}");
    assert!(
        manifest
            .lines()
            .any(|l| l.starts_with("utoipa") && l.contains("optional = true")),
        "the schema library stays optional in the physics crate"
    );
    assert!(
        dependencies.is_subset(&allowed),
        "the physics crate depends on {:?}: only numerics belong there",
        dependencies.difference(&allowed).collect::<Vec<_>>()
    );
    let mut files = Vec::new();
    rust_files(&physics.join("src"), &mut files);
    assert!(files.len() > 10, "too few physics sources found");
    for file in files {
        let source = std::fs::read_to_string(&file).expect("readable source");
        for forbidden in ["std::fs", "std::net", "std::thread::spawn", "std::process"] {
            assert!(!source.contains(forbidden), "{} uses {forbidden}", file.display());
        }
    }
}

#[test]
fn the_scan_sees_grouped_paths_and_skips_test_modules() {
    let source = "use crate::{a, b::c};\nuse crate::d::e;\n#[cfg(test)]\nmod tests {\n use crate::f;\n}\n";
    let found = referenced(without_tests(source));
    assert_eq!(found, ["a", "b", "d"].into_iter().map(String::from).collect());
}

/// The processes: the folders of `src/processes`.
fn process_folders() -> BTreeSet<String> {
    std::fs::read_dir(Path::new(SOURCES).join("processes"))
        .expect("readable processes folder")
        .flatten()
        .filter(|entry| entry.path().is_dir())
        .map(|entry| entry.file_name().to_string_lossy().into_owned())
        .collect()
}

/// A process is a room of its own: the files of a process's folder name no other
/// process (through `crate::processes::`, `super::` or `super::super::`), and the shared
/// modules of `src/processes` name none (the registry in `mod.rs` lists them all).
#[test]
fn no_process_reaches_into_another_and_shared_modules_into_none() {
    let processes = process_folders();
    assert!(processes.len() >= 3, "too few process folders: {processes:?}");
    let root = Path::new(SOURCES).join("processes");
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    let mut trespasses = Vec::new();
    for file in files {
        let relative = file.strip_prefix(&root).expect("under processes");
        let name = file.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        if name.ends_with("tests.rs") || relative == Path::new("mod.rs") {
            continue;
        }
        let own = relative
            .components()
            .next()
            .filter(|_| relative.components().count() > 1)
            .map(|c| c.as_os_str().to_string_lossy().into_owned());
        let source = std::fs::read_to_string(&file).expect("readable source");
        let source = without_tests(&source);
        let named: BTreeSet<String> = ["processes::", "super::", "super::super::"]
            .iter()
            .flat_map(|prefix| named_after(source, prefix))
            .collect();
        for other in named.intersection(&processes) {
            if own.as_ref() != Some(other) {
                trespasses.push(format!("{} names the process {other}", relative.display()));
            }
        }
    }
    assert!(trespasses.is_empty(), "{trespasses:#?}");
}

#[test]
fn the_process_scan_sees_every_way_to_name_a_module() {
    let source = "use super::{a, b::c};\nuse crate::processes::d::e;\nuse super::super::f;\n";
    let named: BTreeSet<String> = ["processes::", "super::", "super::super::"]
        .iter()
        .flat_map(|prefix| named_after(source, prefix))
        .collect();
    assert_eq!(
        named,
        ["a", "b", "d", "f", "super"]
            .into_iter()
            .map(String::from)
            .collect()
    );
}
