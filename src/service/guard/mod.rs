//! Who may do what, and from where. One middleware ([`check`]) in front of every route: the
//! `Host` a request names (DNS rebinding), cross-site requests (a page on another origin must
//! not act), the caller's token and role ([`tokens`]), and the per-client rate limit of the
//! routes that cost work ([`rate`]). Which role a route needs and whether it is rate-limited
//! is declared beside the route in the route table ([`policy`]); the guard looks it up.
//! [`security_headers`] goes on every answer.

pub mod access;
pub mod policy;
pub mod rate;
pub mod tokens;

use super::error::ApiError;
use crate::solver::model::input::clip;
pub use access::Access;
use axum::extract::{ConnectInfo, Request};
use axum::http::{header, HeaderMap, HeaderValue, Method};
use axum::middleware::Next;
use axum::response::Response;
pub use policy::{Cost, Policies, Policy, Who};
use std::net::SocketAddr;
use std::num::NonZeroU32;
use std::path::PathBuf;
use std::sync::Arc;
pub use tokens::{Role, Tokens};

/// The cookie the web page keeps its token in (EventSource, `<img>` and download links cannot
/// send an `Authorization` header).
pub const COOKIE: &str = "crush_token";

/// The host names every server answers to, whatever the port.
const LOOPBACK_HOSTS: [&str; 3] = ["localhost", "127.0.0.1", "[::1]"];

/// Flags of `crush serve` on access control.
#[derive(Debug, Clone, clap::Args)]
pub struct AccessArgs {
    /// Token file: one token a line, `name role token` (role: read, submit or admin; `#`
    /// comments). Without one, anyone who can reach the port may do anything, so the server
    /// listens on loopback only unless --allow-anonymous-remote.
    #[arg(long, env = "CRUSH_TOKEN_FILE")]
    pub token_file: Option<PathBuf>,
    /// Listen on a non-loopback --host without a token file: anyone who can reach the port
    /// may read, submit and cancel every job.
    #[arg(long, env = "CRUSH_ALLOW_ANONYMOUS_REMOTE")]
    pub allow_anonymous_remote: bool,
    /// A host name (the `Host` header, any port) this server answers to besides localhost,
    /// 127.0.0.1 and [::1]; repeat or separate with commas. Without a token file only those
    /// are answered; with one, any host unless this is given.
    #[arg(
        long = "allowed-host",
        env = "CRUSH_ALLOWED_HOSTS",
        value_delimiter = ','
    )]
    pub allowed_hosts: Vec<String>,
    /// Who may read /healthz when tokens are configured.
    #[arg(long, env = "CRUSH_HEALTHZ_ACCESS", value_enum, default_value_t = Access::Open)]
    pub healthz_access: Access,
    /// Who may read /metrics when tokens are configured.
    #[arg(long, env = "CRUSH_METRICS_ACCESS", value_enum, default_value_t = Access::Read)]
    pub metrics_access: Access,
    /// Submits, sweeps, estimates, plans and sign-ins a client (a token, or an address without one)
    /// may make per second on average.
    #[arg(long, env = "CRUSH_RATE_LIMIT_PER_S", default_value_t = NonZeroU32::new(20).unwrap())]
    pub rate_limit_per_s: NonZeroU32,
    /// How many of those a client may make at once after a pause.
    #[arg(long, env = "CRUSH_RATE_LIMIT_BURST", default_value_t = NonZeroU32::new(120).unwrap())]
    pub rate_limit_burst: NonZeroU32,
}

/// Who sent a request: a token's name and role, or anyone when the server has no tokens.
#[derive(Debug, Clone)]
pub struct Caller {
    /// The token's name; `None` without tokens.
    pub name: Option<String>,
    pub role: Role,
    /// The token came in an `Authorization` header (not the page's cookie).
    pub bearer: bool,
}

impl Caller {
    /// Whether this caller may cancel or delete a job or sweep submitted by `owner`: an admin
    /// any, a submitter its own.
    pub fn may_cancel(&self, owner: Option<&str>) -> bool {
        self.role >= Role::Admin || (self.role >= Role::Submit && owner == self.name.as_deref())
    }
}

/// What a route needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Need {
    Nothing,
    Role(Role),
}

