//! Turning valid messages into bad ones: random bytes, byte mutations, JSON edits with
//! extreme values, other kinds and versions.

use super::*;

/// JSON values that stress a field: extremes, wrong types, NaN-like strings.
pub(crate) fn odd_value(rng: &mut ChaCha8Rng) -> serde_json::Value {
    use serde_json::json;
    match rng.random_range(0..26) {
        0 => json!(1e300),
        1 => json!(-1e300),
        2 => json!(f64::MAX),
        3 => json!(f64::MIN_POSITIVE),
        4 => json!(u64::MAX),
        5 => json!(i64::MIN),
        6 => json!(-1),
        7 => json!(0),
        8 => json!(u32::MAX),
        9 => json!(u64::from(u32::MAX) + 1),
        10 => json!("NaN"),
        11 => json!("inf"),
        12 => json!("-Infinity"),
        13 => json!(""),
        14 => json!("x".repeat(rng.random_range(1..4000))),
        15 => json!(null),
        16 => json!(true),
        17 => json!([]),
        18 => json!({}),
        19 => json!([1e300, -1e300]),
        20 => json!(1e-320),
        21 => json!(-0.0),
        22 => json!("../../../../etc/passwd"),
        23 => json!("a/b/*/**"),
        24 => json!(rng.random::<f64>() * 1e6 - 5e5),
        _ => json!(rng.random::<u32>()),
    }
}

