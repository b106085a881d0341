//! rmw_zenoh's names on the Zenoh wire: the key of a topic or service, the liveliness
//! tokens of nodes and endpoints, their QoS field and the entity GIDs
//! (ros2/rmw_zenoh `docs/design.md`, `liveliness_utils.cpp`, `qos.cpp`).
//!
//! - A topic or service key is `<domain>/<fully qualified name without its outer '/'>/
//!   <DDS type name>/<RIHS01 hash>`: `0/map/nav_msgs::msg::dds_::OccupancyGrid_/RIHS01_8d34…`.
//! - A node's token is `@ros2_lv/<domain>/<session id>/<node id>/<node id>/NN/<enclave>/
//!   <namespace>/<node>`; an endpoint's adds its own id and kind (`MP` publisher, `MS`
//!   subscription, `SS` service server, `SC` client) and `/<name>/<type>/<hash>/<qos>`.
//!   Every `/` inside a name is written `%`, so an empty enclave or the root namespace
//!   `/` is `%` and `/map` is `%map`.
//! - The QoS field is `rel:dur:hist,depth:dl_s,dl_ns:ls_s,ls_ns:live,lease_s,lease_ns`, each
//!   value written only where it differs from rmw_zenoh's default (reliable, volatile,
//!   keep last, depth 42, infinite deadline, lifespan and lease, automatic liveliness),
//!   with rmw's enum values (reliable 1, best effort 2; transient local 1, volatile 2;
//!   keep last 1, keep all 2).

use sha2::{Digest, Sha256};

/// The admin space of rmw_zenoh's liveliness tokens.
pub const ADMIN_SPACE: &str = "@ros2_lv";

/// What an entity is, as its token says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EntityKind {
    Node,
    Publisher,
    Subscription,
    Service,
    Client,
}

