//! Tenants and their bearer tokens.
//!
//! The auth file (`--auth-file`) holds one `<tenant> <token>` pair per line; blank lines
//! and lines starting with `#` are ignored. A tenant may have several tokens (rotation);
//! a token belongs to one tenant. Only the SHA-256 of each token is kept in memory, and a
//! presented token is hashed and compared with every stored hash in constant time, so
//! neither memory dumps nor response timings give tokens away.
//!
//! Every job and sweep belongs to the tenant that created it. Without an auth file the
//! service has one implicit tenant, [`IMPLICIT_TENANT`], which also owns the jobs created
//! before tenants existed.

use std::fmt;
use std::path::Path;
use std::sync::Arc;

use sha2::{Digest, Sha256};
use subtle::ConstantTimeEq;

/// The tenant of every request when the service runs without an auth file (and the
/// owner of jobs and sweeps created before tenants existed).
pub const IMPLICIT_TENANT: &str = "default";

/// Shortest accepted token: shorter ones are guessable.
pub const MIN_TOKEN_LENGTH: usize = 16;

/// Longest tenant name.
pub const MAX_TENANT_LENGTH: usize = 64;

/// The owner of jobs and sweeps: a name from the auth file, or [`IMPLICIT_TENANT`].
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Tenant(Arc<str>);

impl Tenant {
    pub fn new(name: &str) -> Self {
        Self(Arc::from(name))
    }

    /// The tenant of a service without an auth file.
    pub fn implicit() -> Self {
        Self::new(IMPLICIT_TENANT)
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl fmt::Display for Tenant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// Why the auth file cannot be used (the service refuses to start).
#[derive(Debug, thiserror::Error)]
pub enum AuthFileError {
    #[error("cannot read the auth file {path}: {source}")]
    Read { path: String, source: std::io::Error },
    /// A malformed line; the message names the line, never the token.
    #[error("auth file line {line}: {reason}")]
    Line { line: usize, reason: String },
    #[error("the auth file holds no `<tenant> <token>` line")]
    Empty,
}

/// The SHA-256 of every token with its tenant.
#[derive(Clone)]
pub struct TokenTable {
    entries: Vec<([u8; 32], Tenant)>,
}

impl fmt::Debug for TokenTable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Hashes are not secrets, but there is nothing useful in printing them.
        f.debug_struct("TokenTable")
            .field("tokens", &self.entries.len())
            .finish()
    }
}

fn digest(token: &str) -> [u8; 32] {
    Sha256::digest(token.as_bytes()).into()
}

pub(crate) fn valid_tenant(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= MAX_TENANT_LENGTH
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'-' | b'_' | b'.'))
}