/// Every JSON path (object keys and array indices) in `value`.
pub(crate) fn paths(
    value: &serde_json::Value,
    prefix: &mut Vec<PathStep>,
    out: &mut Vec<Vec<PathStep>>,
) {
    out.push(prefix.clone());
    match value {
        serde_json::Value::Object(map) => {
            for (k, v) in map {
                prefix.push(PathStep::Key(k.clone()));
                paths(v, prefix, out);
                prefix.pop();
            }
        }
        serde_json::Value::Array(items) => {
            // Large arrays (cells, waypoints): a few indices are enough.
            for (i, v) in items.iter().enumerate().take(8) {
                prefix.push(PathStep::Index(i));
                paths(v, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

#[derive(Debug, Clone)]
pub(crate) enum PathStep {
    Key(String),
    Index(usize),
}

pub(crate) fn at_path<'a>(
    value: &'a mut serde_json::Value,
    path: &[PathStep],
) -> Option<&'a mut serde_json::Value> {
    let mut v = value;
    for step in path {
        v = match step {
            PathStep::Key(k) => v.get_mut(k.as_str())?,
            PathStep::Index(i) => v.get_mut(*i)?,
        };
    }
    Some(v)
}

/// A JSON-aware edit: replace a field with an odd value, drop or add a field, change
/// the version or the kind, nest deeply, duplicate arrays.
pub(crate) fn json_edit(rng: &mut ChaCha8Rng, base: &[u8]) -> Vec<u8> {
    let Ok(mut value) = serde_json::from_slice::<serde_json::Value>(base) else {
        return base.to_vec();
    };
    // Indexing a JSON value that is not an object panics (serde_json's `IndexMut`):
    // a base that is a bare number or string (a mutation of a mutation) is left alone.
    if !value.is_object() {
        return base.to_vec();
    }
    match rng.random_range(0..8) {
        0 => {
            value["v"] = match rng.random_range(0..6) {
                0 => serde_json::json!(0),
                1 => serde_json::json!(2),
                2 => serde_json::json!(u32::MAX),
                3 => serde_json::json!(-1),
                4 => serde_json::json!("1"),
                _ => serde_json::json!(1.5),
            };
        }
        1 => value["kind"] = serde_json::json!(KINDS[rng.random_range(0..KINDS.len())]),
        2 => {
            if let Some(obj) = value.as_object_mut() {
                let keys: Vec<String> = obj.keys().cloned().collect();
                if !keys.is_empty() {
                    obj.remove(&keys[rng.random_range(0..keys.len())]);
                }
                if rng.random_bool(0.5) {
                    obj.insert("extra".into(), odd_value(rng));
                }
            }
        }
        3 => {
            // Deep nesting in the body.
            let depth = rng.random_range(10..200);
            let mut nested = odd_value(rng);
            for _ in 0..depth {
                nested = serde_json::json!([nested]);
            }
            value["body"] = nested;
        }
        _ => {
            let mut all = Vec::new();
            paths(&value, &mut Vec::new(), &mut all);
            let body_paths: Vec<&Vec<PathStep>> = all
                .iter()
                .filter(|p| matches!(p.first(), Some(PathStep::Key(k)) if k == "body"))
                .collect();
            if !body_paths.is_empty() {
                let path = body_paths[rng.random_range(0..body_paths.len())].clone();
                let odd = odd_value(rng);
                if let Some(slot) = at_path(&mut value, &path) {
                    if rng.random_bool(0.2) {
                        if let serde_json::Value::Object(map) = slot {
                            map.insert("unknown_field".into(), odd);
                        } else {
                            *slot = odd;
                        }
                    } else {
                        *slot = odd;
                    }
                }
            }
        }
    }
    serde_json::to_vec(&value).unwrap_or_else(|_| base.to_vec())
}

/// Byte-level mutations of a valid message.
pub(crate) fn mutate(rng: &mut ChaCha8Rng, base: &[u8], others: &[Vec<u8>]) -> Vec<u8> {
    let mut bytes = base.to_vec();
    let rounds = if rng.random_bool(0.7) {
        1
    } else {
        rng.random_range(2..6)
    };
    for _ in 0..rounds {
        let len = bytes.len();
        match rng.random_range(0..10) {
            0 if len > 0 => {
                for _ in 0..rng.random_range(1..8) {
                    let i = rng.random_range(0..len);
                    bytes[i] ^= 1 << rng.random_range(0..8);
                }
            }
            1 => {
                let at = rng.random_range(0..=len);
                let n = rng.random_range(1..32);
                let junk: Vec<u8> = (0..n).map(|_| rng.random()).collect();
                bytes.splice(at..at, junk);
            }
            2 if len > 0 => {
                let a = rng.random_range(0..len);
                let b = (a + rng.random_range(1..64)).min(len);
                bytes.drain(a..b);
            }
            3 => bytes.truncate(rng.random_range(0..=len)),
            4 if len > 0 => {
                const TOKENS: &[u8] = b"{}[]\",:-+.eE0123456789 \\tnf";
                let i = rng.random_range(0..len);
                bytes[i] = TOKENS[rng.random_range(0..TOKENS.len())];
            }
            5 => {
                // Digits inserted into a number: huge values.
                let at = rng.random_range(0..=len);
                let digits: Vec<u8> = (0..rng.random_range(1..25))
                    .map(|_| b'0' + rng.random_range(0..10u8))
                    .collect();
                bytes.splice(at..at, digits);
            }
            6 => bytes.extend_from_slice(
                [&b" "[..], b"x", b"{}", b"\0", b"]", b"\n\n"][rng.random_range(0..6)],
            ),
            7 if !others.is_empty() => {
                // Splice another message's tail into this one.
                let other = &others[rng.random_range(0..others.len())];
                let a = rng.random_range(0..=len);
                let b = rng.random_range(0..=other.len());
                bytes.truncate(a);
                bytes.extend_from_slice(&other[b..]);
            }
            _ => bytes = json_edit(rng, &bytes),
        }
    }
    bytes
}

/// Random bytes of random length (0..2 KiB), sometimes printable JSON-ish.
pub(crate) fn random_bytes(rng: &mut ChaCha8Rng) -> Vec<u8> {
    let n = rng.random_range(0..2048);
    if rng.random_bool(0.3) {
        const ALPHABET: &[u8] = b"{}[]\":,0123456789.-eEtruefalsnl vkindbody";
        (0..n)
            .map(|_| ALPHABET[rng.random_range(0..ALPHABET.len())])
            .collect()
    } else {
        (0..n).map(|_| rng.random()).collect()
    }
}

/// One payload for a target: random, a mutation of the right kind, a valid message
/// of the right kind (often extreme), or a message of another kind.
pub(crate) fn payload(rng: &mut ChaCha8Rng, target: &Target, all: &[Vec<u8>]) -> Vec<u8> {
    let roll = rng.random_range(0..100);
    if roll < 20 || target.bases.is_empty() {
        random_bytes(rng)
    } else if roll < 85 {
        let base = &target.bases[rng.random_range(0..target.bases.len())];
        mutate(rng, base, all)
    } else if roll < 93 {
        target.bases[rng.random_range(0..target.bases.len())].clone()
    } else {
        let other = &all[rng.random_range(0..all.len())];
        if rng.random_bool(0.5) {
            other.clone()
        } else {
            mutate(rng, other, &[])
        }
    }
}

// ---------------------------------------------------------------------------------------
// Valid messages, ordinary and extreme.
