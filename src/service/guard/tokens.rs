//! API tokens: the token file (`--token-file`), the role each token grants, and the lookup of
//! a presented token, which takes the same time whichever token (if any) it matches.
//!
//! The file holds one token a line, `name role token`, `#` starting a comment line:
//!
//! ```text
//! # name   role    token
//! alice    admin   3q2+7w-Ue1xXkP0JmN8rT4sZ
//! ci       submit  0f5b8c1e9a7d4b2f6e3c0a8d
//! grafana  read    kq1ZrD7uYp2mXc9vB4nT8wLs
//! ```

use schemars::JsonSchema;
use sha2::{Digest, Sha256};
use subtle::ConstantTimeEq;

/// Shortest token accepted: 20 characters of the token alphabet carry at least 120 bits when
/// drawn at random (`openssl rand -base64 24`, `openssl rand -hex 16`).
pub const MIN_TOKEN_CHARS: usize = 20;

/// Longest token or name accepted.
const MAX_CHARS: usize = 256;

/// What a token may do; each role may do everything the ones before it may.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = crate::solver::model::schema::choices)]
pub enum Role {
    /// Every GET: jobs, results, event streams, sweeps, metrics.
    Read,
    /// Also submit jobs and sweeps, ask for estimates and plans, and cancel the jobs it submitted.
    Submit,
    /// Also cancel any job.
    Admin,
}

impl Role {
    pub fn as_str(self) -> &'static str {
        match self {
            Role::Read => "read",
            Role::Submit => "submit",
            Role::Admin => "admin",
        }
    }

    fn parse(s: &str) -> Option<Role> {
        [Role::Read, Role::Submit, Role::Admin]
            .into_iter()
            .find(|r| r.as_str() == s)
    }
}

/// One token of the file: its name (stored as the owner of the jobs it submits), its role and
/// the SHA-256 of its text (compared in constant time).
#[derive(Clone)]
pub struct Token {
    pub name: String,
    pub role: Role,
    digest: [u8; 32],
}

impl std::fmt::Debug for Token {
    /// Never prints the digest.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Token({} {})", self.name, self.role.as_str())
    }
}

/// The tokens of a token file.
#[derive(Debug, Clone)]
pub struct Tokens(Vec<Token>);

fn digest(text: &str) -> [u8; 32] {
    Sha256::digest(text.as_bytes()).into()
}

/// Characters a token may hold: those of hex, base64 and base64url, all safe in a header and
/// a cookie.
fn token_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || "-._~+/=".contains(c)
}

fn name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || "-._@".contains(c)
}