/// The access rules of one server.
pub struct Guard {
    tokens: Option<Tokens>,
    /// Host names answered besides the loopback ones; `None`: any.
    hosts: Option<Vec<String>>,
    healthz: Access,
    metrics: Access,
    limiter: rate::Limiter,
    /// Each route's policy, as the route table declares it.
    policies: Policies,
}

impl Guard {
    /// The rules the flags ask for, over the routes' declared `policies`; reads the token file.
    pub fn new(args: &AccessArgs, policies: Policies) -> anyhow::Result<Guard> {
        let tokens = args.token_file.as_deref().map(Tokens::load).transpose()?;
        let mut named = Vec::new();
        for host in &args.allowed_hosts {
            let host = host.trim().to_ascii_lowercase();
            anyhow::ensure!(
                !host.is_empty() && !host.contains(['/', ' ', '@']),
                "--allowed-host {host:?} is not a host name"
            );
            named.push(host_name(&host).to_string());
        }
        let hosts = (tokens.is_none() || !named.is_empty()).then_some(named);
        Ok(Guard {
            tokens,
            hosts,
            healthz: args.healthz_access,
            metrics: args.metrics_access,
            limiter: rate::Limiter::new(args.rate_limit_per_s, args.rate_limit_burst),
            policies,
        })
    }

    pub fn has_tokens(&self) -> bool {
        self.tokens.is_some()
    }

    /// Who may do what, one line for the start-up message.
    pub fn describe(&self) -> String {
        let hosts = match &self.hosts {
            None => "any Host".to_string(),
            Some(h) => {
                let all: Vec<&str> = LOOPBACK_HOSTS
                    .iter()
                    .copied()
                    .chain(h.iter().map(String::as_str))
                    .collect();
                format!("Host {}", all.join(", "))
            }
        };
        match &self.tokens {
            None => format!(
                "no token file: anyone who can reach the port may read, submit and cancel \
                 every job ({hosts})"
            ),
            Some(t) => {
                let open = |a: Access| match a {
                    Access::Open => "open",
                    Access::Read => "needs a read token",
                };
                format!(
                    "tokens ({}): reading needs a token, submitting a submit token, cancelling \
                     another's job an admin token; /healthz {}, /metrics {} ({hosts})",
                    t.describe(),
                    open(self.healthz),
                    open(self.metrics)
                )
            }
        }
    }

    /// The token named by `presented` (sign-in).
    pub fn sign_in(&self, presented: &str) -> Option<Caller> {
        let token = self.tokens.as_ref()?.find(presented)?;
        Some(Caller {
            name: Some(token.name.clone()),
            role: token.role,
            bearer: false,
        })
    }

    /// What a request needs, from its route's declared policy.
    fn need(&self, method: &Method, path: &str) -> Need {
        let who = self.policies.of(method, path).who;
        match policy::role_needed(who, self.healthz, self.metrics) {
            None => Need::Nothing,
            Some(role) => Need::Role(role),
        }
    }

    /// Whether a request's route is rate-limited, as declared.
    fn rate_limited(&self, method: &Method, path: &str) -> bool {
        self.policies.of(method, path).cost == Cost::RateLimited
    }

    /// The `Host` of a request, if this server answers to it.
    fn check_host(&self, request: &Request) -> Result<(), ApiError> {
        let Some(names) = &self.hosts else {
            return Ok(());
        };
        let host = request
            .uri()
            .authority()
            .map(|a| a.as_str())
            .or_else(|| request.headers().get(header::HOST)?.to_str().ok())
            .unwrap_or("");
        let name = host_name(host).to_ascii_lowercase();
        if LOOPBACK_HOSTS.contains(&name.as_str()) || names.contains(&name) {
            return Ok(());
        }
        let answers: Vec<&str> = LOOPBACK_HOSTS
            .iter()
            .copied()
            .chain(names.iter().map(String::as_str))
            .collect();
        Err(ApiError::UnknownHost {
            host: host.chars().take(200).collect(),
            answers: format!("{} (--allowed-host adds more)", answers.join(", ")),
        })
    }