impl EntityKind {
    pub fn as_str(self) -> &'static str {
        match self {
            EntityKind::Node => "NN",
            EntityKind::Publisher => "MP",
            EntityKind::Subscription => "MS",
            EntityKind::Service => "SS",
            EntityKind::Client => "SC",
        }
    }

    fn parse(text: &str) -> Option<EntityKind> {
        [
            EntityKind::Node,
            EntityKind::Publisher,
            EntityKind::Subscription,
            EntityKind::Service,
            EntityKind::Client,
        ]
        .into_iter()
        .find(|k| k.as_str() == text)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reliability {
    Reliable,
    BestEffort,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Durability {
    /// Late joiners get the last `depth` samples.
    TransientLocal,
    Volatile,
}

/// The QoS roam's endpoints declare (deadline, lifespan and liveliness always at
/// rmw_zenoh's defaults, which is all rmw_zenoh implements).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    pub reliability: Reliability,
    pub durability: Durability,
    /// Keep last `depth`.
    pub depth: u32,
}

/// rmw_zenoh's default depth (`qos.cpp`).
pub const DEFAULT_DEPTH: u32 = 42;

impl Qos {
    /// A latched topic (`/map`, as Nav2's map_server): reliable, transient local, depth 1.
    pub const LATCHED: Qos = Qos {
        reliability: Reliability::Reliable,
        durability: Durability::TransientLocal,
        depth: 1,
    };
    /// A stream (poses): reliable, volatile, depth 10 (rclcpp's default profile).
    pub const STREAM: Qos = Qos {
        reliability: Reliability::Reliable,
        durability: Durability::Volatile,
        depth: 10,
    };
    /// A service (rmw's services profile): reliable, volatile, depth 10.
    pub const SERVICE: Qos = Qos::STREAM;
    /// `/tf` (tf2_ros' `DynamicBroadcasterQoS`): reliable, volatile, depth 100.
    pub const TF: Qos = Qos {
        reliability: Reliability::Reliable,
        durability: Durability::Volatile,
        depth: 100,
    };

    /// The token's QoS field.
    pub fn keyexpr(&self) -> String {
        let reliability = match self.reliability {
            Reliability::Reliable => "",
            Reliability::BestEffort => "2",
        };
        let durability = match self.durability {
            Durability::Volatile => "",
            Durability::TransientLocal => "1",
        };
        let depth = if self.depth == DEFAULT_DEPTH {
            String::new()
        } else {
            self.depth.to_string()
        };
        format!("{reliability}:{durability}:,{depth}:,:,:,,")
    }

    /// Reads a token's QoS field (the fields roam uses; others must be default or are
    /// refused). `None` when it is not one.
    pub fn parse(text: &str) -> Option<Qos> {
        let parts: Vec<&str> = text.split(':').collect();
        let [rel, dur, hist, deadline, lifespan, live] = parts.as_slice() else {
            return None;
        };
        let reliability = match *rel {
            "" | "1" => Reliability::Reliable,
            "2" => Reliability::BestEffort,
            _ => return None,
        };
        let durability = match *dur {
            "" | "2" => Durability::Volatile,
            "1" => Durability::TransientLocal,
            _ => return None,
        };
        let (kind, depth) = hist.split_once(',')?;
        if !(kind.is_empty() || kind == "1") {
            return None;
        }
        let depth = if depth.is_empty() {
            DEFAULT_DEPTH
        } else {
            depth.parse().ok()?
        };
        let defaults = *deadline == "," && *lifespan == "," && *live == ",,";
        defaults.then_some(Qos {
            reliability,
            durability,
            depth,
        })
    }
}

/// Writes every `/` of a name as `%` (rmw_zenoh's `mangle_name`).
pub fn mangle(name: &str) -> String {
    name.replace('/', "%")
}

/// A ROS name (a topic, a service, a namespace, a node) that roam may put in a key: ROS's
/// own rules (segments of `A-Z a-z 0-9 _`, not starting with a digit, no empty segment),
/// which also keep every Zenoh key-expression character (`*`, `$`, `?`, `#`) out.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{name}' is not a valid ROS {what}: use segments of A-Z, a-z, 0-9 and '_' separated by '/', none starting with a digit, at most 256 characters")]
pub struct NameError {
    pub what: &'static str,
    pub name: String,
}

fn is_segment(s: &str) -> bool {
    !s.is_empty()
        && !s.starts_with(|c: char| c.is_ascii_digit())
        && s.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
}

/// Checks a namespace: `/` or `/a/b`.
pub fn check_namespace(ns: &str) -> Result<(), NameError> {
    let ok = ns == "/"
        || (ns.len() <= 256
            && ns
                .strip_prefix('/')
                .is_some_and(|rest| rest.split('/').all(is_segment)));
    ok.then_some(()).ok_or_else(|| NameError {
        what: "namespace",
        name: ns.to_owned(),
    })
}

/// Checks a node name: one segment.
pub fn check_node_name(name: &str) -> Result<(), NameError> {
    (is_segment(name) && name.len() <= 256)
        .then_some(())
        .ok_or_else(|| NameError {
            what: "node name",
            name: name.to_owned(),
        })
}

/// The fully qualified name of `name`: itself when absolute (`/map`), else under the
/// namespace (`map` in `/site1` is `/site1/map`).
pub fn qualify(namespace: &str, name: &str) -> Result<String, NameError> {
    let bad = || NameError {
        what: "topic or service name",
        name: name.to_owned(),
    };
    let full = if let Some(rest) = name.strip_prefix('/') {
        format!("/{rest}")
    } else if namespace == "/" {
        format!("/{name}")
    } else {
        format!("{namespace}/{name}")
    };
    let ok = full.len() <= 256 && full[1..].split('/').all(is_segment);
    ok.then_some(full).ok_or_else(bad)
}

/// The key of a topic or service: `<domain>/<name without its outer '/'>/<DDS type>/<hash>`.
pub fn entity_key(domain: u32, qualified_name: &str, dds_type: &str, hash: &str) -> String {
    let name = qualified_name.trim_matches('/');
    format!("{domain}/{name}/{dds_type}/{hash}")
}

/// A node as its tokens name it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeInfo {
    pub domain: u32,
    /// The Zenoh session id, as Zenoh prints it.
    pub session: String,
    /// The node's id within the session.
    pub node_id: u32,
    /// `/` or `/a/b`.
    pub namespace: String,
    pub name: String,
    /// SROS enclave; empty for none.
    pub enclave: String,
}