impl Tokens {
    /// Reads a token file; the error names the file and the line.
    pub fn load(path: &std::path::Path) -> anyhow::Result<Tokens> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow::anyhow!("reading the token file {}: {e}", path.display()))?;
        Tokens::parse(&text).map_err(|e| anyhow::anyhow!("token file {}: {e}", path.display()))
    }

    /// Parses the text of a token file: every line `name role token`, or blank, or a `#`
    /// comment. A bad line, an unknown role, a short token, or a name or token used twice is
    /// an error naming the line (never the token).
    pub fn parse(text: &str) -> Result<Tokens, String> {
        let mut tokens: Vec<Token> = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let n = i + 1;
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let fields: Vec<&str> = line.split_whitespace().collect();
            let [name, role, token] = fields[..] else {
                return Err(format!(
                    "line {n}: expected `name role token`, found {} field{}",
                    fields.len(),
                    if fields.len() == 1 { "" } else { "s" }
                ));
            };
            if name.len() > MAX_CHARS || !name.chars().all(name_char) {
                return Err(format!(
                    "line {n}: the name may hold only letters, digits and - . _ @ \
                     (at most {MAX_CHARS})"
                ));
            }
            let role = Role::parse(role).ok_or_else(|| {
                format!("line {n}: the role {role:?} is not one of read, submit, admin")
            })?;
            if token.len() > MAX_CHARS || !token.chars().all(token_char) {
                return Err(format!(
                    "line {n}: the token may hold only letters, digits and - . _ ~ + / = \
                     (at most {MAX_CHARS})"
                ));
            }
            if token.len() < MIN_TOKEN_CHARS {
                return Err(format!(
                    "line {n}: the token of {name} is shorter than {MIN_TOKEN_CHARS} characters"
                ));
            }
            let digest = digest(token);
            if let Some(other) = tokens.iter().find(|t| t.name == name) {
                return Err(format!("line {n}: the name {} is used twice", other.name));
            }
            if let Some(other) = tokens.iter().find(|t| t.digest == digest) {
                return Err(format!(
                    "line {n}: the token of {name} is also the token of {}",
                    other.name
                ));
            }
            tokens.push(Token {
                name: name.to_string(),
                role,
                digest,
            });
        }
        if tokens.is_empty() {
            return Err("no tokens (every line is blank or a comment)".into());
        }
        Ok(Tokens(tokens))
    }

    /// The token whose text is `presented`. Compares digests, in constant time, with every
    /// token: how long it takes says nothing about how much of a token was right.
    pub fn find(&self, presented: &str) -> Option<&Token> {
        let wanted = digest(presented);
        let mut found = None;
        for token in &self.0 {
            if bool::from(token.digest.ct_eq(&wanted)) {
                found = Some(token);
            }
        }
        found
    }

    /// How many tokens of each role, for the start-up line: "2 admin, 1 read".
    pub fn describe(&self) -> String {
        [Role::Admin, Role::Submit, Role::Read]
            .iter()
            .map(|r| (r, self.0.iter().filter(|t| t.role == *r).count()))
            .filter(|(_, n)| *n > 0)
            .map(|(r, n)| format!("{n} {}", r.as_str()))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: &str = "aaaaaaaaaaaaaaaaaaaaaaaa";
    const B: &str = "bbbbbbbbbbbbbbbbbbbbbbbb";

    #[test]
    fn a_token_file_gives_each_token_its_name_and_role() {
        let text = format!("# a comment\n\nalice admin {A}\n  ci   submit   {B}  \n");
        let tokens = Tokens::parse(&text).unwrap();
        let alice = tokens.find(A).unwrap();
        assert_eq!((alice.name.as_str(), alice.role), ("alice", Role::Admin));
        assert_eq!(tokens.find(B).unwrap().role, Role::Submit);
        assert!(tokens.find("cccccccccccccccccccccccc").is_none());
        assert!(tokens.find(&A[1..]).is_none());
        assert_eq!(tokens.describe(), "1 admin, 1 submit");
        assert!(!format!("{tokens:?}").contains(A));
    }

    #[test]
    fn a_bad_token_file_is_refused_with_the_line_named_and_no_token_shown() {
        let cases = [
            (
                format!("alice admin {A}\nbob writer {B}"),
                "line 2: the role \"writer\"",
            ),
            (
                format!("alice admin {A} extra"),
                "line 1: expected `name role token`, found 4",
            ),
            (
                "alice admin".to_string(),
                "line 1: expected `name role token`, found 2",
            ),
            (
                "alice read short-token".to_string(),
                "line 1: the token of alice is shorter",
            ),
            (
                format!("alice read {A}\nbob admin {A}"),
                "line 2: the token of bob is also",
            ),
            (
                format!("alice read {A}\nalice admin {B}"),
                "line 2: the name alice is used twice",
            ),
            (format!("al;ce read {A}"), "line 1: the name may hold only"),
            (
                "alice read aaaaaaaaaaaaaaaaaaaa;aaaa".to_string(),
                "line 1: the token may hold only",
            ),
            ("# only a comment\n\n".to_string(), "no tokens"),
        ];
        for (text, wanted) in cases {
            let error = Tokens::parse(&text).unwrap_err();
            assert!(error.starts_with(wanted), "{text:?}: {error}");
            assert!(!error.contains(A) && !error.contains(B), "{error}");
        }
    }

    #[test]
    fn roles_are_ordered_read_submit_admin() {
        assert!(Role::Read < Role::Submit && Role::Submit < Role::Admin);
    }
}
