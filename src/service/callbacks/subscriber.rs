//! The `subscriber` member of an execution request (OGC API – Processes, Part 1:
//! `{"successUri", "failedUri", "inProgressUri"}`, each optional), parsed once at
//! submission against the operator's policy: absolute `http`/`https` URIs whose host is
//! allowed (`--callback-allow`), of a tenant that has a signing secret
//! (`--callback-secrets`). Every refusal names its member, e.g. `/subscriber/successUri`.

use reqwest::Url;
use serde_json::Value;

use super::CallbackPolicy;
use crate::processes::{FieldError, InvalidInputs};

/// Longest accepted subscriber URI (characters).
pub const MAX_URI_LENGTH: usize = 2048;

/// Where a job's outcome and progress are POSTed; at least one URI is set.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Subscriber {
    /// Receives the status document when the job is `successful`.
    pub success_uri: Option<Url>,
    /// Receives it when the job is `failed` or `dismissed`.
    pub failed_uri: Option<Url>,
    /// Receives it while the job runs, at most once per progress interval.
    pub in_progress_uri: Option<Url>,
}

/// The members, in the order they are checked and reported.
const MEMBERS: [&str; 3] = ["successUri", "failedUri", "inProgressUri"];

impl Subscriber {
    /// Parses the `subscriber` member of `tenant`'s request. `None` for a missing or
    /// `null` member, or an object without URIs (nothing to call).
    pub fn parse(
        value: Option<&Value>,
        policy: &CallbackPolicy,
        tenant: &str,
    ) -> Result<Option<Self>, InvalidInputs> {
        let object = match value {
            None | Some(Value::Null) => return Ok(None),
            Some(Value::Object(object)) => object,
            Some(_) => {
                return Err(InvalidInputs(vec![FieldError::new(
                    "/subscriber",
                    "must be an object with any of `successUri`, `failedUri`, `inProgressUri`",
                )]));
            }
        };
        let mut errors: Vec<FieldError> = object
            .keys()
            .filter(|key| !MEMBERS.contains(&key.as_str()))
            .map(|key| {
                FieldError::new(
                    format!("/subscriber/{}", crate::pointer::escape(key)),
                    "unknown member of `subscriber` (expected `successUri`, `failedUri`, `inProgressUri`)",
                )
            })
            .collect();
        let mut uris: [Option<Url>; 3] = [None, None, None];
        for (slot, member) in uris.iter_mut().zip(MEMBERS) {
            let Some(value) = object.get(member) else { continue };
            match parse_uri(value, policy) {
                Ok(uri) => *slot = Some(uri),
                Err(detail) => errors.push(FieldError::new(format!("/subscriber/{member}"), detail)),
            }
        }
        if errors.is_empty() && uris.iter().any(Option::is_some) && policy.secrets.of(tenant).is_empty() {
            errors.push(FieldError::new(
                "/subscriber",
                format!(
                    "this service has no callback signing secret for tenant `{tenant}`, so it sends \
                     it no callbacks: its operator gives one with `--callback-secrets`"
                ),
            ));
        }
        if !errors.is_empty() {
            return Err(InvalidInputs(errors));
        }
        let [success_uri, failed_uri, in_progress_uri] = uris;
        if success_uri.is_none() && failed_uri.is_none() && in_progress_uri.is_none() {
            return Ok(None);
        }
        Ok(Some(Self {
            success_uri,
            failed_uri,
            in_progress_uri,
        }))
    }

    /// The subscriber as the request spelled it (for idempotency hashes).
    pub fn to_json(&self) -> Value {
        let mut object = serde_json::Map::new();
        for (member, uri) in MEMBERS
            .iter()
            .zip([&self.success_uri, &self.failed_uri, &self.in_progress_uri])
        {
            if let Some(uri) = uri {
                object.insert((*member).to_owned(), Value::String(uri.to_string()));
            }
        }
        Value::Object(object)
    }
}

