//! Idempotency keys: a client that retries a creation (`POST /processes/{id}/execution`,
//! `POST /sweeps`, `POST /signals`) after losing the answer sends the same
//! `Idempotency-Key` header, and gets the resource its first request created instead of
//! a second one.
//!
//! A key is the tenant's (another tenant's identical key is another key) and names one
//! resource together with the hash of the request that created it ([`RequestHash`]:
//! what was created, and the body as the service understood it). The key row is inserted
//! in the transaction that inserts the resource ([`IdempotencyStore::store_key`]), so the
//! two land together or not at all, and it is deleted with the resource (foreign keys
//! with `ON DELETE CASCADE`, `migrations/0006_idempotency.sql`): a key lives exactly as
//! long as its resource. The same key with another request is a conflict (422).
//!
//! Two concurrent first uses of one key: both may find no key, but only one insert of
//! the key commits (primary key `(tenant, idempotency_key)`); the other transaction
//! fails on the key's unique constraint, rolls back its resource, and the caller looks
//! the key up again ([`is_key_taken`]) and answers with the winner's resource.

use std::fmt;

use serde_json::Value;
use sha2::{Digest, Sha256};

use super::content_hash::canonical;

/// Longest accepted key (characters).
pub const MAX_KEY_LENGTH: usize = 255;

/// The name of the header.
pub const HEADER: &str = "Idempotency-Key";

/// What a key created.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Job,
    Sweep,
    Signal,
}

impl Kind {
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Job => "job",
            Kind::Sweep => "sweep",
            Kind::Signal => "signal",
        }
    }

    fn parse(text: &str) -> Option<Self> {
        [Kind::Job, Kind::Sweep, Kind::Signal]
            .into_iter()
            .find(|kind| kind.as_str() == text)
    }
}

/// A valid key: 1 to [`MAX_KEY_LENGTH`] visible ASCII characters (no spaces), as
/// sent in the header.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IdempotencyKey(String);

impl IdempotencyKey {
    /// Parses the header's value; the error says why it is refused.
    pub fn parse(value: &[u8]) -> Result<Self, String> {
        let text = std::str::from_utf8(value).map_err(|_| "is not ASCII text".to_owned())?;
        if text.is_empty() {
            return Err("is empty".into());
        }
        if text.len() > MAX_KEY_LENGTH {
            return Err(format!(
                "is {} characters long; at most {MAX_KEY_LENGTH} are accepted",
                text.len()
            ));
        }
        if let Some(bad) = text.chars().find(|c| !c.is_ascii_graphic()) {
            return Err(format!(
                "contains {bad:?}: only visible ASCII characters (no spaces) are accepted"
            ));
        }
        Ok(Self(text.to_owned()))
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl fmt::Display for IdempotencyKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// SHA-256 (hex) of what a request asks to create: its kind, then the canonical JSON
/// of its body (member order and whitespace do not matter) or its bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RequestHash(String);

impl RequestHash {
    /// A JSON request: `kind`, the resource it targets (a process id, or empty) and
    /// its body, canonical.
    pub fn of_json(kind: Kind, target: &str, body: &Value) -> Self {
        let mut text = String::with_capacity(512);
        text.push_str(kind.as_str());
        text.push('\n');
        text.push_str(target);
        text.push('\n');
        canonical(body, &mut text);
        Self::digest(text.as_bytes())
    }

    /// A request whose body is not JSON (a CSV record): `kind`, a description of how
    /// to read it (content type, query) and its bytes.
    pub fn of_bytes(kind: Kind, reading: &str, body: &[u8]) -> Self {
        let mut hasher = Sha256::new();
        hasher.update(kind.as_str().as_bytes());
        hasher.update(b"\n");
        hasher.update(reading.as_bytes());
        hasher.update(b"\n");
        hasher.update(body);
        Self(hex(&hasher.finalize()))
    }

    fn digest(bytes: &[u8]) -> Self {
        Self(hex(&Sha256::digest(bytes)))
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|byte| format!("{byte:02x}")).collect()
}

/// A key and the request it comes with: what a creation stores, or compares with the
/// stored key.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyedRequest {
    pub key: IdempotencyKey,
    pub kind: Kind,
    pub hash: RequestHash,
}

/// A key already used by the tenant.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StoredKey {
    pub kind: Kind,
    pub request_hash: String,
    /// The id of the resource it created.
    pub resource_id: String,
}

