//! Who may open the live view: the `Origin` allow-list and the token, checked on the
//! head of each WebSocket upgrade (`gate` does the I/O; this is the pure decision).
//!
//! A browser sends the page's origin with every WebSocket upgrade and lets any page open
//! one to any address, loopback included: without this check any web page the user opens
//! could read the fleet's positions and maps from `ws://127.0.0.1:8765`. A client that
//! sends no `Origin` is not a browser page (the Foxglove desktop app, Python or Rust
//! clients) and is let through the Origin check; the token, when one is configured, is
//! then what keeps strangers on the network out.

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::head::{HeadError, RequestHead};
use crate::wire::shown;

/// The Foxglove web app's origin, allowed by default.
pub const FOXGLOVE_APP_ORIGIN: &str = "https://app.foxglove.dev";
/// The subprotocol the Foxglove SDK's server speaks (the Foxglove WebSocket protocol v1).
pub const SDK_SUBPROTOCOL: &str = "foxglove.sdk.v1";
/// The SDK's other subprotocol (v1 with schema tables); a client offering it needs no help.
const SDK_SUBPROTOCOL_1_1: &str = "foxglove.sdk.v1.1";
/// The protocol's older name, which clients of `@foxglove/ws-protocol` and Lichtblick
/// offer alone: the same messages (see `gate`), so the gate translates the name.
pub const LEGACY_SUBPROTOCOL: &str = "foxglove.websocket.v1";
/// Token lengths accepted: long enough not to be guessed over a network.
pub const MIN_TOKEN_LEN: usize = 16;
pub const MAX_TOKEN_LEN: usize = 256;
/// The longest origin accepted in the allow-list.
const MAX_ORIGIN_LEN: usize = 256;

/// Why the view's access settings are refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AccessError {
    #[error("'{0}' is not an origin: give scheme://host[:port], e.g. {FOXGLOVE_APP_ORIGIN}, without a path")]
    Origin(String),
    #[error("the token must be {MIN_TOKEN_LEN} to {MAX_TOKEN_LEN} characters from A-Z, a-z, 0-9, '-', '.', '_' and '~' (e.g. `openssl rand -hex 32`); the one given has {len} characters{extra}")]
    Token { len: usize, extra: &'static str },
    #[error("cannot read the token file {path}: {reason}")]
    TokenFile { path: PathBuf, reason: String },
}

/// The shared secret a client must present. Its `Debug` never shows it.
#[derive(Clone, PartialEq, Eq)]
pub struct Token(String);

impl std::fmt::Debug for Token {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Token(<{} characters>)", self.0.len())
    }
}

impl Token {
    /// A token from text (surrounding whitespace, as a file's last newline, is dropped).
    /// Only URL-unreserved characters, so it travels unchanged in a `?token=` query.
    pub fn new(text: &str) -> Result<Token, AccessError> {
        let token = text.trim();
        let len = token.chars().count();
        if !(MIN_TOKEN_LEN..=MAX_TOKEN_LEN).contains(&len) {
            return Err(AccessError::Token { len, extra: "" });
        }
        if !token
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-._~".contains(&b))
        {
            return Err(AccessError::Token {
                len,
                extra: " and others",
            });
        }
        Ok(Token(token.to_owned()))
    }

    /// The token in the file at `path` (read up to a few KiB: a token file is one line).
    pub fn from_file(path: &Path) -> Result<Token, AccessError> {
        let error = |reason: String| AccessError::TokenFile {
            path: path.to_owned(),
            reason,
        };
        let file = std::fs::File::open(path).map_err(|e| error(e.to_string()))?;
        let mut text = String::new();
        file.take(4 * 1024)
            .read_to_string(&mut text)
            .map_err(|e| error(e.to_string()))?;
        Token::new(&text)
    }

    /// Whether `presented` is this token, in time that does not depend on where the two
    /// differ (only on the length of the token), so the token cannot be guessed byte by
    /// byte from how fast a refusal comes.
    pub fn matches(&self, presented: &str) -> bool {
        let (a, b) = (self.0.as_bytes(), presented.as_bytes());
        let mut diff = u8::from(a.len() != b.len());
        for (i, x) in a.iter().enumerate() {
            diff |= x ^ b.get(i).copied().unwrap_or(!x);
        }
        std::hint::black_box(diff) == 0
    }
}

/// Who may connect: origins a browser page may come from, and the token, if any.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Access {
    origins: Vec<String>,
    token: Option<Token>,
}

