//! The Zenoh session a service opens, layered from, lowest to highest precedence:
//!
//! 1. the `zenoh:` section of the service's own config file (a Zenoh config fragment in
//!    the shape of a Zenoh JSON5 config file);
//! 2. the Zenoh config file named by `ZENOH_CONFIG` (JSON5 or YAML);
//! 3. the flags `--mode`, `--connect`, `--listen`, `--no-multicast`;
//! 4. each `--cfg KEY:VALUE` (a Zenoh config path and a JSON5 value), in order.
//!
//! Layers 1 and 2 are merged as JSON objects (a key set in 2 replaces the same key in
//! 1, other keys of 1 stay) over roam's [transport defaults](transport_defaults), then
//! handed to Zenoh, which validates the result and fills in its defaults; layers 3 and 4
//! are inserted into that config one key at a time.

use std::path::{Path, PathBuf};

use serde_json::Value;

/// The environment variable naming a Zenoh config file (Zenoh's own convention).
pub const ZENOH_CONFIG_ENV: &str = "ZENOH_CONFIG";

/// The largest Zenoh message a roam session receives, in bytes (Zenoh's
/// `transport/link/rx/max_message_size`, 1 GiB by default). Above the largest request
/// any roam service accepts (the map server's `max_request_bytes`, 96 MiB) and the
/// largest layer it serves, so every message roam itself sends arrives and a service
/// sees, and refuses by name, any request up to this size; a larger one is dropped by
/// Zenoh where it arrives (the sender's query times out) instead of being reassembled.
pub const MAX_MESSAGE_BYTES: u64 = 128 * 1024 * 1024;

/// How long, in microseconds, Zenoh may wait to queue one blocking message (a query, a
/// reply, a `Block` put) on a link before it closes that link's transport (Zenoh's
/// `transport/link/tx/queue/congestion_control/block/wait_before_close`, 5 s by
/// default). Zenoh sets this deadline once for the whole message, at its first wait, not
/// per fragment: a 48 MB query routed to a service on a loaded 2-core machine could take
/// longer than 5 s to drain, and the router then closed *the service's* transport with
/// every query in flight. 30 s lets [`MAX_MESSAGE_BYTES`] cross at 4.5 MB/s; a peer that
/// has gone away is dropped sooner by its lease (10 s).
pub const WAIT_BEFORE_CLOSE_US: u64 = 30_000_000;

/// roam's own defaults for every session it opens, under every other layer (a file,
/// `ZENOH_CONFIG`, a flag or `--cfg` set the same keys over them).
pub fn transport_defaults() -> Value {
    serde_json::json!({
        "transport": {"link": {
            "rx": {"max_message_size": MAX_MESSAGE_BYTES},
            "tx": {"queue": {"congestion_control": {"block": {
                "wait_before_close": WAIT_BEFORE_CLOSE_US
            }}}}
        }}
    })
}

/// Zenoh session flags shared by every role of the `roam` binary.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct SessionArgs {
    /// Zenoh mode: `peer` (default for services), `client` (connect only to a router) or
    /// `router` (route for others).
    #[arg(long, value_parser = ["peer", "client", "router"])]
    pub mode: Option<String>,
    /// An endpoint to connect to, e.g. `tcp/10.0.0.5:7447`. Repeat for several.
    #[arg(long, value_name = "ENDPOINT")]
    pub connect: Vec<String>,
    /// An endpoint to listen on, e.g. `tcp/0.0.0.0:7447`. Repeat for several.
    #[arg(long, value_name = "ENDPOINT")]
    pub listen: Vec<String>,
    /// Turn off multicast scouting: meet other sessions only through `--connect`.
    #[arg(long)]
    pub no_multicast: bool,
    /// Any Zenoh config key, e.g. `--cfg 'scouting/gossip/enabled:false'`. The value is
    /// JSON5. Applied last, in order.
    #[arg(long = "cfg", value_name = "KEY:VALUE")]
    pub cfg: Vec<String>,
}

/// Why a Zenoh configuration could not be built.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    #[error("cannot read the Zenoh config file {path} (from {ZENOH_CONFIG_ENV}): {reason}")]
    EnvFile { path: PathBuf, reason: String },
    #[error("the Zenoh configuration is invalid: {0}")]
    Invalid(String),
    #[error("--cfg '{0}' is not KEY:VALUE (for example --cfg 'mode:\"client\"')")]
    CfgSyntax(String),
    #[error("cannot set Zenoh config key '{key}' to {value}: {reason}")]
    Insert {
        key: String,
        value: String,
        reason: String,
    },
    #[error("cannot open the Zenoh session: {0}")]
    Open(String),
}

