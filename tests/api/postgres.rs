//! A throwaway PostgreSQL server for the tests, and a fresh database per test.
//!
//! The first test that needs PostgreSQL starts one cluster for the whole test binary:
//! `initdb` in a temporary directory, `postgres` on a free port of 127.0.0.1 with its
//! socket in that directory and durability off (fsync, synchronous commit: nothing
//! here must survive a crash), run as `nobody` when the tests run as root (PostgreSQL
//! refuses root). A small shell keeper holds the server: when this process exits, for
//! whatever reason, the keeper's stdin closes and it stops the server and deletes the
//! directory. Each test then gets its own `CREATE DATABASE`.
//!
//! `CHOCMODAL_TEST_DATABASE_URL=postgres://user@host/db` uses that server instead (the
//! user must be allowed to create databases). Without either, or with
//! `CHOCMODAL_SKIP_POSTGRES_TESTS=1`, the PostgreSQL tests are ignored (`build.rs` looks
//! when the package is built); under `CI=true` they are not: they fail, saying how to
//! install PostgreSQL, and the skip variable fails them too (see `skip.rs`).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

use sqlx::Connection;

/// Set to `1` to skip the PostgreSQL tests (they fail without PostgreSQL otherwise).
pub const SKIP_VARIABLE: &str = "CHOCMODAL_SKIP_POSTGRES_TESTS";
/// A server to use instead of a throwaway cluster.
pub const URL_VARIABLE: &str = "CHOCMODAL_TEST_DATABASE_URL";

/// Panics when the PostgreSQL test `test` is asked to be skipped under CI (see
/// [`crate::skip`]).
pub fn refuse_skip_under_ci(test: &str) {
    crate::skip::refuse_under_ci(SKIP_VARIABLE, test, "needs a PostgreSQL server")
}

struct Server {
    /// URL of the maintenance database (`postgres`) on the server.
    admin_url: String,
    /// The keeper of a throwaway cluster (its stdin open while this process lives).
    _keeper: Option<Mutex<Child>>,
}

static SERVER: OnceLock<Result<Server, String>> = OnceLock::new();

fn server() -> &'static Server {
    let server = SERVER.get_or_init(|| match std::env::var(URL_VARIABLE) {
        Ok(url) => Ok(Server {
            admin_url: url,
            _keeper: None,
        }),
        Err(_) => start_cluster(),
    });
    match server {
        Ok(server) => server,
        Err(reason) => panic!("PostgreSQL tests cannot run: {reason}"),
    }
}

/// Creates an empty database on the test server; returns its URL.
pub async fn fresh_database() -> String {
    let admin_url = server().admin_url.clone();
    let name = format!("chocmodal_test_{}", uuid::Uuid::new_v4().simple());
    let mut admin = sqlx::PgConnection::connect(&admin_url)
        .await
        .unwrap_or_else(|error| panic!("cannot connect to the test server: {error}"));
    sqlx::query(sqlx::AssertSqlSafe(format!("CREATE DATABASE {name}")))
        .execute(&mut admin)
        .await
        .unwrap_or_else(|error| panic!("cannot create a test database: {error}"));
    let _ = admin.close().await;
    with_database(&admin_url, &name)
}

/// `url` with its database name replaced by `name`.
fn with_database(url: &str, name: &str) -> String {
    let (base, query) = match url.split_once('?') {
        Some((base, query)) => (base, Some(query)),
        None => (url, None),
    };
    let (scheme, rest) = base.split_once("://").expect("a postgres:// URL");
    let authority = rest.split('/').next().unwrap_or_default();
    match query {
        Some(query) => format!("{scheme}://{authority}/{name}?{query}"),
        None => format!("{scheme}://{authority}/{name}"),
    }
}

