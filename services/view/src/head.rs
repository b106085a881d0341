//! The head of an HTTP/1.1 message (a WebSocket upgrade and its answer), parsed strictly.
//!
//! The gate decides who may connect from the request head alone, so the head is parsed
//! with no leniency a smuggled header could hide in: CRLF line ends only, no folded lines,
//! token header names, visible-ASCII values, a bounded size and header count. Whatever is
//! not plainly valid is refused rather than guessed at. The head is written back out from
//! the parsed fields, so what the SDK's server reads is exactly what was checked.

/// The largest head read (request line and headers, with the blank line).
pub const MAX_HEAD_BYTES: usize = 8 * 1024;
/// The most header fields in one head.
pub const MAX_HEADERS: usize = 64;

/// Why a head is not a valid HTTP/1.1 head.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum HeadError {
    #[error("the head is larger than {MAX_HEAD_BYTES} bytes")]
    TooLarge,
    #[error("more than {MAX_HEADERS} header fields")]
    TooManyHeaders,
    #[error("not an HTTP/1.1 head: {0}")]
    Malformed(&'static str),
    #[error("the header '{0}' is given more than once")]
    Repeated(String),
}

/// Where a head ends: the length up to and including its blank line, once `buf` holds it.
pub fn head_end(buf: &[u8]) -> Option<usize> {
    buf.windows(4).position(|w| w == b"\r\n\r\n").map(|i| i + 4)
}

/// Header fields in the order given, names as written.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Headers(Vec<(String, String)>);

impl Headers {
    /// Every value of the field `name` (case-insensitive).
    pub fn all<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a str> + 'a {
        self.0
            .iter()
            .filter(move |(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }

    /// The field `name`'s one value; a field given twice is refused, since two readers
    /// could pick different ones.
    pub fn single(&self, name: &str) -> Result<Option<&str>, HeadError> {
        let mut values = self
            .0
            .iter()
            .filter(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str());
        let first = values.next();
        if values.next().is_some() {
            return Err(HeadError::Repeated(name.to_owned()));
        }
        Ok(first)
    }

    /// Replaces every field `name` with one holding `value`, where the first one was.
    pub fn set(&mut self, name: &str, value: &str) {
        let at = self
            .0
            .iter()
            .position(|(n, _)| n.eq_ignore_ascii_case(name));
        self.0.retain(|(n, _)| !n.eq_ignore_ascii_case(name));
        let field = (name.to_owned(), value.to_owned());
        match at {
            Some(i) => self.0.insert(i, field),
            None => self.0.push(field),
        }
    }

    fn write(&self, out: &mut Vec<u8>) {
        for (name, value) in &self.0 {
            out.extend_from_slice(name.as_bytes());
            out.extend_from_slice(b": ");
            out.extend_from_slice(value.as_bytes());
            out.extend_from_slice(b"\r\n");
        }
        out.extend_from_slice(b"\r\n");
    }
}

/// A request head: `METHOD /target HTTP/1.1` and its fields.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RequestHead {
    pub method: String,
    /// The origin-form target: a path and maybe `?query`.
    pub target: String,
    pub headers: Headers,
}

impl RequestHead {
    /// Parses a head (`bytes` ends with its blank line, as [`head_end`] finds it).
    pub fn parse(bytes: &[u8]) -> Result<RequestHead, HeadError> {
        let (start, headers) = lines(bytes)?;
        let mut parts = start.split(' ');
        let (Some(method), Some(target), Some(version), None) =
            (parts.next(), parts.next(), parts.next(), parts.next())
        else {
            return Err(HeadError::Malformed(
                "the request line is not 'METHOD TARGET HTTP/1.1'",
            ));
        };
        if method.is_empty() || !method.bytes().all(is_tchar) {
            return Err(HeadError::Malformed("the method is not a token"));
        }
        if !target.starts_with('/') || !target.bytes().all(|b| b.is_ascii_graphic()) {
            return Err(HeadError::Malformed("the target is not a path"));
        }
        if version != "HTTP/1.1" {
            return Err(HeadError::Malformed("the version is not HTTP/1.1"));
        }
        Ok(RequestHead {
            method: method.to_owned(),
            target: target.to_owned(),
            headers,
        })
    }