impl SessionArgs {
    /// Flags for a session that talks only to the given router endpoint: client mode,
    /// multicast off. What the in-process stack and the tests use.
    pub fn client_of(endpoint: &str) -> Self {
        SessionArgs {
            mode: Some("client".into()),
            connect: vec![endpoint.to_owned()],
            no_multicast: true,
            ..SessionArgs::default()
        }
    }

    /// Flags for a router that listens on `endpoint` with multicast off.
    pub fn router_on(endpoint: &str) -> Self {
        SessionArgs {
            mode: Some("router".into()),
            listen: vec![endpoint.to_owned()],
            no_multicast: true,
            ..SessionArgs::default()
        }
    }

    /// Builds the layered Zenoh config; `file_section` is the `zenoh:` section of the
    /// service's config file, if it has one. `ZENOH_CONFIG` is read from the environment.
    pub fn zenoh_config(
        &self,
        file_section: Option<&Value>,
    ) -> Result<zenoh::Config, SessionError> {
        let env_file = std::env::var_os(ZENOH_CONFIG_ENV).map(PathBuf::from);
        self.zenoh_config_with(file_section, env_file.as_deref())
    }

    /// [`Self::zenoh_config`] with the `ZENOH_CONFIG` file given explicitly (for tests).
    pub fn zenoh_config_with(
        &self,
        file_section: Option<&Value>,
        env_file: Option<&Path>,
    ) -> Result<zenoh::Config, SessionError> {
        let mut merged = transport_defaults();
        if let Some(section) = file_section {
            merge(&mut merged, section.clone());
        }
        if let Some(path) = env_file {
            merge(&mut merged, read_zenoh_file(path)?);
        }
        let mut config = zenoh::Config::from_json5(&merged.to_string())
            .map_err(|e| SessionError::Invalid(e.to_string()))?;
        let mut insert = |key: &str, value: String| {
            config
                .insert_json5(key, &value)
                .map_err(|e| SessionError::Insert {
                    key: key.to_owned(),
                    value,
                    reason: e.to_string(),
                })
        };
        if let Some(mode) = &self.mode {
            insert("mode", json(mode))?;
        }
        if !self.connect.is_empty() {
            insert("connect/endpoints", json(&self.connect))?;
        }
        if !self.listen.is_empty() {
            insert("listen/endpoints", json(&self.listen))?;
        }
        if self.no_multicast {
            insert("scouting/multicast/enabled", "false".into())?;
        }
        for entry in &self.cfg {
            let (key, value) = entry
                .split_once(':')
                .filter(|(k, v)| !k.is_empty() && !v.is_empty())
                .ok_or_else(|| SessionError::CfgSyntax(entry.clone()))?;
            insert(key, value.to_owned())?;
        }
        Ok(config)
    }
}

fn json<T: serde::Serialize + ?Sized>(value: &T) -> String {
    serde_json::to_string(value).unwrap_or_else(|_| "null".into())
}

/// Reads a Zenoh config file (JSON5, or YAML by extension) as a JSON value.
fn read_zenoh_file(path: &Path) -> Result<Value, SessionError> {
    let fail = |reason: String| SessionError::EnvFile {
        path: path.to_owned(),
        reason,
    };
    let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
    let is_yaml = matches!(
        path.extension().and_then(|e| e.to_str()),
        Some("yaml") | Some("yml")
    );
    let value: Value = if is_yaml {
        serde_yaml_ng::from_str(&text).map_err(|e| fail(e.to_string()))?
    } else {
        json5::from_str(&text).map_err(|e| fail(e.to_string()))?
    };
    if !value.is_object() {
        return Err(fail("the file must hold one object".into()));
    }
    Ok(value)
}

/// Merges `over` into `base`: objects key by key, everything else replaced.
fn merge(base: &mut Value, over: Value) {
    match (base, over) {
        (Value::Object(base), Value::Object(over)) => {
            for (key, value) in over {
                match base.get_mut(&key) {
                    Some(slot) => merge(slot, value),
                    None => {
                        base.insert(key, value);
                    }
                }
            }
        }
        (slot, value) => *slot = value,
    }
}