/// What a key already in use means for a request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Prior {
    /// The same request: answer with this resource (its id).
    Same(String),
    /// Another request (another body, or another kind of resource): refuse it.
    Conflict(KeyConflict),
}

/// The same key sent with another request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyConflict {
    pub key: String,
    /// What the key created first.
    pub kind: Kind,
    pub resource_id: String,
    /// Whether the first request created another kind of resource.
    pub other_kind: bool,
}

impl StoredKey {
    /// What this stored key means for `request`.
    pub fn prior_for(self, request: &KeyedRequest) -> Prior {
        if self.kind == request.kind && self.request_hash == request.hash.as_str() {
            Prior::Same(self.resource_id)
        } else {
            Prior::Conflict(KeyConflict {
                key: request.key.as_str().to_owned(),
                kind: self.kind,
                resource_id: self.resource_id,
                other_kind: self.kind != request.kind,
            })
        }
    }
}

/// The outcome of a creation that may carry a key.
#[derive(Debug, Clone, PartialEq)]
pub enum Keyed<T> {
    /// Created now.
    Created(T),
    /// The key's first request created this, with the same request: nothing new.
    Replayed(T),
    /// The key was first used with another request: nothing created.
    Conflict(KeyConflict),
}

/// Whether `error` is the unique violation of a concurrent first use of the same key.
pub fn is_key_taken(error: &sqlx::Error) -> bool {
    match error {
        sqlx::Error::Database(database) => {
            database.is_unique_violation()
                && (database.message().contains("idempotency_keys")
                    || database.constraint() == Some("idempotency_keys_pkey"))
        }
        _ => false,
    }
}

/// The key statements, run inside the caller's transaction on either backend.
pub(crate) trait IdempotencyStore {
    /// The key `key` of `tenant`, if used.
    async fn find_key(
        &mut self,
        tenant: &str,
        key: &IdempotencyKey,
    ) -> Result<Option<StoredKey>, sqlx::Error>;

    /// Records `request`'s key as having created `resource_id`.
    async fn store_key(
        &mut self,
        tenant: &str,
        request: &KeyedRequest,
        resource_id: &str,
        now_ms: i64,
    ) -> Result<(), sqlx::Error>;
}

const FIND: &str = "SELECT kind, request_hash, COALESCE(job_id, sweep_id, signal_id) AS resource_id \
     FROM idempotency_keys WHERE tenant = $1 AND idempotency_key = $2";

/// The insert for a key of `kind` (the id goes to that kind's column).
fn store_sql(kind: Kind) -> &'static str {
    match kind {
        Kind::Job => {
            "INSERT INTO idempotency_keys (tenant, idempotency_key, kind, request_hash, job_id, created_at) \
             VALUES ($1, $2, $3, $4, $5, $6)"
        }
        Kind::Sweep => {
            "INSERT INTO idempotency_keys (tenant, idempotency_key, kind, request_hash, sweep_id, created_at) \
             VALUES ($1, $2, $3, $4, $5, $6)"
        }
        Kind::Signal => {
            "INSERT INTO idempotency_keys (tenant, idempotency_key, kind, request_hash, signal_id, created_at) \
             VALUES ($1, $2, $3, $4, $5, $6)"
        }
    }
}

