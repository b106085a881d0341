//! Who a request is from, for its fair share.

use std::sync::Arc;

/// The longest client name kept; a longer one is cut there.
pub const MAX_CLIENT_ID_BYTES: usize = 64;

/// Who a request is from, for its fair share: the name the client gives (clipped to
/// [`MAX_CLIENT_ID_BYTES`]), or one shared name for every client that gives none.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ClientId(Arc<str>);

impl ClientId {
    /// The share of the requests that name no client.
    pub fn anonymous() -> ClientId {
        ClientId(Arc::from(""))
    }

    /// The client named `name` (empty: [`ClientId::anonymous`]).
    pub fn named(name: &str) -> ClientId {
        let mut end = name.len().min(MAX_CLIENT_ID_BYTES);
        while !name.is_char_boundary(end) {
            end -= 1;
        }
        ClientId(Arc::from(&name[..end]))
    }

    pub fn as_str(&self) -> &str {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn client_names_are_clipped() {
        let long = "é".repeat(100);
        assert!(ClientId::named(&long).as_str().len() <= MAX_CLIENT_ID_BYTES);
        assert_eq!(ClientId::named(""), ClientId::anonymous());
    }
}
