//! The `chocmodal` command line.
//!
//! `chocmodal run <processId> <body.json | ->` runs one execution request in-process,
//! with no server: the results document goes to stdout, invalid inputs give the same
//! problem document as the HTTP API on stderr and exit status 2, a failed run exits 1.
//! A result whose quality verdict is not `good` still exits 0 (as its job would be
//! `successful`) but says so on stderr: `warning: quality poor: <reason>; <reason>`;
//! each plausibility warning about the inputs is a line `warning: <pointer>: <message>`.
//! `--out DIR` writes the histories as CSV, `--report FILE` the calculation note.
//! `chocmodal serve` runs the HTTP API and its workers, `chocmodal worker` workers alone
//! (see [`crate::service`]).

use std::io::Read;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

use clap::{Parser, Subcommand};

use crate::problem::Problem;
use crate::processes::signal_input::{SignalLibrary, SignalSource, signal_keys};
use crate::processes::{Registry, RunError, RunOutput, impact_report};
use crate::quality_note::QualityNote;
use crate::signal_record::{self, RecordFormat};

#[derive(Debug, Parser)]
#[command(
    name = "chocmodal",
    version,
    about = "Modal multi-contact dynamics of slender beam bundles"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run one execution request in-process and print its results document.
    Run(RunArgs),
    /// Serve the HTTP API and run jobs (SQLite by default, or PostgreSQL).
    Serve(Box<crate::service::ServeArgs>),
    /// Run jobs from the queue without serving the API (scale-out on PostgreSQL).
    Worker(crate::service::WorkerArgs),
}

#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Process id, e.g. `cantilever-impact`.
    pub process_id: String,
    /// Execution request body (`{"inputs": {...}}`): a file path, or `-` for stdin.
    pub body: String,
    /// Also write every history as `DIR/<name>.csv` at full output resolution.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also write the run's calculation note as FILE: one printable HTML page (the
    /// same page as `GET /jobs/{jobId}/report`).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Print progress to stderr: the percent done, the time taken and, from 1 % on, the
    /// time left at the pace so far.
    #[arg(long)]
    pub progress: bool,
}

/// Entry point of the binary.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Run(args) => run_command(&args, &Registry::builtin()),
        Command::Serve(args) => crate::service::serve(&args, Registry::builtin()),
        Command::Worker(args) => crate::service::worker(&args, Registry::builtin()),
    }
}

/// Exit status of `chocmodal run`: 0 success, 1 failed run or IO error, 2 invalid inputs.
pub fn run_command(args: &RunArgs, registry: &Registry) -> ExitCode {
    match execute(args, registry) {
        Ok(document) => {
            if let Some(note) = QualityNote::of(&document) {
                eprintln!("warning: {note}");
            }
            println!(
                "{}",
                serde_json::to_string_pretty(&document).expect("results serialize")
            );
            ExitCode::SUCCESS
        }
        Err(CliFailure::Problem(problem)) => {
            eprintln!("{}", problem.to_json_pretty());
            ExitCode::from(
                if problem.status == 422 || problem.status == 400 || problem.status == 404 {
                    2
                } else {
                    1
                },
            )
        }
        Err(CliFailure::Failed(message)) => {
            eprintln!("chocmodal: {message}");
            ExitCode::from(1)
        }
    }
}

enum CliFailure {
    Problem(Problem),
    Failed(String),
}

/// `--progress`'s line: the percent done, the time taken, and from 1 % on the time left
/// at the pace so far (padded, so that a shorter line overwrites a longer one).
fn progress_line(fraction: f64, elapsed: f64) -> String {
    let percent = (fraction * 100.0).floor();
    let mut line = format!("{percent:3}% {}", duration_text(elapsed));
    if (1.0..100.0).contains(&percent) {
        let left = elapsed * (1.0 - fraction) / fraction;
        line.push_str(&format!(", about {} left", duration_text(left)));
    }
    format!("{line:<40}")
}