    /// The query part of the target (after `?`), if any.
    pub fn query(&self) -> Option<&str> {
        self.target.split_once('?').map(|(_, q)| q)
    }

    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(256);
        out.extend_from_slice(self.method.as_bytes());
        out.push(b' ');
        out.extend_from_slice(self.target.as_bytes());
        out.extend_from_slice(b" HTTP/1.1\r\n");
        self.headers.write(&mut out);
        out
    }
}

/// A response head: `HTTP/1.1 CODE reason` and its fields.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ResponseHead {
    pub status: u16,
    pub reason: String,
    pub headers: Headers,
}

impl ResponseHead {
    pub fn parse(bytes: &[u8]) -> Result<ResponseHead, HeadError> {
        let (start, headers) = lines(bytes)?;
        let mut parts = start.splitn(3, ' ');
        let (Some("HTTP/1.1"), Some(code), reason) = (parts.next(), parts.next(), parts.next())
        else {
            return Err(HeadError::Malformed(
                "the status line is not 'HTTP/1.1 CODE REASON'",
            ));
        };
        let status = match code.parse::<u16>() {
            Ok(status) if code.len() == 3 => status,
            _ => return Err(HeadError::Malformed("the status is not a 3-digit code")),
        };
        Ok(ResponseHead {
            status,
            reason: reason.unwrap_or_default().to_owned(),
            headers,
        })
    }

    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = format!("HTTP/1.1 {:03} {}\r\n", self.status, self.reason).into_bytes();
        self.headers.write(&mut out);
        out
    }
}

/// The token characters of RFC 9110 (header names, methods).
fn is_tchar(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&b)
}

/// Splits a head into its start line and its header fields.
fn lines(bytes: &[u8]) -> Result<(&str, Headers), HeadError> {
    if bytes.len() > MAX_HEAD_BYTES {
        return Err(HeadError::TooLarge);
    }
    let Some(body) = bytes.strip_suffix(b"\r\n\r\n") else {
        return Err(HeadError::Malformed(
            "the head does not end with a blank line",
        ));
    };
    // Only visible ASCII, spaces and tabs between the CRLFs: no bare CR or LF, no NUL, no
    // bytes a lenient reader might take for something else.
    let text = std::str::from_utf8(body).map_err(|_| HeadError::Malformed("not ASCII"))?;
    let mut lines = text.split("\r\n");
    let start = lines.next().unwrap_or_default();
    let mut headers = Vec::new();
    for line in lines {
        if line.is_empty() {
            return Err(HeadError::Malformed("a blank line inside the head"));
        }
        if !line
            .bytes()
            .all(|b| b.is_ascii_graphic() || b == b' ' || b == b'\t')
        {
            return Err(HeadError::Malformed(
                "a control or non-ASCII byte in a header",
            ));
        }
        if headers.len() == MAX_HEADERS {
            return Err(HeadError::TooManyHeaders);
        }
        let Some((name, value)) = line.split_once(':') else {
            return Err(HeadError::Malformed("a header line without ':'"));
        };
        // A leading space or tab would be a folded line; a space before ':' is refused by
        // RFC 9112 (both are smuggling classics).
        if name.is_empty() || !name.bytes().all(is_tchar) {
            return Err(HeadError::Malformed("a header name is not a token"));
        }
        headers.push((name.to_owned(), value.trim_matches([' ', '\t']).to_owned()));
    }
    if !start.bytes().all(|b| b.is_ascii_graphic() || b == b' ') {
        return Err(HeadError::Malformed(
            "a control or non-ASCII byte in the start line",
        ));
    }
    Ok((start, Headers(headers)))
}

#[cfg(test)]
mod tests {
    use super::*;

    const UPGRADE: &str = "GET /?token=abc HTTP/1.1\r\nHost: 127.0.0.1:8765\r\n\
        Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\
        Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: foxglove.sdk.v1\r\n\
        Origin: https://app.foxglove.dev\r\n\r\n";