/// One implementation, compiled for each backend's connection.
macro_rules! idempotency_store {
    ($connection:ty) => {
        impl IdempotencyStore for $connection {
            async fn find_key(
                &mut self,
                tenant: &str,
                key: &IdempotencyKey,
            ) -> Result<Option<StoredKey>, sqlx::Error> {
                let row: Option<(String, String, String)> = sqlx::query_as(FIND)
                    .bind(tenant)
                    .bind(key.as_str())
                    .fetch_optional(&mut *self)
                    .await?;
                row.map(
                    |(kind, request_hash, resource_id)| -> Result<StoredKey, sqlx::Error> {
                        let kind = Kind::parse(&kind).ok_or_else(|| sqlx::Error::ColumnDecode {
                            index: "kind".into(),
                            source: format!("unknown idempotency key kind `{kind}`").into(),
                        })?;
                        Ok(StoredKey {
                            kind,
                            request_hash,
                            resource_id,
                        })
                    },
                )
                .transpose()
            }

            async fn store_key(
                &mut self,
                tenant: &str,
                request: &KeyedRequest,
                resource_id: &str,
                now_ms: i64,
            ) -> Result<(), sqlx::Error> {
                sqlx::query(store_sql(request.kind))
                    .bind(tenant)
                    .bind(request.key.as_str())
                    .bind(request.kind.as_str())
                    .bind(request.hash.as_str())
                    .bind(resource_id)
                    .bind(now_ms)
                    .execute(&mut *self)
                    .await?;
                Ok(())
            }
        }
    };
}

idempotency_store!(sqlx::SqliteConnection);
idempotency_store!(sqlx::PgConnection);

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn keys_are_visible_ascii_of_bounded_length() {
        assert_eq!(
            IdempotencyKey::parse(b"order-17/retry").unwrap().as_str(),
            "order-17/retry"
        );
        assert!(IdempotencyKey::parse(b"").unwrap_err().contains("empty"));
        assert!(IdempotencyKey::parse(b"two words").unwrap_err().contains("' '"));
        assert!(IdempotencyKey::parse("clé".as_bytes()).is_err());
        let long = "k".repeat(MAX_KEY_LENGTH + 1);
        assert!(
            IdempotencyKey::parse(long.as_bytes())
                .unwrap_err()
                .contains("255")
        );
    }

    #[test]
    fn the_request_hash_ignores_member_order_but_not_values_kinds_or_targets() {
        let a = json!({"inputs": {"steps": 3, "step_ms": 1}});
        let b: Value = serde_json::from_str(r#"{"inputs": {"step_ms": 1, "steps": 3}}"#).unwrap();
        let hash = |kind, target, body: &Value| RequestHash::of_json(kind, target, body);
        assert_eq!(hash(Kind::Job, "p", &a), hash(Kind::Job, "p", &b));
        assert_ne!(hash(Kind::Job, "p", &a), hash(Kind::Job, "q", &a));
        assert_ne!(hash(Kind::Job, "p", &a), hash(Kind::Sweep, "p", &a));
        assert_ne!(
            hash(Kind::Job, "p", &a),
            hash(Kind::Job, "p", &json!({"inputs": {"steps": 4, "step_ms": 1}}))
        );
    }

    #[test]
    fn a_stored_key_replays_the_same_request_and_refuses_another() {
        let request = KeyedRequest {
            key: IdempotencyKey::parse(b"k1").unwrap(),
            kind: Kind::Signal,
            hash: RequestHash::of_bytes(Kind::Signal, "text/csv", b"0,1\n1,2\n"),
        };
        let stored = StoredKey {
            kind: Kind::Signal,
            request_hash: request.hash.as_str().to_owned(),
            resource_id: "s1".into(),
        };
        assert_eq!(stored.clone().prior_for(&request), Prior::Same("s1".into()));
        let other = KeyedRequest {
            hash: RequestHash::of_bytes(Kind::Signal, "text/csv", b"0,1\n1,3\n"),
            ..request.clone()
        };
        assert!(matches!(
            stored.clone().prior_for(&other),
            Prior::Conflict(KeyConflict {
                other_kind: false,
                ..
            })
        ));
        let job = KeyedRequest {
            kind: Kind::Job,
            ..request
        };
        assert!(matches!(
            stored.prior_for(&job),
            Prior::Conflict(KeyConflict { other_kind: true, .. })
        ));
    }
}