/// Seconds as `12.3 s`, `4 min 05 s` or `1 h 02 min`.
fn duration_text(seconds: f64) -> String {
    if seconds < 60.0 {
        format!("{seconds:.1} s")
    } else if seconds < 3600.0 {
        format!(
            "{} min {:02} s",
            (seconds / 60.0).floor(),
            (seconds % 60.0).floor()
        )
    } else {
        format!(
            "{} h {:02} min",
            (seconds / 3600.0).floor(),
            ((seconds % 3600.0) / 60.0).floor()
        )
    }
}

fn execute(args: &RunArgs, registry: &Registry) -> Result<serde_json::Value, CliFailure> {
    let process = registry
        .get(&args.process_id)
        .ok_or_else(|| CliFailure::Problem(Problem::no_such_process(&args.process_id)))?;
    let text = read_body(&args.body).map_err(CliFailure::Failed)?;
    let inputs = crate::json_body::parse_envelope(&text).map_err(CliFailure::Problem)?;
    // `run` validates too (invalid inputs come back as `RunError::Invalid`): validating
    // first would do the modal analysis and the stability eigenproblem twice.

    let show_progress = args.progress;
    let mut last_percent = -1i64;
    let started = std::time::Instant::now();
    let mut progress = |fraction: f64| {
        let percent = (fraction * 100.0).floor() as i64;
        if show_progress && percent != last_percent {
            last_percent = percent;
            eprint!("\r{}", progress_line(fraction, started.elapsed().as_secs_f64()));
        }
        ControlFlow::Continue(())
    };
    let signals = record_files(&inputs, &body_directory(&args.body));
    // The run computes on a pool of this machine's cores (it uses as many as its
    // `solver.threads` asks): from inside the pool, a step shared between threads forks
    // and joins there, without waking this thread at every step.
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(cores)
        .build()
        .map_err(|e| CliFailure::Failed(format!("cannot start the run's threads: {e}")))?;
    let output = pool
        .install(|| process.run_with(&inputs, &signals, &mut progress))
        .map_err(|e| match e {
            RunError::Invalid(invalid) => CliFailure::Problem(Problem::invalid_inputs(&invalid)),
            other => CliFailure::Failed(other.to_string()),
        })?;
    if show_progress {
        eprintln!();
    }
    for warning in &output.warnings {
        eprintln!("warning: {}: {}", warning.pointer, warning.message);
    }
    if let Some(dir) = &args.out {
        write_histories(dir, &output).map_err(CliFailure::Failed)?;
    }
    let href = |name: &str| match &args.out {
        Some(dir) => dir.join(format!("{name}.csv")).display().to_string(),
        None => format!("{name}.csv"),
    };
    // The plots are drawn from the histories before the document takes them.
    let plots = args
        .report
        .as_ref()
        .map(|_| plots(process.as_ref(), &output, &href));
    let mut document = output.document_with_outputs(href);
    crate::provenance::Provenance::of(&inputs).stamp(&mut document);
    if let (Some(path), Some(plots)) = (&args.report, plots) {
        let note = calculation_note(process.as_ref(), &inputs, &document, plots);
        std::fs::write(path, note)
            .map_err(|e| CliFailure::Failed(format!("cannot write {}: {e}", path.display())))?;
    }
    Ok(document)
}

/// The plots of the run's calculation note, each linked to its history's CSV file.
fn plots(
    process: &dyn crate::processes::Process,
    output: &RunOutput,
    href: &dyn Fn(&str) -> String,
) -> Vec<crate::calculation_note::Plot> {
    process
        .note_facts(&output.document)
        .plots
        .iter()
        .map(|request| {
            let history = output.histories.iter().find(|h| h.name == request.output);
            crate::calculation_note::Plot::of(request, history, href(&request.output))
        })
        .collect()
}

/// The run's calculation note ([`crate::calculation_note`]), with its `plots`.
fn calculation_note(
    process: &dyn crate::processes::Process,
    inputs: &serde_json::Value,
    document: &serde_json::Value,
    plots: Vec<crate::calculation_note::Plot>,
) -> String {
    use crate::calculation_note::{Identification, Note, render};
    let facts = process.note_facts(document);
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_millis()).unwrap_or(i64::MAX));
    let note = Note {
        identification: Identification {
            process_id: process.id().to_owned(),
            process_title: process.title().to_owned(),
            dates: vec![("Run (chocmodal run)".into(), crate::service::clock::rfc3339(now))],
            ..Identification::default()
        },
        inputs,
        document,
        facts,
        plots,
        envelope_href: "#envelope".into(),
    };
    render(&note)
}