    /// The caller named by the request's token: the `Authorization: Bearer` header, else the
    /// page's cookie. `Ok(None)`: no credentials (or a cookie no longer valid).
    fn identify(&self, headers: &HeaderMap) -> Result<Option<Caller>, ApiError> {
        let Some(tokens) = &self.tokens else {
            return Ok(Some(Caller {
                name: None,
                role: Role::Admin,
                bearer: false,
            }));
        };
        if let Some(value) = headers.get(header::AUTHORIZATION) {
            let presented = value
                .to_str()
                .ok()
                .and_then(|v| v.split_once(' '))
                .filter(|(scheme, _)| scheme.eq_ignore_ascii_case("bearer"))
                .map(|(_, token)| token.trim());
            return match presented.and_then(|t| tokens.find(t)) {
                Some(t) => Ok(Some(Caller {
                    name: Some(t.name.clone()),
                    role: t.role,
                    bearer: true,
                })),
                None => Err(ApiError::Unauthorized {
                    detail: "the Authorization header carries no token of this server \
                             (send `Authorization: Bearer TOKEN`)"
                        .into(),
                    invalid_token: true,
                }),
            };
        }
        Ok(cookie(headers, COOKIE)
            .and_then(|t| tokens.find(&t))
            .map(|t| Caller {
                name: Some(t.name.clone()),
                role: t.role,
                bearer: false,
            }))
    }
}

/// The host name of a `Host` value, without its port: `example.org:8080` → `example.org`,
/// `[::1]:80` → `[::1]`. An IPv6 literal is `[…]` followed by nothing or `:port`; a value
/// that is neither that nor `name[:port]` is kept whole, so that it names no host answered.
fn host_name(host: &str) -> &str {
    let (name, port) = if host.starts_with('[') {
        let Some(end) = host.find(']') else {
            return host;
        };
        let (name, rest) = host.split_at(end + 1);
        match rest.strip_prefix(':') {
            Some(port) => (name, port),
            None if rest.is_empty() => (name, ""),
            None => return host,
        }
    } else {
        host.rsplit_once(':').unwrap_or((host, ""))
    };
    if port.bytes().all(|b| b.is_ascii_digit()) {
        name
    } else {
        host
    }
}

/// The value of the cookie `name`, if the request has it.
fn cookie(headers: &HeaderMap, name: &str) -> Option<String> {
    headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(cookie::Cookie::split_parse)
        .filter_map(Result::ok)
        .find(|c| c.name() == name)
        .map(|c| c.value().to_string())
}

/// Why a request another site's page may have sent must not act: for every method but GET,
/// HEAD and OPTIONS, a `Sec-Fetch-Site` other than `same-origin` or `none` (a browser's own
/// word), or an `Origin` that is not the request's own.
fn cross_site(method: &Method, headers: &HeaderMap) -> Option<String> {
    if [Method::GET, Method::HEAD, Method::OPTIONS].contains(method) {
        return None;
    }
    let text = |name| headers.get(name).map(|v| v.to_str().unwrap_or("?"));
    if let Some(site) = text("sec-fetch-site") {
        if site != "same-origin" && site != "none" {
            return Some(format!(
                "a cross-site request (Sec-Fetch-Site: {}) may not act on this server",
                clip(site)
            ));
        }
    }
    if let Some(origin) = text(header::ORIGIN.as_str()) {
        let host = text(header::HOST.as_str()).unwrap_or("");
        let authority = origin.split_once("://").map(|(_, a)| a);
        if !authority.is_some_and(|a| a.eq_ignore_ascii_case(host)) {
            return Some(format!(
                "a request from the origin {} may not act on this server (host {})",
                clip(origin),
                clip(host)
            ));
        }
    }
    None
}

/// Whether a body is JSON by its content type; a plain HTML form cannot send one.
fn is_json(headers: &HeaderMap) -> bool {
    headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .map(|v| {
            v.split(';')
                .next()
                .unwrap_or("")
                .trim()
                .to_ascii_lowercase()
        })
        .is_some_and(|e| e == "application/json" || e.ends_with("+json"))
}