/// Opens a Zenoh session.
pub async fn open(config: zenoh::Config) -> Result<zenoh::Session, SessionError> {
    zenoh::open(config)
        .await
        .map_err(|e| SessionError::Open(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn get(config: &zenoh::Config, key: &str) -> Value {
        serde_json::from_str(&config.get_json(key).expect("key")).expect("json")
    }

    #[test]
    fn layers_apply_in_order_file_env_flags_cfg() {
        let dir = std::env::temp_dir().join(format!("roam-session-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let env_file = dir.join("zenoh.json5");
        std::fs::write(
            &env_file,
            "{ mode: 'client', connect: { endpoints: ['tcp/127.0.0.1:7001'] }, // comment\n }",
        )
        .expect("write");
        let file_section = serde_json::json!({
            "mode": "router",
            "listen": {"endpoints": ["tcp/127.0.0.1:7000"]},
            "connect": {"endpoints": ["tcp/127.0.0.1:6999"]},
        });
        let args = SessionArgs {
            connect: vec!["tcp/127.0.0.1:7002".into()],
            no_multicast: true,
            cfg: vec!["mode:\"peer\"".into()],
            ..SessionArgs::default()
        };
        let config = args
            .zenoh_config_with(Some(&file_section), Some(&env_file))
            .expect("config");
        // The file's listen stays, the env file's mode was overridden by --cfg, the
        // env file's connect was overridden by --connect.
        assert_eq!(
            get(&config, "listen/endpoints"),
            serde_json::json!(["tcp/127.0.0.1:7000"])
        );
        assert_eq!(
            get(&config, "connect/endpoints"),
            serde_json::json!(["tcp/127.0.0.1:7002"])
        );
        assert_eq!(get(&config, "mode"), serde_json::json!("peer"));
        assert_eq!(
            get(&config, "scouting/multicast/enabled"),
            serde_json::json!(false)
        );

        let env_only = SessionArgs::default()
            .zenoh_config_with(Some(&file_section), Some(&env_file))
            .expect("config");
        assert_eq!(get(&env_only, "mode"), serde_json::json!("client"));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn transport_defaults_apply_under_every_layer() {
        let config = SessionArgs::default()
            .zenoh_config_with(None, None)
            .expect("config");
        assert_eq!(
            get(&config, "transport/link/rx/max_message_size"),
            serde_json::json!(MAX_MESSAGE_BYTES)
        );
        let wait = "transport/link/tx/queue/congestion_control/block/wait_before_close";
        assert_eq!(get(&config, wait), serde_json::json!(WAIT_BEFORE_CLOSE_US));
        let file_section =
            serde_json::json!({"transport": {"link": {"rx": {"max_message_size": 1000}}}});
        let args = SessionArgs {
            cfg: vec![format!("{wait}:7")],
            ..SessionArgs::default()
        };
        let config = args
            .zenoh_config_with(Some(&file_section), None)
            .expect("config");
        assert_eq!(
            get(&config, "transport/link/rx/max_message_size"),
            serde_json::json!(1000)
        );
        assert_eq!(get(&config, wait), serde_json::json!(7));
    }

    #[test]
    fn bad_cfg_and_bad_files_are_named() {
        let args = SessionArgs {
            cfg: vec!["no-colon".into()],
            ..SessionArgs::default()
        };
        let err = args
            .zenoh_config_with(None, None)
            .expect_err("must be refused");
        assert!(err.to_string().contains("no-colon"), "{err}");

        let args = SessionArgs {
            cfg: vec!["mode:\"sideways\"".into()],
            ..SessionArgs::default()
        };
        assert!(matches!(
            args.zenoh_config_with(None, None),
            Err(SessionError::Insert { .. })
        ));

        let missing = Path::new("/nonexistent/zenoh.json5");
        let err = SessionArgs::default()
            .zenoh_config_with(None, Some(missing))
            .expect_err("must be refused");
        assert!(
            err.to_string().contains("/nonexistent/zenoh.json5"),
            "{err}"
        );
    }
}

#[cfg(test)]
mod shipped_configs {
    use super::*;

    /// Every Zenoh config shipped in `deploy/` is accepted by Zenoh.
    #[test]
    fn deploy_configs_parse() {
        let deploy = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../deploy");
        let mut seen = 0;
        for entry in std::fs::read_dir(&deploy).expect("deploy dir") {
            let path = entry.expect("entry").path();
            if path.extension().and_then(|e| e.to_str()) == Some("json5") {
                SessionArgs::default()
                    .zenoh_config_with(None, Some(&path))
                    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                seen += 1;
            }
        }
        assert!(seen >= 2);
    }
}
