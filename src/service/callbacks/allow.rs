//! The hosts the operator allows callbacks to (`--callback-allow`): a subscriber URI
//! whose host matches none of them is refused at submission, and a stored one is not
//! called any more once its host was taken off the list.
//!
//! A pattern is a host name (`hooks.example.com`), a wildcard over its subdomains
//! (`*.example.com`: `a.example.com`, `a.b.example.com`, not `example.com` itself), an
//! IPv4 address (`10.0.0.7`) or an IPv6 address in brackets (`[::1]`), each optionally
//! with a port (`localhost:8080`: that port only; without one: any port). Names compare
//! without regard to case. Only the URI's host is checked, not the address it resolves
//! to: allow names whose DNS the operator trusts.

use std::fmt;
use std::str::FromStr;

use reqwest::Url;

/// One allowed host (or family of hosts), with an optional port.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HostPattern {
    host: HostMatch,
    port: Option<u16>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum HostMatch {
    /// This host exactly (a lower-case name, an IPv4 address, or `[v6]`).
    Exact(String),
    /// Any subdomain of this name (stored with its leading dot: `.example.com`).
    Subdomains(String),
}

impl FromStr for HostPattern {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let text = text.trim().to_ascii_lowercase();
        if text.is_empty() {
            return Err("an empty host pattern".into());
        }
        if text == "*" || text.contains("://") || text.contains('/') {
            return Err(format!(
                "`{text}`: expected a host (`hooks.example.com`, `*.example.com`, `10.0.0.7`, `[::1]`), \
                 optionally with `:port`"
            ));
        }
        let (host, port) = split_port(&text)?;
        let host = match host.strip_prefix("*.") {
            Some(domain) => {
                check_name(domain, &text)?;
                HostMatch::Subdomains(format!(".{domain}"))
            }
            None if host.starts_with('[') => {
                let inner = host.trim_start_matches('[').trim_end_matches(']');
                let address: std::net::Ipv6Addr = inner
                    .parse()
                    .map_err(|_| format!("`{text}`: `{host}` is not an IPv6 address"))?;
                // The form `Url::host_str` gives: compressed, in brackets.
                HostMatch::Exact(format!("[{address}]"))
            }
            None => {
                check_name(host, &text)?;
                HostMatch::Exact(host.to_owned())
            }
        };
        Ok(Self { host, port })
    }
}

/// `host:port` → (`host`, port); `[v6]:port` too; a bare IPv6 address is refused
/// (its colons would be ambiguous).
fn split_port(text: &str) -> Result<(&str, Option<u16>), String> {
    let (host, port) = if text.starts_with('[') {
        match text.find(']') {
            Some(end) => {
                let rest = &text[end + 1..];
                match rest.strip_prefix(':') {
                    Some(port) => (&text[..=end], Some(port)),
                    None if rest.is_empty() => (text, None),
                    None => return Err(format!("`{text}`: unexpected `{rest}` after the address")),
                }
            }
            None => return Err(format!("`{text}`: an IPv6 address needs its closing `]`")),
        }
    } else if text.matches(':').count() > 1 {
        return Err(format!("`{text}`: write an IPv6 address in brackets, `[::1]`"));
    } else {
        match text.split_once(':') {
            Some((host, port)) => (host, Some(port)),
            None => (text, None),
        }
    };
    let port = port
        .map(|port| {
            port.parse::<u16>()
                .ok()
                .filter(|&p| p > 0)
                .ok_or_else(|| format!("`{text}`: `{port}` is not a port (1 to 65535)"))
        })
        .transpose()?;
    Ok((host, port))
}

fn check_name(name: &str, text: &str) -> Result<(), String> {
    let fine = !name.is_empty()
        && name.split('.').all(|label| {
            !label.is_empty()
                && label
                    .bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_')
        });
    if fine {
        Ok(())
    } else {
        Err(format!(
            "`{text}`: `{name}` is not a host name (letters, digits, `-`, `_` between dots; \
             a wildcard only as the first label, `*.example.com`)"
        ))
    }
}