/// What an endpoint's token adds to its node's.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EndpointInfo {
    pub id: u32,
    pub kind: EntityKind,
    pub qualified_name: String,
    pub dds_type: String,
    pub hash: String,
    pub qos: Qos,
}

fn mangled_or_percent(name: &str) -> String {
    if name.is_empty() {
        "%".to_owned()
    } else {
        mangle(name)
    }
}

/// The node's liveliness token.
pub fn node_token(node: &NodeInfo) -> String {
    format!(
        "{ADMIN_SPACE}/{}/{}/{}/{}/NN/{}/{}/{}",
        node.domain,
        node.session,
        node.node_id,
        node.node_id,
        mangled_or_percent(&node.enclave),
        mangled_or_percent(&node.namespace),
        mangle(&node.name)
    )
}

/// An endpoint's liveliness token.
pub fn endpoint_token(node: &NodeInfo, endpoint: &EndpointInfo) -> String {
    format!(
        "{ADMIN_SPACE}/{}/{}/{}/{}/{}/{}/{}/{}/{}/{}/{}/{}",
        node.domain,
        node.session,
        node.node_id,
        endpoint.id,
        endpoint.kind.as_str(),
        mangled_or_percent(&node.enclave),
        mangled_or_percent(&node.namespace),
        mangle(&node.name),
        mangle(&endpoint.qualified_name),
        mangle(&endpoint.dds_type),
        mangle(&endpoint.hash),
        endpoint.qos.keyexpr()
    )
}

/// A token read back: the node, and the endpoint when it is not a node's.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Token {
    pub node: NodeInfo,
    pub endpoint: Option<EndpointInfo>,
}