/// The middleware: host, cross-site, caller, role, JSON body, rate limit; then the route,
/// with the [`Caller`] in the request's extensions.
pub async fn check(
    axum::extract::State(guard): axum::extract::State<Arc<Guard>>,
    mut request: Request,
    next: Next,
) -> Result<Response, ApiError> {
    guard.check_host(&request)?;
    let method = request.method().clone();
    let path = request.uri().path().to_string();
    if let Some(why) = cross_site(&method, request.headers()) {
        return Err(ApiError::Forbidden { detail: why });
    }
    let peer = request
        .extensions()
        .get::<ConnectInfo<SocketAddr>>()
        .map(|c| c.0);
    let need = guard.need(&method, &path);
    let caller = match (guard.identify(request.headers()), need) {
        (Ok(caller), _) => caller,
        (Err(_), Need::Nothing) => None,
        (Err(e), Need::Role(_)) => {
            // Guessing tokens costs as much as submitting.
            guard.limiter.check(&rate::peer_key(peer))?;
            return Err(e);
        }
    };
    if let Need::Role(role) = need {
        match &caller {
            None => {
                return Err(ApiError::Unauthorized {
                    detail: format!(
                        "{method} {path} needs a token with the {} role: send \
                         `Authorization: Bearer TOKEN` (the web page asks for one)",
                        role.as_str()
                    ),
                    invalid_token: false,
                })
            }
            Some(c) if c.role < role => {
                return Err(ApiError::Forbidden {
                    detail: format!(
                        "{method} {path} needs the {} role; the token {} has the {} role",
                        role.as_str(),
                        c.name.as_deref().unwrap_or("?"),
                        c.role.as_str()
                    ),
                })
            }
            Some(_) => {}
        }
    }
    let bearer = caller.as_ref().is_some_and(|c| c.bearer);
    if method == Method::POST && !bearer && !is_json(request.headers()) {
        let sent = request.headers().get(header::CONTENT_TYPE);
        return Err(ApiError::UnsupportedMediaType(
            sent.map_or("(none)", |v| v.to_str().unwrap_or("?"))
                .to_string(),
        ));
    }
    if guard.rate_limited(&method, &path) {
        let key = match caller.as_ref().and_then(|c| c.name.as_deref()) {
            Some(name) => format!("the token {name}"),
            None => rate::peer_key(peer),
        };
        guard.limiter.check(&key)?;
    }
    if let Some(caller) = caller {
        request.extensions_mut().insert(caller);
    }
    Ok(next.run(request).await)
}

/// The content security policy of every answer: nothing but this server's own scripts,
/// styles, pictures and connections; no inline script, no framing, no `<base>`, no plugins.
pub const CSP: &str = "default-src 'self'; script-src 'self'; style-src 'self'; \
     img-src 'self'; connect-src 'self'; font-src 'self'; object-src 'none'; base-uri 'none'; \
     form-action 'self'; frame-ancestors 'none'";