impl HostPattern {
    /// Whether `uri`'s host (and port) match this pattern.
    pub fn matches(&self, uri: &Url) -> bool {
        let Some(host) = uri.host_str() else {
            return false;
        };
        let host = host.to_ascii_lowercase();
        let host = host.trim_end_matches('.');
        let host_fits = match &self.host {
            HostMatch::Exact(exact) => host == exact,
            HostMatch::Subdomains(suffix) => host.len() > suffix.len() && host.ends_with(suffix.as_str()),
        };
        host_fits
            && self
                .port
                .is_none_or(|port| uri.port_or_known_default() == Some(port))
    }
}

impl fmt::Display for HostPattern {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.host {
            HostMatch::Exact(host) => f.write_str(host)?,
            HostMatch::Subdomains(suffix) => write!(f, "*{suffix}")?,
        }
        match self.port {
            Some(port) => write!(f, ":{port}"),
            None => Ok(()),
        }
    }
}

/// The operator's list; empty: no callbacks at all.
#[derive(Debug, Clone, Default)]
pub struct AllowList(Vec<HostPattern>);

impl AllowList {
    pub fn new(patterns: Vec<HostPattern>) -> Self {
        Self(patterns)
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    pub fn allows(&self, uri: &Url) -> bool {
        self.0.iter().any(|pattern| pattern.matches(uri))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn url(text: &str) -> Url {
        Url::parse(text).unwrap()
    }

    fn pattern(text: &str) -> HostPattern {
        text.parse().unwrap_or_else(|e| panic!("{text}: {e}"))
    }

    #[test]
    fn an_exact_host_matches_itself_on_any_port_whatever_the_case() {
        let p = pattern("Hooks.Example.com");
        assert!(p.matches(&url("https://hooks.example.com/x")));
        assert!(p.matches(&url("http://HOOKS.example.com:8443/x")));
        assert!(!p.matches(&url("https://evil-hooks.example.com/")));
        assert!(!p.matches(&url("https://hooks.example.com.evil.net/")));
    }

    #[test]
    fn a_wildcard_matches_subdomains_only() {
        let p = pattern("*.example.com");
        assert!(p.matches(&url("https://a.example.com/")));
        assert!(p.matches(&url("https://a.b.example.com/")));
        assert!(!p.matches(&url("https://example.com/")));
        assert!(!p.matches(&url("https://badexample.com/")));
    }

    #[test]
    fn a_port_restricts_the_match_and_defaults_count() {
        let p = pattern("127.0.0.1:9000");
        assert!(p.matches(&url("http://127.0.0.1:9000/hook")));
        assert!(!p.matches(&url("http://127.0.0.1:9001/hook")));
        assert!(pattern("example.com:443").matches(&url("https://example.com/")));
        assert!(!pattern("example.com:443").matches(&url("http://example.com/")));
    }

    #[test]
    fn ipv6_addresses_are_written_in_brackets() {
        let p = pattern("[0:0::1]:8080");
        assert!(p.matches(&url("http://[::1]:8080/")), "{p}");
        assert!("::1".parse::<HostPattern>().is_err());
        assert!("[::1".parse::<HostPattern>().is_err());
    }

    #[test]
    fn nonsense_patterns_are_refused_with_the_reason() {
        for bad in [
            "",
            "*",
            "https://example.com",
            "a..b",
            "example.com:0",
            "example.com:x",
            "*.",
            "a/b",
        ] {
            let error = bad.parse::<HostPattern>().unwrap_err();
            assert!(!error.is_empty(), "{bad}");
        }
        assert!(
            "exa mple.com"
                .parse::<HostPattern>()
                .unwrap_err()
                .contains("not a host name")
        );
    }

    #[test]
    fn an_empty_list_allows_nothing() {
        assert!(!AllowList::default().allows(&url("http://127.0.0.1/")));
        let list = AllowList::new(vec![pattern("localhost"), pattern("*.corp.net")]);
        assert!(list.allows(&url("http://localhost:1234/")));
        assert!(list.allows(&url("https://ci.corp.net/")));
        assert!(!list.allows(&url("https://corp.net/")));
    }
}