impl Default for Access {
    /// The Foxglove web app and clients without an `Origin`; no token.
    fn default() -> Self {
        Access {
            origins: vec![FOXGLOVE_APP_ORIGIN.to_owned()],
            token: None,
        }
    }
}

/// The HTTP status of a refused upgrade.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    BadRequest,
    Unauthorized,
    Forbidden,
    MethodNotAllowed,
    RequestTimeout,
    HeadTooLarge,
    BadGateway,
    Unavailable,
}

impl Status {
    pub fn code(self) -> u16 {
        match self {
            Status::BadRequest => 400,
            Status::Unauthorized => 401,
            Status::Forbidden => 403,
            Status::MethodNotAllowed => 405,
            Status::RequestTimeout => 408,
            Status::HeadTooLarge => 431,
            Status::BadGateway => 502,
            Status::Unavailable => 503,
        }
    }

    pub fn reason(self) -> &'static str {
        match self {
            Status::BadRequest => "Bad Request",
            Status::Unauthorized => "Unauthorized",
            Status::Forbidden => "Forbidden",
            Status::MethodNotAllowed => "Method Not Allowed",
            Status::RequestTimeout => "Request Timeout",
            Status::HeadTooLarge => "Request Header Fields Too Large",
            Status::BadGateway => "Bad Gateway",
            Status::Unavailable => "Service Unavailable",
        }
    }
}

/// A refused upgrade: its status and why (escaped and bounded: it is logged).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refusal {
    pub status: Status,
    pub why: String,
}

impl Refusal {
    fn new(status: Status, why: impl Into<String>) -> Refusal {
        Refusal {
            status,
            why: why.into(),
        }
    }
}

impl From<HeadError> for Refusal {
    fn from(e: HeadError) -> Refusal {
        let status = match e {
            HeadError::TooLarge | HeadError::TooManyHeaders => Status::HeadTooLarge,
            HeadError::Malformed(_) | HeadError::Repeated(_) => Status::BadRequest,
        };
        Refusal::new(status, e.to_string())
    }
}

/// An admitted upgrade, and whether its subprotocol needs translating.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Admitted {
    /// The client offered only [`LEGACY_SUBPROTOCOL`].
    pub legacy_subprotocol: bool,
}

/// An origin as browsers send it: lower case, no trailing `/`.
fn normalized_origin(origin: &str) -> Result<String, AccessError> {
    let lower = origin.trim().trim_end_matches('/').to_ascii_lowercase();
    let refused = || AccessError::Origin(shown(origin));
    let rest = lower
        .strip_prefix("https://")
        .or_else(|| lower.strip_prefix("http://"))
        .ok_or_else(refused)?;
    let valid = !rest.is_empty()
        && lower.len() <= MAX_ORIGIN_LEN
        && rest
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-.:[]".contains(&b));
    if valid {
        Ok(lower)
    } else {
        Err(refused())
    }
}

impl Access {
    /// Browser pages from `origins` (`scheme://host[:port]`; none means only clients that
    /// send no `Origin`), and clients that present `token` when one is given.
    pub fn new(
        origins: impl IntoIterator<Item = impl AsRef<str>>,
        token: Option<Token>,
    ) -> Result<Access, AccessError> {
        let mut list = Vec::new();
        for origin in origins {
            let origin = normalized_origin(origin.as_ref())?;
            if !list.contains(&origin) {
                list.push(origin);
            }
        }
        Ok(Access {
            origins: list,
            token,
        })
    }

    /// The allowed origins, normalized.
    pub fn origins(&self) -> &[String] {
        &self.origins
    }

    /// Whether a client must present a token.
    pub fn needs_token(&self) -> bool {
        self.token.is_some()
    }

    /// Decides on an upgrade's head: 405 for anything but `GET`, 403 for a browser page
    /// from an origin not on the list, 401 for a missing or wrong token.
    pub fn check(&self, head: &RequestHead) -> Result<Admitted, Refusal> {
        if head.method != "GET" {
            return Err(Refusal::new(
                Status::MethodNotAllowed,
                format!("method {}", shown(&head.method)),
            ));
        }
        if let Some(origin) = head.headers.single("origin")? {
            let allowed = self.origins.iter().any(|o| o.eq_ignore_ascii_case(origin));
            if !allowed {
                return Err(Refusal::new(
                    Status::Forbidden,
                    format!("Origin \"{}\" is not allowed", shown(origin)),
                ));
            }
        }
        if let Some(token) = &self.token {
            self.check_token(token, head)?;
        }
        Ok(Admitted {
            legacy_subprotocol: offers_only_legacy(head),
        })
    }