/// Why a token was not read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("not an rmw_zenoh liveliness token: {0}")]
pub struct TokenError(pub &'static str);

fn demangle(text: &str) -> String {
    text.replace('%', "/")
}

/// Reads a token as rmw_zenoh's `Entity::make` does (9 parts for a node, 13 for an
/// endpoint, none empty).
pub fn parse_token(token: &str) -> Result<Token, TokenError> {
    let parts: Vec<&str> = token.split('/').collect();
    if parts.len() != 9 && parts.len() != 13 {
        return Err(TokenError("it has neither 9 nor 13 parts"));
    }
    if parts.iter().any(|p| p.is_empty()) {
        return Err(TokenError("a part is empty"));
    }
    if parts[0] != ADMIN_SPACE {
        return Err(TokenError("it is not under @ros2_lv"));
    }
    let number = |s: &str| {
        s.parse::<u32>()
            .map_err(|_| TokenError("an id is not a number"))
    };
    let kind = EntityKind::parse(parts[5]).ok_or(TokenError("unknown entity kind"))?;
    let enclave = demangle(parts[6]);
    let node = NodeInfo {
        domain: number(parts[1])?,
        session: parts[2].to_owned(),
        node_id: number(parts[3])?,
        namespace: demangle(parts[7]),
        name: demangle(parts[8]),
        enclave: if enclave == "/" {
            String::new()
        } else {
            enclave
        },
    };
    let endpoint = match (kind, parts.len()) {
        (EntityKind::Node, 9) => None,
        (EntityKind::Node, _) => return Err(TokenError("a node token with endpoint parts")),
        (_, 13) => Some(EndpointInfo {
            id: number(parts[4])?,
            kind,
            qualified_name: demangle(parts[9]),
            dds_type: demangle(parts[10]),
            hash: demangle(parts[11]),
            qos: Qos::parse(parts[12]).ok_or(TokenError("its QoS field is not one"))?,
        }),
        _ => return Err(TokenError("an endpoint token without its endpoint parts")),
    };
    Ok(Token { node, endpoint })
}

/// An entity's 16-byte GID: the first 16 bytes of the SHA-256 of its liveliness token.
/// rmw_zenoh hashes the token too (with XXH3-128); GIDs are only ever compared for
/// equality, so any stable, unique 16 bytes do.
pub fn gid(token: &str) -> [u8; 16] {
    let digest = Sha256::digest(token.as_bytes());
    let mut gid = [0u8; 16];
    gid.copy_from_slice(&digest[..16]);
    gid
}

#[cfg(test)]
mod tests {
    use super::*;

    const STRING_HASH: &str =
        "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18";

    fn talker() -> NodeInfo {
        NodeInfo {
            domain: 2,
            session: "8b20917502ee955ac4476e0266340d5c".into(),
            node_id: 0,
            namespace: "/".into(),
            name: "talker".into(),
            enclave: String::new(),
        }
    }

    /// The examples of rmw_zenoh's design document, written and read back.
    #[test]
    fn tokens_are_rmw_zenoh_s() {
        let node = talker();
        assert_eq!(
            node_token(&node),
            "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/0/NN/%/%/talker"
        );
        let publisher = EndpointInfo {
            id: 10,
            kind: EntityKind::Publisher,
            qualified_name: "/chatter".into(),
            dds_type: "std_msgs::msg::dds_::String_".into(),
            hash: STRING_HASH.into(),
            qos: Qos {
                depth: 7,
                ..Qos::STREAM
            },
        };
        let token = endpoint_token(&node, &publisher);
        assert_eq!(
            token,
            format!("@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/std_msgs::msg::dds_::String_/{STRING_HASH}/::,7:,:,:,,")
        );
        assert_eq!(
            parse_token(&token),
            Ok(Token {
                node: node.clone(),
                endpoint: Some(publisher)
            })
        );
        assert_eq!(
            parse_token(&node_token(&node)),
            Ok(Token {
                node,
                endpoint: None
            })
        );
    }

    #[test]
    fn qos_fields_round_trip() {
        assert_eq!(Qos::LATCHED.keyexpr(), ":1:,1:,:,:,,");
        assert_eq!(Qos::SERVICE.keyexpr(), "::,10:,:,:,,");
        let best = Qos {
            reliability: Reliability::BestEffort,
            durability: Durability::Volatile,
            depth: DEFAULT_DEPTH,
        };
        assert_eq!(best.keyexpr(), "2::,:,:,:,,");
        for qos in [Qos::LATCHED, Qos::SERVICE, best] {
            assert_eq!(Qos::parse(&qos.keyexpr()), Some(qos));
        }
        assert_eq!(
            Qos::parse("::,10:1,0:,:,,"),
            None,
            "a deadline is not roam's"
        );
        assert_eq!(Qos::parse("garbage"), None);
    }

    #[test]
    fn keys_and_names() {
        assert_eq!(
            entity_key(0, "/map", "nav_msgs::msg::dds_::OccupancyGrid_", "RIHS01_x"),
            "0/map/nav_msgs::msg::dds_::OccupancyGrid_/RIHS01_x"
        );
        assert_eq!(qualify("/", "map").as_deref(), Ok("/map"));
        assert_eq!(
            qualify("/site1", "r1/plan").as_deref(),
            Ok("/site1/r1/plan")
        );
        assert_eq!(qualify("/site1", "/map").as_deref(), Ok("/map"));
        for bad in ["", "a//b", "a/*", "1abc", "a b", "map/"] {
            assert!(qualify("/", bad).is_err(), "{bad:?}");
        }
        assert!(check_namespace("/").is_ok() && check_namespace("/a/b_2").is_ok());
        for bad in ["", "a", "/a/", "/a/**", "//"] {
            assert!(check_namespace(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn malformed_tokens_are_refused() {
        for bad in [
            "@ros2_lv/0/z/0/0/NN/%/%",
            "@ros2_lv/0/z/0/0/XX/%/%/n",
            "@other/0/z/0/0/NN/%/%/n",
            "@ros2_lv/x/z/0/0/NN/%/%/n",
            "@ros2_lv/0/z/0/1/MP/%/%/n/%t/T/H/nonsense",
            "@ros2_lv/0/z/0/0/NN/%/%/n/%t/T/H/::,:,:,:,,",
        ] {
            assert!(parse_token(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn gids_differ_per_token() {
        assert_ne!(gid("a"), gid("b"));
        assert_eq!(gid("a"), gid("a"));
    }
}