    #[test]
    fn a_websocket_upgrade_is_read_and_written_back_the_same() {
        let head = RequestHead::parse(UPGRADE.as_bytes()).expect("a valid head");
        assert_eq!(head.method, "GET");
        assert_eq!(head.query(), Some("token=abc"));
        assert_eq!(
            head.headers.single("origin"),
            Ok(Some("https://app.foxglove.dev"))
        );
        assert_eq!(head.headers.single("authorization"), Ok(None));
        assert_eq!(head.to_bytes(), UPGRADE.as_bytes());
        assert_eq!(head_end(UPGRADE.as_bytes()), Some(UPGRADE.len()));
        let mut more = UPGRADE.as_bytes().to_vec();
        more.extend_from_slice(b"\x81\x00");
        assert_eq!(head_end(&more), Some(UPGRADE.len()));
        assert_eq!(head_end(b"GET / HTTP/1.1\r\nHost: x\r\n"), None);
    }

    #[test]
    fn malformed_heads_are_refused() {
        let bad: &[&[u8]] = &[
            b"GET / HTTP/1.0\r\n\r\n",
            b"GET / HTTP/1.1 extra\r\n\r\n",
            b"GET http://x/ HTTP/1.1\r\n\r\n",
            b"GET  / HTTP/1.1\r\n\r\n",
            b"G(T / HTTP/1.1\r\n\r\n",
            b"GET / HTTP/1.1\r\nOrigin : x\r\n\r\n",
            b"GET / HTTP/1.1\r\n Origin: x\r\n\r\n",
            b"GET / HTTP/1.1\r\nOrigin x\r\n\r\n",
            b"GET / HTTP/1.1\r\nOrigin: a\nb\r\n\r\n",
            b"GET / HTTP/1.1\r\nOrigin: a\rb\r\n\r\n",
            b"GET / HTTP/1.1\r\nOrigin: a\x00b\r\n\r\n",
            b"GET / HTTP/1.1\r\nOrigin: \xc3\xa9\r\n\r\n",
            b"GET /\x1b[31m HTTP/1.1\r\n\r\n",
            b"GET / HTTP/1.1\r\nHost: x\r\n",
            b"GET / HTTP/1.1\r\n\r\nOrigin: x\r\n\r\n",
        ];
        for head in bad {
            assert!(
                matches!(RequestHead::parse(head), Err(HeadError::Malformed(_))),
                "{:?} accepted",
                String::from_utf8_lossy(head)
            );
        }
    }

    #[test]
    fn oversized_heads_and_too_many_headers_are_refused() {
        let mut big = b"GET / HTTP/1.1\r\nX: ".to_vec();
        big.extend(std::iter::repeat_n(b'a', MAX_HEAD_BYTES));
        big.extend_from_slice(b"\r\n\r\n");
        assert_eq!(RequestHead::parse(&big), Err(HeadError::TooLarge));
        let mut many = String::from("GET / HTTP/1.1\r\n");
        for i in 0..=MAX_HEADERS {
            many.push_str(&format!("X-{i}: 1\r\n"));
        }
        many.push_str("\r\n");
        assert_eq!(
            RequestHead::parse(many.as_bytes()),
            Err(HeadError::TooManyHeaders)
        );
    }

    #[test]
    fn a_repeated_header_has_no_single_value_and_set_replaces_all() {
        let head = RequestHead::parse(b"GET / HTTP/1.1\r\nOrigin: a\r\nX: 1\r\norigin: b\r\n\r\n")
            .expect("head");
        assert_eq!(
            head.headers.single("Origin"),
            Err(HeadError::Repeated("Origin".into()))
        );
        let mut headers = head.headers;
        headers.set("ORIGIN", "c");
        assert_eq!(headers.all("origin").collect::<Vec<_>>(), vec!["c"]);
        assert_eq!(headers.0[0], ("ORIGIN".to_owned(), "c".to_owned()));
    }

    #[test]
    fn a_response_head_is_read_and_rewritten() {
        let text =
            b"HTTP/1.1 101 Switching Protocols\r\nsec-websocket-protocol: foxglove.sdk.v1\r\n\r\n";
        let mut head = ResponseHead::parse(text).expect("response");
        assert_eq!(head.status, 101);
        assert_eq!(head.reason, "Switching Protocols");
        assert_eq!(head.to_bytes(), text.to_vec());
        head.headers
            .set("Sec-WebSocket-Protocol", "foxglove.websocket.v1");
        assert!(String::from_utf8_lossy(&head.to_bytes())
            .contains("Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n"));
        assert!(ResponseHead::parse(b"HTTP/1.1 1010 x\r\n\r\n").is_err());
        assert!(ResponseHead::parse(b"HTTP/1.0 101 x\r\n\r\n").is_err());
    }
}