    /// The token from `Authorization: Bearer …` when that header is there, else from the
    /// target's `token=` query parameter (browsers cannot set headers on a WebSocket).
    fn check_token(&self, token: &Token, head: &RequestHead) -> Result<(), Refusal> {
        let presented = match head.headers.single("authorization")? {
            Some(value) => {
                let (scheme, rest) = value.split_once(' ').unwrap_or((value, ""));
                if !scheme.eq_ignore_ascii_case("bearer") {
                    return Err(Refusal::new(
                        Status::Unauthorized,
                        "Authorization is not 'Bearer <token>'",
                    ));
                }
                Some(rest.trim_start_matches(' '))
            }
            None => {
                let mut found = head
                    .query()
                    .into_iter()
                    .flat_map(|q| q.split('&'))
                    .filter_map(|pair| pair.strip_prefix("token="));
                let first = found.next();
                if found.next().is_some() {
                    return Err(Refusal::new(
                        Status::BadRequest,
                        "more than one token= given",
                    ));
                }
                first
            }
        };
        match presented {
            Some(presented) if token.matches(presented) => Ok(()),
            Some(_) => Err(Refusal::new(Status::Unauthorized, "wrong token")),
            None => Err(Refusal::new(Status::Unauthorized, "no token")),
        }
    }
}

