//! Element counts checked while a message is parsed, not after.
//!
//! A payload under its size limit can still hold far more elements than a service will
//! take (a 60 MB mission is ten million waypoints). With `#[serde(deserialize_with =
//! "bounded::vec::<_, N, _>")]` the parser stops at element N + 1 with an error that
//! names the limit, so a request over it costs at most N elements of work and memory,
//! never the whole body.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{Deserialize, Deserializer, SeqAccess, Visitor};

/// A sequence of at most `N` elements; one more is a parse error naming `N`.
pub fn vec<'de, T, const N: usize, D>(deserializer: D) -> Result<Vec<T>, D::Error>
where
    T: Deserialize<'de>,
    D: Deserializer<'de>,
{
    deserializer.deserialize_seq(BoundedSeq::<T, N>(PhantomData))
}

struct BoundedSeq<T, const N: usize>(PhantomData<T>);

impl<'de, T: Deserialize<'de>, const N: usize> Visitor<'de> for BoundedSeq<T, N> {
    type Value = Vec<T>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "a sequence of at most {N} elements")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<T>, A::Error> {
        let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(N).min(4096));
        while let Some(element) = seq.next_element()? {
            if out.len() == N {
                return Err(serde::de::Error::custom(format_args!(
                    "more than {N} elements; send at most {N}"
                )));
            }
            out.push(element);
        }
        Ok(out)
    }
}

/// A string of at most `N` bytes; a longer one is a parse error naming `N`.
pub fn string<'de, const N: usize, D>(deserializer: D) -> Result<String, D::Error>
where
    D: Deserializer<'de>,
{
    let s = String::deserialize(deserializer)?;
    if s.len() > N {
        return Err(serde::de::Error::custom(format_args!(
            "a string of {} bytes; at most {N}",
            s.len()
        )));
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize)]
    struct Three {
        #[serde(deserialize_with = "vec::<_, 3, _>")]
        items: Vec<u32>,
        #[serde(deserialize_with = "string::<4, _>")]
        name: String,
    }

    #[test]
    fn up_to_the_limit_parses() {
        let t: Three = serde_json::from_str(r#"{"items": [1, 2, 3], "name": "abcd"}"#).expect("ok");
        assert_eq!((t.items.len(), t.name.as_str()), (3, "abcd"));
    }

    #[test]
    fn one_more_stops_the_parse_naming_the_limit() {
        let e = serde_json::from_str::<Three>(r#"{"items": [1, 2, 3, 4], "name": "a"}"#)
            .expect_err("four");
        assert!(e.to_string().contains("at most 3"), "{e}");
        let e = serde_json::from_str::<Three>(r#"{"items": [], "name": "abcde"}"#)
            .expect_err("five bytes");
        assert!(e.to_string().contains("at most 4"), "{e}");
    }

    #[test]
    fn the_parse_stops_at_the_limit_not_at_the_end() {
        // The element after the limit is garbage: had the parser gone on, the error
        // would be about it.
        let e = serde_json::from_str::<Three>(r#"{"items": [1, 2, 3, 4, "x"], "name": "a"}"#)
            .expect_err("over");
        assert!(e.to_string().contains("at most 3"), "{e}");
    }
}
