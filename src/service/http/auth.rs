//! Authentication: every request gets its [`Tenant`] in its extensions, or a 401.
//!
//! With an auth file, every route but `/healthz` (and `/metrics` when it is public)
//! needs `Authorization: Bearer <token>`; the token's tenant owns what the request
//! creates and is the only one that sees it. Without an auth file every request is the
//! implicit tenant.
//!
//! The dashboard works with tokens too: its static files (`/ui/...`: scripts, style,
//! the submit form, the shipped examples) hold no tenant's data and are served to
//! anyone, and a browser asking for a page (`/jobs` as HTML) without a token gets the
//! page's shell with a 401. The page's scripts then ask for a token, keep it in the
//! tab's session storage and send it with every API call.

use std::sync::Arc;

use axum::extract::{Request, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use super::dashboard;
use crate::problem::Problem;
use crate::service::auth::{Tenant, TokenTable};

/// Who may call what.
#[derive(Debug, Clone)]
pub struct AuthPolicy {
    /// `None`: no authentication, one implicit tenant.
    pub tokens: Option<TokenTable>,
    /// `/metrics` answers without a token.
    pub metrics_public: bool,
}

/// Routes that answer without a token.
fn is_open(policy: &AuthPolicy, path: &str) -> bool {
    path == "/healthz"
        || path == "/readyz"
        || path.starts_with("/ui/")
        || (policy.metrics_public && path == "/metrics")
}

/// The bearer token of an `Authorization` header (scheme case-insensitive).
fn bearer_token(value: &HeaderValue) -> Option<&str> {
    let text = value.to_str().ok()?;
    let (scheme, token) = text.split_once(' ')?;
    scheme
        .eq_ignore_ascii_case("bearer")
        .then(|| token.trim())
        .filter(|t| !t.is_empty())
}

fn unauthorized(request: &Request, detail: &str, challenge: &'static str) -> Response {
    let mut response = match super::negotiation::wants_page(request) {
        Some(page) => {
            let mut page = dashboard::html_page(page, StatusCode::UNAUTHORIZED);
            page.headers_mut()
                .append(header::VARY, HeaderValue::from_static("accept"));
            page
        }
        None => Problem::unauthorized(detail).into_response(),
    };
    response
        .headers_mut()
        .insert(header::WWW_AUTHENTICATE, HeaderValue::from_static(challenge));
    response
}

/// Middleware: puts the request's [`Tenant`] in its extensions, or answers 401.
pub async fn authenticate(
    State(policy): State<Arc<AuthPolicy>>,
    mut request: Request,
    next: Next,
) -> Response {
    let tenant = match &policy.tokens {
        None => Tenant::implicit(),
        Some(_) if is_open(&policy, request.uri().path()) => Tenant::implicit(),
        Some(tokens) => match request.headers().get(header::AUTHORIZATION) {
            None => {
                return unauthorized(
                    &request,
                    "this service needs `Authorization: Bearer <token>`",
                    "Bearer realm=\"chocmodal\"",
                );
            }
            Some(value) => match bearer_token(value).and_then(|token| tokens.tenant_for(token)) {
                Some(tenant) => tenant,
                None => {
                    tracing::info!(path = %request.uri().path(), "request with an invalid bearer token");
                    return unauthorized(
                        &request,
                        "the bearer token is not valid",
                        "Bearer realm=\"chocmodal\", error=\"invalid_token\"",
                    );
                }
            },
        },
    };
    request.extensions_mut().insert(tenant);
    next.run(request).await
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bearer_scheme_is_case_insensitive_and_needs_a_token() {
        let token = |text: &'static str| bearer_token(&HeaderValue::from_static(text)).map(str::to_owned);
        assert_eq!(token("Bearer abc"), Some("abc".into()));
        assert_eq!(token("bearer  abc "), Some("abc".into()));
        assert_eq!(token("Basic abc"), None);
        assert_eq!(token("Bearer "), None);
        assert_eq!(token("Bearer"), None);
    }
}
