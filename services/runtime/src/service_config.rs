//! The part of every service's config file that is the same for all of them: the key
//! root, the instance name and the Zenoh fragment. Each service's config embeds it with
//! `#[serde(flatten)]`, so a file keeps its flat shape (`root:`, `instance:`, `zenoh:`
//! beside the service's own fields) and the three fields, their defaults and their docs
//! are written once.
//!
//! Serde does not support `deny_unknown_fields` on a struct with a flattened field
//! (the attribute is silently ineffective there), and a misspelt field must still be
//! refused by name. So each config also flattens an [`UnknownFields`] last: serde hands
//! a flattened map every key no named field and no earlier flattened struct took, and
//! `UnknownFields` refuses the first one it is given.
//!
//! ```
//! use roam_runtime::service_config::{ServiceConfig, UnknownFields};
//!
//! #[derive(Debug, Default, serde::Deserialize)]
//! #[serde(default)]
//! struct ExampleConfig {
//!     #[serde(flatten)]
//!     service: ServiceConfig,
//!     rate_hz: f64,
//!     #[serde(flatten)]
//!     unknown: UnknownFields,
//! }
//!
//! let ok: ExampleConfig = serde_yaml_ng::from_str("root: site\nrate_hz: 5").unwrap();
//! assert_eq!((ok.service.root.as_str(), ok.rate_hz), ("site", 5.0));
//! let typo = serde_yaml_ng::from_str::<ExampleConfig>("rate: 5").unwrap_err();
//! assert!(typo.to_string().contains("unknown field `rate`"), "{typo}");
//! ```

use std::fmt;

use serde::de::{self, Deserializer, IgnoredAny, MapAccess, Visitor};
use serde::Deserialize;

/// What every service's config file names the same way.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct ServiceConfig {
    /// The key root every key of the service is under (`<root>/…`).
    pub root: String,
    /// The instance name in the service's liveliness token; the Zenoh session id when
    /// absent.
    pub instance: Option<String>,
    /// A Zenoh config fragment, lowest precedence (see [`crate::session`]).
    pub zenoh: Option<serde_json::Value>,
}

impl Default for ServiceConfig {
    fn default() -> Self {
        ServiceConfig {
            root: roam_proto::keys::DEFAULT_ROOT.to_owned(),
            instance: None,
            zenoh: None,
        }
    }
}

impl ServiceConfig {
    /// The defaults under key root `root`.
    pub fn at(root: impl Into<String>) -> Self {
        ServiceConfig {
            root: root.into(),
            ..ServiceConfig::default()
        }
    }
}

/// Flattened last into a config struct, refuses any field the struct does not name
/// (module doc: why not `deny_unknown_fields`). It holds nothing.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UnknownFields;

impl<'de> Deserialize<'de> for UnknownFields {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_map(RefuseAny)
    }
}

struct RefuseAny;

impl<'de> Visitor<'de> for RefuseAny {
    type Value = UnknownFields;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("no fields beyond the config's own")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<UnknownFields, A::Error> {
        match map.next_key::<String>()? {
            None => Ok(UnknownFields),
            Some(key) => {
                let _: IgnoredAny = map.next_value()?;
                Err(de::Error::custom(format_args!(
                    "unknown field `{}`: see the service's README for its config fields",
                    roam_proto::excerpt::excerpt_n(&key, 64)
                )))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Default, Deserialize)]
    #[serde(default)]
    struct Example {
        #[serde(flatten)]
        service: ServiceConfig,
        scenario: Option<String>,
        rate_hz: f64,
        #[serde(flatten)]
        unknown: UnknownFields,
    }

    fn parse(text: &str) -> Result<Example, String> {
        serde_yaml_ng::from_str(text).map_err(|e| e.to_string())
    }

    #[test]
    fn the_common_fields_sit_beside_the_services_own() {
        let config = parse(
            "root: site\ninstance: a\nzenoh: { mode: client }\nscenario: s.yaml\nrate_hz: 2.5",
        )
        .expect("a valid config");
        assert_eq!(config.service.root, "site");
        assert_eq!(config.service.instance.as_deref(), Some("a"));
        assert_eq!(
            config.service.zenoh,
            Some(serde_json::json!({ "mode": "client" }))
        );
        assert_eq!(config.scenario.as_deref(), Some("s.yaml"));
        assert_eq!(config.rate_hz, 2.5);
        assert_eq!(config.unknown, UnknownFields);
    }

    #[test]
    fn absent_fields_take_their_defaults() {
        let config = parse("{}").expect("an empty config");
        assert_eq!(config.service, ServiceConfig::default());
        assert_eq!(config.service.root, roam_proto::keys::DEFAULT_ROOT);
        assert_eq!(config.rate_hz, 0.0);
    }

    #[test]
    fn a_misspelt_field_is_refused_by_name_wherever_it_is() {
        for text in [
            "rot: site",
            "rate_hz: 1\nscenaro: x",
            "instance: a\nzenho: {}",
        ] {
            let e = parse(text).expect_err(text);
            let name = text
                .lines()
                .last()
                .and_then(|l| l.split(':').next())
                .unwrap_or_default();
            assert!(
                e.contains(&format!("unknown field `{name}`")),
                "{text}: {e}"
            );
        }
    }

    #[test]
    fn a_wrong_type_in_either_part_is_refused() {
        let e = parse("rate_hz: fast").expect_err("a string for a number");
        assert!(e.contains("rate_hz"), "{e}");
        let e = parse("root: [a, b]").expect_err("a list for the root");
        assert!(e.contains("invalid type"), "{e}");
    }
}