/// One URI member: an absolute http(s) URI of an allowed host, or why not.
fn parse_uri(value: &Value, policy: &CallbackPolicy) -> Result<Url, String> {
    let Value::String(text) = value else {
        return Err("must be a string: an absolute `http` or `https` URI".into());
    };
    if text.len() > MAX_URI_LENGTH {
        return Err(format!("is longer than {MAX_URI_LENGTH} characters"));
    }
    let uri = Url::parse(text).map_err(|error| {
        format!("is not an absolute URI ({error}): expected e.g. `https://hooks.example.com/jobs`")
    })?;
    if !matches!(uri.scheme(), "http" | "https") {
        return Err(format!(
            "must be an `http` or `https` URI, not `{}:`",
            uri.scheme()
        ));
    }
    let host = match uri.host_str() {
        Some(host) if !host.is_empty() => host.to_owned(),
        _ => return Err("has no host".into()),
    };
    if policy.allow.is_empty() {
        return Err(
            "this service sends no callbacks: its operator has allowed no host (`--callback-allow`)".into(),
        );
    }
    if !policy.allow.allows(&uri) {
        return Err(format!(
            "host `{host}` is not one this service may call back (its operator allows hosts with \
             `--callback-allow`)"
        ));
    }
    Ok(uri)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::service::callbacks::{AllowList, CallbackSecrets};
    use serde_json::json;

    fn policy() -> CallbackPolicy {
        let mut secrets = CallbackSecrets::default();
        secrets.insert("default", "0123456789abcdef0123");
        CallbackPolicy {
            allow: AllowList::new(vec![
                "127.0.0.1".parse().unwrap(),
                "*.example.com".parse().unwrap(),
            ]),
            secrets,
        }
    }

    fn errors(value: Value, policy: &CallbackPolicy, tenant: &str) -> Vec<(String, String)> {
        Subscriber::parse(Some(&value), policy, tenant)
            .unwrap_err()
            .0
            .into_iter()
            .map(|e| (e.pointer, e.detail))
            .collect()
    }

    #[test]
    fn allowed_uris_parse_and_missing_ones_stay_unset() {
        let subscriber = Subscriber::parse(
            Some(&json!({"successUri": "http://127.0.0.1:9000/done", "inProgressUri": "https://a.example.com/p"})),
            &policy(),
            "default",
        )
        .unwrap()
        .unwrap();
        assert_eq!(
            subscriber.success_uri.unwrap().as_str(),
            "http://127.0.0.1:9000/done"
        );
        assert!(subscriber.failed_uri.is_none());
        assert_eq!(
            subscriber.in_progress_uri.unwrap().host_str(),
            Some("a.example.com")
        );
        assert_eq!(Subscriber::parse(None, &policy(), "default").unwrap(), None);
        assert_eq!(
            Subscriber::parse(Some(&Value::Null), &policy(), "default").unwrap(),
            None
        );
        assert_eq!(
            Subscriber::parse(Some(&json!({})), &policy(), "default").unwrap(),
            None
        );
    }

    #[test]
    fn each_bad_uri_is_refused_at_its_member_with_the_reason() {
        let found = errors(
            json!({
                "successUri": "/relative/path",
                "failedUri": "ftp://127.0.0.1/x",
                "inProgressUri": "https://evil.net/x",
                "callbackUri": "http://127.0.0.1/"
            }),
            &policy(),
            "default",
        );
        let detail = |pointer: &str| {
            found
                .iter()
                .find(|(p, _)| p == pointer)
                .map(|(_, d)| d.clone())
                .unwrap_or_else(|| panic!("no error at {pointer}: {found:?}"))
        };
        assert!(detail("/subscriber/successUri").contains("not an absolute URI"));
        assert!(detail("/subscriber/failedUri").contains("`http` or `https`"));
        assert!(detail("/subscriber/inProgressUri").contains("host `evil.net`"));
        assert!(detail("/subscriber/inProgressUri").contains("--callback-allow"));
        assert!(detail("/subscriber/callbackUri").contains("unknown member"));
        assert_eq!(
            errors(json!({"successUri": 7}), &policy(), "default")[0].1,
            "must be a string: an absolute `http` or `https` URI"
        );
        assert_eq!(errors(json!(["x"]), &policy(), "default")[0].0, "/subscriber");
    }

    #[test]
    fn without_an_allow_list_or_a_secret_subscribers_are_refused_saying_why() {
        let closed = CallbackPolicy::default();
        let found = errors(json!({"successUri": "http://127.0.0.1/"}), &closed, "default");
        assert_eq!(found[0].0, "/subscriber/successUri");
        assert!(
            found[0].1.contains("allowed no host (`--callback-allow`)"),
            "{found:?}"
        );
        let found = errors(json!({"successUri": "http://127.0.0.1/"}), &policy(), "alpha");
        assert_eq!(found[0].0, "/subscriber");
        assert!(found[0].1.contains("tenant `alpha`") && found[0].1.contains("--callback-secrets"));
    }
}