impl TokenTable {
    /// Reads and parses the auth file at `path`.
    pub fn load(path: &Path) -> Result<Self, AuthFileError> {
        let text = std::fs::read_to_string(path).map_err(|source| AuthFileError::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::parse(&text)
    }

    /// Parses the text of an auth file.
    pub fn parse(text: &str) -> Result<Self, AuthFileError> {
        let mut entries: Vec<([u8; 32], Tenant)> = Vec::new();
        let mut lines_of: Vec<usize> = Vec::new();
        for (index, line) in text.lines().enumerate() {
            let number = index + 1;
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let bad = |reason: String| AuthFileError::Line { line: number, reason };
            let fields: Vec<&str> = line.split_whitespace().collect();
            let [tenant, token] = fields[..] else {
                return Err(bad(format!(
                    "expected `<tenant> <token>`, found {} fields",
                    fields.len()
                )));
            };
            if !valid_tenant(tenant) {
                return Err(bad(format!(
                    "the tenant name must be 1 to {MAX_TENANT_LENGTH} letters, digits, `-`, `_` or `.`"
                )));
            }
            if token.len() < MIN_TOKEN_LENGTH {
                return Err(bad(format!(
                    "the token is shorter than {MIN_TOKEN_LENGTH} characters"
                )));
            }
            if !token.bytes().all(|b| b.is_ascii_graphic()) {
                return Err(bad("the token must be printable ASCII".into()));
            }
            let hash = digest(token);
            if let Some(previous) = entries.iter().position(|(h, _)| *h == hash) {
                return Err(bad(format!(
                    "the same token is already on line {}",
                    lines_of[previous]
                )));
            }
            entries.push((hash, Tenant::new(tenant)));
            lines_of.push(number);
        }
        if entries.is_empty() {
            return Err(AuthFileError::Empty);
        }
        Ok(Self { entries })
    }

    /// The tenant of `token`, if it is one of the table's. Every stored hash is
    /// compared, each in constant time, whatever matches.
    pub fn tenant_for(&self, token: &str) -> Option<Tenant> {
        let presented = digest(token);
        let mut found = None;
        for (hash, tenant) in &self.entries {
            if bool::from(hash.ct_eq(&presented)) {
                found = Some(tenant);
            }
        }
        found.cloned()
    }

    /// Number of tokens.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = "# team tokens\n\nalpha aaaaaaaaaaaaaaaaaaaaaaaa\n  beta   bbbbbbbbbbbbbbbbbbbbbbbb  \nalpha cccccccccccccccccccccccc\n";

    #[test]
    fn tokens_map_to_their_tenant_and_comments_are_ignored() {
        let table = TokenTable::parse(FILE).unwrap();
        assert_eq!(table.len(), 3);
        assert_eq!(
            table.tenant_for("aaaaaaaaaaaaaaaaaaaaaaaa"),
            Some(Tenant::new("alpha"))
        );
        assert_eq!(
            table.tenant_for("cccccccccccccccccccccccc"),
            Some(Tenant::new("alpha"))
        );
        assert_eq!(
            table.tenant_for("bbbbbbbbbbbbbbbbbbbbbbbb"),
            Some(Tenant::new("beta"))
        );
        assert_eq!(table.tenant_for("bbbbbbbbbbbbbbbbbbbbbbbB"), None);
        assert_eq!(table.tenant_for(""), None);
    }

    #[test]
    fn only_hashes_are_kept() {
        let table = TokenTable::parse(FILE).unwrap();
        let shown = format!("{table:?}");
        assert!(!shown.contains("aaaa"), "{shown}");
        assert!(
            table
                .entries
                .iter()
                .all(|(hash, _)| !hash.windows(4).any(|w| w == b"aaaa"))
        );
    }

    fn line_error(text: &str) -> (usize, String) {
        match TokenTable::parse(text) {
            Err(AuthFileError::Line { line, reason }) => (line, reason),
            other => panic!("expected a line error, got {other:?}"),
        }
    }

    #[test]
    fn a_malformed_line_is_named_without_its_token() {
        let (line, reason) = line_error("# c\nalpha aaaaaaaaaaaaaaaaaaaa\nbeta\n");
        assert_eq!(line, 3);
        assert!(reason.contains("<tenant> <token>"), "{reason}");
        let (line, reason) = line_error("alpha aaaaaaaaaaaaaaaaaaaa extra\n");
        assert_eq!(line, 1);
        assert!(reason.contains("3 fields"), "{reason}");
        let (line, reason) = line_error("alpha qwxz\n");
        assert_eq!(line, 1);
        assert!(!reason.contains("qwxz"), "the token leaks: {reason}");
        let (line, _) = line_error("al/pha aaaaaaaaaaaaaaaaaaaa\n");
        assert_eq!(line, 1);
    }

    #[test]
    fn a_token_given_twice_is_refused() {
        let (line, reason) = line_error("alpha aaaaaaaaaaaaaaaaaaaa\nbeta aaaaaaaaaaaaaaaaaaaa\n");
        assert_eq!(line, 2);
        assert!(reason.contains("line 1"), "{reason}");
    }

    #[test]
    fn an_empty_file_is_refused() {
        assert!(matches!(
            TokenTable::parse("# nothing\n\n"),
            Err(AuthFileError::Empty)
        ));
    }
}
