//! Each route's policy — who may call it and whether its calls are rate-limited — as the route
//! table declares it beside the route (`routes::table`), and the lookup the guard makes of a
//! request's method and path against those declarations. A path no route declares gets the
//! [`Policies::unknown`] policy: a role to read, so that an anonymous caller learns nothing of
//! which paths exist.
//!
//! Imports nothing of the routes: the table hands its declarations in.

use super::access::Access;
use super::tokens::Role;
use axum::http::Method;

/// Who may call a route.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Who {
    /// Anyone: the page, its assets, the session (signing in needs no token).
    Anyone,
    /// A token with at least this role.
    Role(Role),
    /// As `--healthz-access` says.
    HealthzFlag,
    /// As `--metrics-access` says.
    MetricsFlag,
}

/// What a call costs the server beyond answering it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cost {
    /// Reads, deletes, downloads (downloads are held to their own slots and pace).
    Light,
    /// Work per call (a case checked and estimated, a job or sweep stored, a token compared):
    /// rate-limited per client.
    RateLimited,
}

/// A route's policy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Policy {
    pub who: Who,
    pub cost: Cost,
}

/// One segment of a route's path: a literal, or a `{parameter}` that takes any one segment.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Segment {
    Literal(&'static str),
    Any,
}

/// The declared policies, looked up by method and path.
#[derive(Debug, Clone, Default)]
pub struct Policies {
    routes: Vec<(Method, Vec<Segment>, Policy)>,
}

impl Policies {
    /// From the route table's declarations: (method, path pattern with `{name}` segments,
    /// policy). HEAD takes GET's policy.
    pub fn new(declared: &[(&'static str, &'static str, Policy)]) -> Policies {
        Policies {
            routes: declared
                .iter()
                .map(|(method, path, policy)| {
                    let method = Method::from_bytes(method.as_bytes()).expect("a route's method");
                    let segments = path
                        .split('/')
                        .map(|s| match s.starts_with('{') && s.ends_with('}') {
                            true => Segment::Any,
                            false => Segment::Literal(s),
                        })
                        .collect();
                    (method, segments, *policy)
                })
                .collect(),
        }
    }

    /// The policy of a request: its route's, else [`Policies::unknown`].
    pub fn of(&self, method: &Method, path: &str) -> Policy {
        let method = match *method {
            Method::HEAD => &Method::GET,
            ref m => m,
        };
        let parts: Vec<&str> = path.split('/').collect();
        self.routes
            .iter()
            .find(|(m, segments, _)| {
                m == method
                    && segments.len() == parts.len()
                    && segments.iter().zip(&parts).all(|(s, p)| match s {
                        Segment::Literal(l) => l == p,
                        Segment::Any => !p.is_empty(),
                    })
            })
            .map_or_else(|| Policies::unknown(method), |(_, _, p)| *p)
    }

    /// The policy of a path no route declares (answered 404 or 405 once past the guard): a
    /// reader's role for GET and HEAD, a submitter's for the rest, as the routes' own.
    pub fn unknown(method: &Method) -> Policy {
        Policy {
            who: match *method {
                Method::GET | Method::HEAD => Who::Role(Role::Read),
                _ => Who::Role(Role::Submit),
            },
            cost: Cost::Light,
        }
    }
}

/// The role `who` needs on a server whose flags give `healthz` and `metrics`; `None`: none.
pub fn role_needed(who: Who, healthz: Access, metrics: Access) -> Option<Role> {
    let flag = |a: Access| match a {
        Access::Open => None,
        Access::Read => Some(Role::Read),
    };
    match who {
        Who::Anyone => None,
        Who::Role(r) => Some(r),
        Who::HealthzFlag => flag(healthz),
        Who::MetricsFlag => flag(metrics),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const READ: Policy = Policy {
        who: Who::Role(Role::Read),
        cost: Cost::Light,
    };
    const SUBMIT: Policy = Policy {
        who: Who::Role(Role::Submit),
        cost: Cost::RateLimited,
    };

    #[test]
    fn a_request_gets_the_policy_of_the_route_it_matches_and_an_unknown_path_a_role() {
        let p = Policies::new(&[
            ("GET", "/v1/jobs/{id}", READ),
            ("POST", "/v1/jobs", SUBMIT),
            (
                "POST",
                "/v1/jobs/{id}/cancel",
                Policy {
                    cost: Cost::Light,
                    ..SUBMIT
                },
            ),
        ]);
        assert_eq!(p.of(&Method::GET, "/v1/jobs/abc"), READ);
        assert_eq!(p.of(&Method::HEAD, "/v1/jobs/abc"), READ);
        assert_eq!(p.of(&Method::POST, "/v1/jobs"), SUBMIT);
        assert_eq!(p.of(&Method::POST, "/v1/jobs/x/cancel").cost, Cost::Light);
        // A parameter takes one whole segment, never none or two.
        assert_eq!(
            p.of(&Method::GET, "/v1/jobs/"),
            Policies::unknown(&Method::GET)
        );
        assert_eq!(
            p.of(&Method::GET, "/v1/jobs/a/b"),
            Policies::unknown(&Method::GET)
        );
        // The method is part of the route.
        assert_eq!(
            p.of(&Method::DELETE, "/v1/jobs"),
            Policies::unknown(&Method::DELETE)
        );
        assert_eq!(
            Policies::unknown(&Method::DELETE).who,
            Who::Role(Role::Submit)
        );
    }

    #[test]
    fn the_flags_set_who_reads_health_and_metrics() {
        assert_eq!(
            role_needed(Who::HealthzFlag, Access::Open, Access::Read),
            None
        );
        assert_eq!(
            role_needed(Who::MetricsFlag, Access::Open, Access::Read),
            Some(Role::Read)
        );
        assert_eq!(role_needed(Who::Anyone, Access::Read, Access::Read), None);
    }
}