/// Adds the security headers to every answer: the CSP, no MIME sniffing, no framing, no
/// referrer, and no use of our answers by other sites' pages (`<img>`, `<script>`).
pub async fn security_headers(mut response: Response) -> Response {
    let headers = response.headers_mut();
    for (name, value) in [
        ("content-security-policy", CSP),
        ("x-content-type-options", "nosniff"),
        ("x-frame-options", "DENY"),
        ("referrer-policy", "no-referrer"),
        ("cross-origin-resource-policy", "same-origin"),
    ] {
        headers.insert(name, HeaderValue::from_static(value));
    }
    response
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(pairs: &[(&'static str, &'static str)]) -> HeaderMap {
        let mut h = HeaderMap::new();
        for (k, v) in pairs {
            h.insert(*k, HeaderValue::from_static(v));
        }
        h
    }

    #[test]
    fn a_host_name_loses_its_port() {
        assert_eq!(host_name("example.org:8080"), "example.org");
        assert_eq!(host_name("example.org"), "example.org");
        assert_eq!(host_name("[::1]:80"), "[::1]");
        assert_eq!(host_name("[::1]"), "[::1]");
        assert_eq!(host_name("127.0.0.1:1"), "127.0.0.1");
        assert_eq!(host_name(""), "");
    }

    #[test]
    fn an_ipv6_literal_followed_by_anything_but_a_port_is_kept_whole() {
        for host in [
            "[::1]evil",
            "[::1]evil:80",
            "[::1]:80x",
            "[::1]:80:80",
            "[::1",
        ] {
            let name = host_name(host);
            assert!(!LOOPBACK_HOSTS.contains(&name), "{host} read as {name}");
        }
        assert_eq!(host_name("[::1]evil"), "[::1]evil");
        assert_eq!(host_name("example.org:80x"), "example.org:80x");
    }

    #[test]
    fn a_long_origin_or_sec_fetch_site_is_quoted_clipped() {
        let long = "a".repeat(50_000);
        for name in ["origin", "sec-fetch-site", "host"] {
            let mut h = headers(&[("origin", "http://evil.example")]);
            h.insert(name, HeaderValue::from_str(&long).unwrap());
            let why = cross_site(&Method::POST, &h).unwrap();
            assert!(why.len() < 400, "{name}: {} bytes", why.len());
        }
    }

    #[test]
    fn only_unsafe_requests_from_another_site_are_cross_site() {
        let post = Method::POST;
        let own = [
            ("host", "127.0.0.1:8080"),
            ("origin", "http://127.0.0.1:8080"),
        ];
        assert_eq!(cross_site(&post, &headers(&own)), None);
        assert_eq!(cross_site(&post, &headers(&[("host", "a")])), None);
        let same = [("host", "a"), ("sec-fetch-site", "same-origin")];
        assert_eq!(cross_site(&post, &headers(&same)), None);
        assert_eq!(
            cross_site(&post, &headers(&[("sec-fetch-site", "none")])),
            None
        );
        for refused in [
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "http://evil.example"),
            ][..],
            &[("host", "127.0.0.1:8080"), ("origin", "null")][..],
            &[("host", "a"), ("sec-fetch-site", "cross-site")][..],
            &[("host", "a"), ("sec-fetch-site", "same-site")][..],
        ] {
            assert!(
                cross_site(&post, &headers(refused)).is_some(),
                "{refused:?}"
            );
            assert_eq!(cross_site(&Method::GET, &headers(refused)), None);
        }
        let cross = [("host", "a"), ("sec-fetch-site", "cross-site")];
        assert!(cross_site(&Method::DELETE, &headers(&cross)).is_some());
    }

    #[test]
    fn a_caller_cancels_its_own_jobs_and_an_admin_any() {
        let submit = Caller {
            name: Some("ci".into()),
            role: Role::Submit,
            bearer: true,
        };
        assert!(submit.may_cancel(Some("ci")));
        assert!(!submit.may_cancel(Some("alice")));
        assert!(!submit.may_cancel(None));
        let read = Caller {
            role: Role::Read,
            ..submit.clone()
        };
        assert!(!read.may_cancel(Some("ci")));
        let admin = Caller {
            role: Role::Admin,
            ..submit
        };
        assert!(admin.may_cancel(Some("alice")) && admin.may_cancel(None));
    }

    #[test]
    fn the_page_and_session_are_open_and_everything_else_needs_a_role() {
        let args = AccessArgs {
            token_file: None,
            allow_anonymous_remote: false,
            allowed_hosts: vec![],
            healthz_access: Access::Open,
            metrics_access: Access::Read,
            rate_limit_per_s: NonZeroU32::new(1).unwrap(),
            rate_limit_burst: NonZeroU32::new(1).unwrap(),
        };
        let g = Guard::new(&args, crate::service::routes::policies()).unwrap();
        let get = Method::GET;
        assert_eq!(g.need(&get, "/"), Need::Nothing);
        assert_eq!(g.need(&get, "/assets/app.js"), Need::Nothing);
        assert_eq!(g.need(&Method::POST, "/v1/session"), Need::Nothing);
        assert_eq!(g.need(&get, "/healthz"), Need::Nothing);
        assert_eq!(g.need(&get, "/metrics"), Need::Role(Role::Read));
        assert_eq!(g.need(&get, "/v1/jobs"), Need::Role(Role::Read));
        assert_eq!(g.need(&get, "/nowhere"), Need::Role(Role::Read));
        assert_eq!(g.need(&Method::POST, "/v1/jobs"), Need::Role(Role::Submit));
        let cancel = "/v1/jobs/00000000-0000-4000-8000-000000000000/cancel";
        assert_eq!(g.need(&Method::POST, cancel), Need::Role(Role::Submit));
    }
}