/// Whether the client offers [`LEGACY_SUBPROTOCOL`] and none the SDK's server speaks.
fn offers_only_legacy(head: &RequestHead) -> bool {
    let mut legacy = false;
    for offered in head
        .headers
        .all("sec-websocket-protocol")
        .flat_map(|v| v.split(','))
        .map(str::trim)
    {
        match offered {
            SDK_SUBPROTOCOL | SDK_SUBPROTOCOL_1_1 => return false,
            LEGACY_SUBPROTOCOL => legacy = true,
            _ => {}
        }
    }
    legacy
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOKEN: &str = "0123456789abcdef-token";

    fn head(target: &str, fields: &[(&str, &str)]) -> RequestHead {
        let mut text = format!("GET {target} HTTP/1.1\r\nHost: 127.0.0.1:8765\r\n");
        for (name, value) in fields {
            text.push_str(&format!("{name}: {value}\r\n"));
        }
        text.push_str("\r\n");
        RequestHead::parse(text.as_bytes()).expect("a valid head")
    }

    fn status(result: Result<Admitted, Refusal>) -> Option<u16> {
        result.err().map(|r| r.status.code())
    }

    #[test]
    fn by_default_the_foxglove_app_and_clients_without_an_origin_connect() {
        let access = Access::default();
        assert_eq!(access.origins(), [FOXGLOVE_APP_ORIGIN]);
        assert_eq!(status(access.check(&head("/", &[]))), None, "no Origin");
        let app = head("/", &[("Origin", "https://app.foxglove.dev")]);
        assert_eq!(status(access.check(&app)), None);
        let upper = head("/", &[("Origin", "HTTPS://APP.FOXGLOVE.DEV")]);
        assert_eq!(status(access.check(&upper)), None);
    }

    #[test]
    fn a_foreign_origin_is_forbidden_and_its_line_is_escaped() {
        let access = Access::default();
        for origin in [
            "https://evil.example",
            "null",
            "http://app.foxglove.dev",
            "https://app.foxglove.dev.evil.example",
        ] {
            let refused = access
                .check(&head("/", &[("Origin", origin)]))
                .expect_err(origin);
            assert_eq!(refused.status, Status::Forbidden, "{origin}");
        }
        let long = format!("https://{}.example", "a".repeat(5000));
        let refused = access
            .check(&head("/", &[("Origin", &long)]))
            .expect_err("long");
        assert!(refused.why.len() < 200, "{}", refused.why);
        assert!(refused.why.contains("bytes)"), "{}", refused.why);
        let two = head(
            "/",
            &[("Origin", FOXGLOVE_APP_ORIGIN), ("origin", "https://x")],
        );
        assert_eq!(status(access.check(&two)), Some(400), "two Origins");
        let post = RequestHead::parse(b"POST / HTTP/1.1\r\n\r\n").expect("head");
        assert_eq!(status(access.check(&post)), Some(405));
    }

    #[test]
    fn the_allow_list_replaces_the_default_and_is_checked() {
        let access = Access::new(
            ["http://localhost:8080/", "https://Lichtblick.example"],
            None,
        )
        .expect("origins");
        assert_eq!(
            access.origins(),
            ["http://localhost:8080", "https://lichtblick.example"]
        );
        let local = head("/", &[("Origin", "http://localhost:8080")]);
        assert_eq!(status(access.check(&local)), None);
        let app = head("/", &[("Origin", FOXGLOVE_APP_ORIGIN)]);
        assert_eq!(status(access.check(&app)), Some(403));
        let none = Access::new(Vec::<String>::new(), None).expect("empty");
        assert_eq!(status(none.check(&head("/", &[]))), None);
        assert_eq!(status(none.check(&app)), Some(403));
        for bad in [
            "app.foxglove.dev",
            "https://",
            "https://a/b",
            "ftp://x",
            "https://a b",
        ] {
            assert!(Access::new([bad], None).is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn a_token_is_required_from_the_query_or_a_bearer_header() {
        let access = Access::new(
            [FOXGLOVE_APP_ORIGIN],
            Some(Token::new(TOKEN).expect("token")),
        )
        .expect("");
        assert!(access.needs_token());
        let right_query = head(&format!("/?token={TOKEN}"), &[]);
        assert_eq!(status(access.check(&right_query)), None);
        let among = head(&format!("/?x=1&token={TOKEN}&y"), &[]);
        assert_eq!(status(access.check(&among)), None);
        let bearer = head("/", &[("Authorization", &format!("Bearer {TOKEN}"))]);
        assert_eq!(status(access.check(&bearer)), None);
        let lower = head("/", &[("authorization", &format!("bearer {TOKEN}"))]);
        assert_eq!(status(access.check(&lower)), None);

        assert_eq!(status(access.check(&head("/", &[]))), Some(401), "missing");
        let wrong = head("/?token=0123456789abcdef-tokeN", &[]);
        assert_eq!(status(access.check(&wrong)), Some(401), "wrong");
        let prefix = head(&format!("/?token={}", &TOKEN[..TOKEN.len() - 1]), &[]);
        assert_eq!(status(access.check(&prefix)), Some(401), "a prefix");
        let longer = head(&format!("/?token={TOKEN}x"), &[]);
        assert_eq!(status(access.check(&longer)), Some(401), "longer");
        let basic = head("/", &[("Authorization", &format!("Basic {TOKEN}"))]);
        assert_eq!(status(access.check(&basic)), Some(401), "not bearer");
        // The header, when given, is the credential: a right query does not save it.
        let both = head(
            &format!("/?token={TOKEN}"),
            &[("Authorization", "Bearer wrong-wrong-wrong")],
        );
        assert_eq!(status(access.check(&both)), Some(401));
        let twice = head(&format!("/?token={TOKEN}&token={TOKEN}"), &[]);
        assert_eq!(status(access.check(&twice)), Some(400));
        // The Origin is checked first: a right token from a foreign page is still refused.
        let foreign = head(
            &format!("/?token={TOKEN}"),
            &[("Origin", "https://evil.example")],
        );
        assert_eq!(status(access.check(&foreign)), Some(403));
    }

    #[test]
    fn tokens_are_checked_and_never_shown() {
        assert!(Token::new("short").is_err());
        assert!(Token::new(&"a".repeat(MAX_TOKEN_LEN + 1)).is_err());
        assert!(
            Token::new("0123456789abcdef&x=1").is_err(),
            "a query separator"
        );
        assert!(Token::new("0123456789 abcdef").is_err(), "a space");
        let token = Token::new(&format!("  {TOKEN}\n")).expect("trimmed");
        assert!(token.matches(TOKEN));
        assert!(!token.matches(""));
        assert!(!format!("{token:?}").contains(TOKEN));
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("token");
        std::fs::write(&path, format!("{TOKEN}\n")).expect("write");
        assert_eq!(Token::from_file(&path), Ok(token));
        assert!(matches!(
            Token::from_file(&dir.path().join("missing")),
            Err(AccessError::TokenFile { .. })
        ));
    }

    #[test]
    fn only_a_client_offering_just_the_legacy_name_is_translated() {
        let access = Access::default();
        let legacy = |offer: &str| {
            access
                .check(&head("/", &[("Sec-WebSocket-Protocol", offer)]))
                .expect("admitted")
                .legacy_subprotocol
        };
        assert!(legacy("foxglove.websocket.v1"));
        assert!(legacy("other, foxglove.websocket.v1"));
        assert!(!legacy("foxglove.sdk.v1"));
        assert!(!legacy("foxglove.websocket.v1, foxglove.sdk.v1"));
        assert!(!legacy("foxglove.websocket.v1, foxglove.sdk.v1.1"));
        assert!(!legacy("foxglove.websocket.v2"));
        assert!(
            !access
                .check(&head("/", &[]))
                .expect("ok")
                .legacy_subprotocol
        );
    }
}
