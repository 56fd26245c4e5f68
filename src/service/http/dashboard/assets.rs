//! The dashboard's files, embedded in the binary: scripts, style sheet, the vendored
//! plotting library (uPlot, `assets/vendor/`, its version and licence in
//! `assets/vendor/README.md`), and the shipped examples (`examples/*.json`) offered as
//! templates by the submit page.

use crate::processes::{Example, Registry};

/// One embedded file.
#[derive(Debug, Clone, Copy)]
pub struct Asset {
    pub name: &'static str,
    pub content_type: &'static str,
    pub bytes: &'static [u8],
}

const JS: &str = "text/javascript; charset=utf-8";
const CSS: &str = "text/css; charset=utf-8";
const TEXT: &str = "text/plain; charset=utf-8";

macro_rules! asset {
    ($name:literal, $content_type:expr) => {
        Asset {
            name: $name,
            content_type: $content_type,
            bytes: include_bytes!(concat!("assets/", $name)),
        }
    };
    (vendor $name:literal, $content_type:expr) => {
        Asset {
            name: $name,
            content_type: $content_type,
            bytes: include_bytes!(concat!("assets/vendor/", $name)),
        }
    };
}

/// Every file served under `/ui/assets/`.
pub const ASSETS: &[Asset] = &[
    asset!("app.js", JS),
    asset!("util.js", JS),
    asset!("plot.js", JS),
    asset!("lines.js", JS),
    asset!("lists.js", JS),
    asset!("job.js", JS),
    asset!("hex.js", JS),
    asset!("impacts.js", JS),
    asset!("margins.js", JS),
    asset!("spectra.js", JS),
    asset!("signals.js", JS),
    asset!("sweep.js", JS),
    asset!("submit.js", JS),
    asset!("schema.js", JS),
    asset!("style.css", CSS),
    asset!(vendor "uPlot.esm.js", JS),
    asset!(vendor "uPlot.min.css", CSS),
    asset!(vendor "uPlot.LICENSE", TEXT),
];

/// The embedded file called `name`.
pub fn find(name: &str) -> Option<&'static Asset> {
    ASSETS.iter().find(|a| a.name == name)
}

/// The shipped sweep requests (`examples/sweep-*.json`; each names its process itself).
/// A process's own examples come with it ([`crate::processes::Process::examples`]).
pub const SWEEP_EXAMPLES: &[Example] = &[
    Example {
        file: "sweep-calibration.json",
        body: include_str!("../../../../examples/sweep-calibration.json"),
    },
    Example {
        file: "sweep-gaps.json",
        body: include_str!("../../../../examples/sweep-gaps.json"),
    },
    Example {
        file: "sweep-static-correction.json",
        body: include_str!("../../../../examples/sweep-static-correction.json"),
    },
];

/// `[{"file", "process", "kind": "job" | "sweep", "body"}]`: every example of the
/// `registry`'s processes, then the sweeps of those processes, the bodies verbatim (their members keep the
/// order of the files).
pub fn examples_json(registry: &Registry) -> String {
    let jobs = registry
        .all()
        .iter()
        .flat_map(|process| process.examples().iter().map(move |e| (e, Some(process.id()))));
    // A sweep names its process: offered only where that process is.
    let offered = |e: &&Example| {
        let body: serde_json::Value = serde_json::from_str(e.body).unwrap_or_default();
        body["process"]
            .as_str()
            .is_some_and(|id| registry.get(id).is_some())
    };
    let sweeps = SWEEP_EXAMPLES.iter().filter(offered).map(|e| (e, None));
    let items: Vec<String> = jobs
        .chain(sweeps)
        .map(|(e, process)| {
            format!(
                r#"{{"file":{},"process":{},"kind":"{}","body":{}}}"#,
                serde_json::Value::from(e.file),
                process.map_or(serde_json::Value::Null, serde_json::Value::from),
                if process.is_some() { "job" } else { "sweep" },
                e.body.trim()
            )
        })
        .collect();
    format!("[{}]", items.join(","))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_example_is_embedded_and_valid_json() {
        let directory = concat!(env!("CARGO_MANIFEST_DIR"), "/examples");
        let mut files: Vec<String> = std::fs::read_dir(directory)
            .unwrap()
            .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|name| name.ends_with(".json"))
            .collect();
        files.sort();
        let registry = Registry::builtin();
        let parsed: serde_json::Value = serde_json::from_str(&examples_json(&registry)).unwrap();
        let mut embedded: Vec<String> = (parsed.as_array().unwrap().iter())
            .map(|e| e["file"].as_str().unwrap().to_owned())
            .collect();
        embedded.sort();
        assert_eq!(
            embedded, files,
            "examples/ and the processes' and sweeps' examples differ"
        );
        for example in parsed.as_array().unwrap() {
            let body = &example["body"];
            match example["kind"].as_str() {
                Some("job") => assert!(body["inputs"].is_object(), "{example}"),
                _ => assert!(
                    body["process"].is_string() && body["axes"].is_array(),
                    "{example}"
                ),
            }
        }
    }

    /// The version the vendor note states is the one the vendored script says it is.
    #[test]
    fn the_vendored_uplot_is_the_version_its_note_names() {
        let note = include_str!("assets/vendor/README.md");
        let version = note
            .lines()
            .find_map(|line| line.strip_prefix("- version: "))
            .expect("a `- version:` line in vendor/README.md");
        let script = std::str::from_utf8(find("uPlot.esm.js").unwrap().bytes).unwrap();
        let header: String = script.lines().take(8).collect();
        assert!(
            header.contains(&format!("(v{version})")),
            "vendor/README.md says {version}, the script's header: {header}"
        );
        let license = std::str::from_utf8(find("uPlot.LICENSE").unwrap().bytes).unwrap();
        assert!(license.starts_with("The MIT License"), "{license}");
    }

    #[test]
    fn assets_are_found_by_name_only() {
        assert!(find("app.js").is_some());
        assert!(find("../mod.rs").is_none());
        assert!(ASSETS.iter().all(|a| !a.bytes.is_empty()));
    }
}