/// Where the record files a job names are looked for: the job file's directory (the
/// working directory for a job read from stdin).
fn body_directory(source: &str) -> PathBuf {
    match Path::new(source).parent() {
        Some(dir) if source != "-" && !dir.as_os_str().is_empty() => dir.to_owned(),
        _ => PathBuf::from("."),
    }
}

/// The record files named by the job's signal references (`{"type": "signal", "path":
/// "record.csv"}`, or a path given as its `id`), read and checked as `POST /signals`
/// would (CSV `time,acceleration` or JSON); a file that cannot be read or is refused is
/// reported at its reference's pointer.
fn record_files(inputs: &serde_json::Value, directory: &Path) -> SignalLibrary {
    let mut library = SignalLibrary::new(SignalSource::Files);
    for key in signal_keys(inputs) {
        let path = directory.join(&key);
        let read = std::fs::read_to_string(&path)
            .map_err(|e| format!("cannot read the record file {}: {e}", path.display()))
            .and_then(|text| {
                let format = if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json")) {
                    RecordFormat::Json
                } else {
                    RecordFormat::sniff(&text)
                };
                signal_record::parse(&text, format, None, None, usize::MAX)
                    .map_err(|e| format!("the record file {}: {e}", path.display()))
            });
        match read {
            Ok(record) => library.insert(key, Arc::new(record)),
            Err(why) => library.insert_error(key, why),
        }
    }
    library
}

fn read_body(source: &str) -> Result<String, String> {
    let mut text = String::new();
    if source == "-" {
        std::io::stdin()
            .read_to_string(&mut text)
            .map_err(|e| format!("cannot read stdin: {e}"))?;
    } else {
        text = std::fs::read_to_string(source).map_err(|e| format!("cannot read {source}: {e}"))?;
    }
    Ok(text)
}

fn write_histories(dir: &Path, output: &RunOutput) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    for history in &output.histories {
        let path = dir.join(format!("{}.csv", history.name));
        // The per-impact table in its own columns; every other output is a time history.
        let text = match impact_report::read_table(history).filter(|_| history.name == impact_report::TABLE) {
            Some(table) => impact_report::table_csv(&table, &table.rows),
            None => history.to_csv(),
        };
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    // The run's tables beside its histories, by the writer the service serves them with.
    use crate::contact_table::{ContactTable, PinTable, ResultantTable};
    let document = &output.document;
    let tables = [
        ("contacts.csv", ContactTable::of(document).map(|t| t.to_csv())),
        ("pins.csv", PinTable::of(document).map(|t| t.to_csv())),
        ("resultants.csv", ResultantTable::of(document).map(|t| t.to_csv())),
    ];
    for (name, text) in tables {
        if let Some(text) = text {
            let path = dir.join(name);
            std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod progress_tests {
    use super::progress_line;

    /// A quarter done in 10 s leaves 30 s at that pace; nothing is extrapolated before
    /// 1 %; long times read in minutes and hours.
    #[test]
    fn the_progress_line_extrapolates_the_pace_so_far() {
        assert_eq!(
            progress_line(0.25, 10.0).trim_end(),
            " 25% 10.0 s, about 30.0 s left"
        );
        assert_eq!(progress_line(0.005, 2.0).trim_end(), "  0% 2.0 s");
        assert_eq!(
            progress_line(0.5, 245.0).trim_end(),
            " 50% 4 min 05 s, about 4 min 05 s left"
        );
        assert_eq!(
            progress_line(0.1, 1000.0).trim_end(),
            " 10% 16 min 40 s, about 2 h 30 min left"
        );
        assert_eq!(progress_line(1.0, 3.0).trim_end(), "100% 3.0 s");
    }
}
