//! The tenants' callback signing secrets (`--callback-secrets`): one `<tenant> <secret>`
//! pair per line, blank lines and `#` comments ignored, like the auth file. A tenant may
//! have several secrets (rotation: each delivery is signed with every one); a tenant
//! with none cannot subscribe to callbacks. Without an auth file the one tenant is
//! `default`. The secrets are kept in memory as given (they are HMAC keys) and never
//! printed.

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

use crate::service::auth::{MAX_TENANT_LENGTH, valid_tenant};

/// Shortest accepted secret (bytes): shorter ones are guessable.
pub const MIN_SECRET_LENGTH: usize = 16;

/// Why the secrets file cannot be used (the service refuses to start).
#[derive(Debug, thiserror::Error)]
pub enum SecretsFileError {
    #[error("cannot read the callback secrets file {path}: {source}")]
    Read { path: String, source: std::io::Error },
    /// A malformed line; the message names the line, never the secret.
    #[error("callback secrets file line {line}: {reason}")]
    Line { line: usize, reason: String },
}

/// Each tenant's secrets, in file order.
#[derive(Clone, Default)]
pub struct CallbackSecrets {
    by_tenant: BTreeMap<String, Vec<String>>,
}

impl fmt::Debug for CallbackSecrets {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CallbackSecrets")
            .field("tenants", &self.by_tenant.keys().collect::<Vec<_>>())
            .finish()
    }
}

impl CallbackSecrets {
    /// Reads and parses the file at `path`.
    pub fn load(path: &Path) -> Result<Self, SecretsFileError> {
        let text = std::fs::read_to_string(path).map_err(|source| SecretsFileError::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::parse(&text)
    }

    /// Parses the text of a secrets file.
    pub fn parse(text: &str) -> Result<Self, SecretsFileError> {
        let mut secrets = Self::default();
        for (index, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let bad = |reason: String| SecretsFileError::Line {
                line: index + 1,
                reason,
            };
            let fields: Vec<&str> = line.split_whitespace().collect();
            let [tenant, secret] = fields[..] else {
                return Err(bad(format!(
                    "expected `<tenant> <secret>`, found {} fields",
                    fields.len()
                )));
            };
            if !valid_tenant(tenant) {
                return Err(bad(format!(
                    "the tenant name must be 1 to {MAX_TENANT_LENGTH} letters, digits, `-`, `_` or `.`"
                )));
            }
            if secret.len() < MIN_SECRET_LENGTH {
                return Err(bad(format!(
                    "the secret is shorter than {MIN_SECRET_LENGTH} characters"
                )));
            }
            if !secret.bytes().all(|b| b.is_ascii_graphic()) {
                return Err(bad("the secret must be printable ASCII".into()));
            }
            secrets.insert(tenant, secret);
        }
        Ok(secrets)
    }

    /// Adds a secret of `tenant` (tests, and the file's lines).
    pub fn insert(&mut self, tenant: &str, secret: &str) {
        self.by_tenant
            .entry(tenant.to_owned())
            .or_default()
            .push(secret.to_owned());
    }

    /// The secrets of `tenant` (empty: it cannot subscribe).
    pub fn of(&self, tenant: &str) -> &[String] {
        self.by_tenant.get(tenant).map_or(&[], Vec::as_slice)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn secrets_belong_to_their_tenant_and_a_tenant_may_have_several() {
        let secrets = CallbackSecrets::parse(
            "# signing\nalpha 0123456789abcdef0123\n\n beta  fedcba9876543210fedc \nalpha second-secret-of-alpha\n",
        )
        .unwrap();
        assert_eq!(
            secrets.of("alpha"),
            ["0123456789abcdef0123", "second-secret-of-alpha"]
        );
        assert_eq!(secrets.of("beta"), ["fedcba9876543210fedc"]);
        assert!(secrets.of("gamma").is_empty());
        assert!(!format!("{secrets:?}").contains("0123"));
    }

    #[test]
    fn a_bad_line_is_named_without_its_secret() {
        for (text, line, words) in [
            ("alpha\n", 1, "`<tenant> <secret>`, found 1 fields"),
            ("# c\nalpha short\n", 2, "shorter than 16"),
            ("al/pha 0123456789abcdef0123\n", 1, "tenant name"),
        ] {
            match CallbackSecrets::parse(text) {
                Err(SecretsFileError::Line { line: at, reason }) => {
                    assert_eq!(at, line, "{text:?}");
                    assert!(reason.contains(words), "{reason}");
                    assert!(
                        !reason.contains("short\n") && !reason.contains("0123"),
                        "{reason}"
                    );
                }
                other => panic!("{text:?}: expected a line error, got {other:?}"),
            }
        }
    }
}