fn start_cluster() -> Result<Server, String> {
    let bin = find_binaries().ok_or_else(|| {
        format!(
            "the PostgreSQL server binaries (initdb, postgres) are in neither \
             /usr/lib/postgresql/<version>/bin nor PATH. Install them (`apt-get install -y \
             postgresql`, as .ci/run does), or set {URL_VARIABLE}=postgres://user@host/db to use \
             a server where that user may create databases, or set {SKIP_VARIABLE}=1 to ignore \
             the PostgreSQL tests (outside CI)"
        )
    })?;
    let root = id(&["-u"])? == 0;
    // Short (the socket path must fit in 107 bytes) and, as root, reachable by `nobody`.
    let parent = if root {
        PathBuf::from("/tmp")
    } else {
        std::env::temp_dir()
    };
    let dir = tempfile::Builder::new()
        .prefix("chocmodal-pg-")
        .tempdir_in(parent)
        .map_err(|e| format!("cannot create a temporary directory: {e}"))?
        .keep();
    let run_as = if root { Some(give_to_nobody(&dir)?) } else { None };
    let command = |program: &str| {
        let mut command = match &run_as {
            Some(user) => {
                let mut command = Command::new("runuser");
                command.args(["-u", user, "--", program]);
                command
            }
            None => Command::new(program),
        };
        command.current_dir(&dir);
        command
    };

    let data = dir.join("data");
    let output = command(&bin.join("initdb").display().to_string())
        .arg("-D")
        .arg(&data)
        .args([
            "-U",
            "chocmodal",
            "--auth=trust",
            "--no-sync",
            "-E",
            "UTF8",
            "--locale=C",
        ])
        .output()
        .map_err(|e| format!("cannot run initdb: {e}"))?;
    if !output.status.success() {
        return Err(format!(
            "initdb failed: {}",
            String::from_utf8_lossy(&output.stderr)
        ));
    }

    let port = free_port()?;
    let log = dir.join("postgres.log");
    // The keeper: runs the server in the background, waits for its stdin to close
    // (this process exited), then stops the server and removes the directory.
    let keeper_script = r#"
        "$1" -D "$2/data" -p "$3" -k "$2" -h 127.0.0.1 \
            -c fsync=off -c synchronous_commit=off -c full_page_writes=off \
            -c max_connections=300 -c shared_buffers=32MB >"$2/postgres.log" 2>&1 &
        server=$!
        read -r _ || true
        kill -INT "$server" 2>/dev/null
        wait "$server"
        rm -rf "$2"
    "#;
    let keeper = command("sh")
        .args(["-c", keeper_script, "keeper"])
        .arg(bin.join("postgres"))
        .arg(&dir)
        .arg(port.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| format!("cannot start postgres: {e}"))?;
    let mut keeper = keeper;
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let text = std::fs::read_to_string(&log).unwrap_or_default();
        if text.contains("ready to accept connections") {
            break;
        }
        if let Ok(Some(status)) = keeper.try_wait() {
            return Err(format!("postgres exited ({status}): {text}"));
        }
        if Instant::now() > deadline {
            return Err(format!("postgres did not start within 60 s: {text}"));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    Ok(Server {
        admin_url: format!("postgres://chocmodal@127.0.0.1:{port}/postgres"),
        _keeper: Some(Mutex::new(keeper)),
    })
}

/// The newest `/usr/lib/postgresql/<version>/bin`, else the PATH entry with `initdb`.
fn find_binaries() -> Option<PathBuf> {
    let has_server = |dir: &Path| dir.join("initdb").is_file() && dir.join("postgres").is_file();
    let mut versions: Vec<(u32, PathBuf)> = std::fs::read_dir("/usr/lib/postgresql")
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|entry| {
            let version = entry.file_name().to_str()?.parse::<u32>().ok()?;
            Some((version, entry.path().join("bin")))
        })
        .filter(|(_, bin)| has_server(bin))
        .collect();
    versions.sort();
    if let Some((_, bin)) = versions.pop() {
        return Some(bin);
    }
    std::env::split_paths(&std::env::var_os("PATH")?).find(|dir| has_server(dir))
}

/// Output of `id <args>`: a user or group id.
fn id(args: &[&str]) -> Result<u32, String> {
    let mut output = String::new();
    Command::new("id")
        .args(args)
        .stdout(Stdio::piped())
        .spawn()
        .and_then(|mut child| {
            child.stdout.take().unwrap().read_to_string(&mut output)?;
            child.wait()
        })
        .map_err(|e| format!("cannot run id: {e}"))?;
    output
        .trim()
        .parse()
        .map_err(|_| format!("unexpected output of id {args:?}: {output}"))
}

/// Gives `dir` to `nobody`, who runs the server when the tests run as root.
fn give_to_nobody(dir: &Path) -> Result<String, String> {
    let (uid, gid) = (id(&["-u", "nobody"])?, id(&["-g", "nobody"])?);
    std::os::unix::fs::chown(dir, Some(uid), Some(gid))
        .map_err(|e| format!("cannot give {} to nobody: {e}", dir.display()))?;
    Ok("nobody".to_owned())
}

fn free_port() -> Result<u16, String> {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").map_err(|e| format!("no free port: {e}"))?;
    listener
        .local_addr()
        .map(|address| address.port())
        .map_err(|e| format!("no free port: {e}"))
}

#[test]
fn a_database_url_keeps_its_server_and_options() {
    assert_eq!(
        with_database("postgres://u:p@h:5432/postgres?sslmode=disable", "t1"),
        "postgres://u:p@h:5432/t1?sslmode=disable"
    );
    assert_eq!(with_database("postgresql://u@h", "t2"), "postgresql://u@h/t2");
}
