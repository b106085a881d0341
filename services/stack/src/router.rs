//! A Zenoh router inside roam: `roam router` for a fleet (nothing else to install) and
//! the in-process router of `roam stack` and the tests.

use std::net::TcpListener;

use roam_proto::keys;
use roam_runtime::{session, SessionArgs, SessionError};

/// The largest query, in bytes, a roam router passes on to a service whose requests are
/// small (every queryable but the map server's): above the largest such cap
/// (localization's 4 MiB; the planner's and the sim's are 64 KiB, the ROS 2 node's
/// 16 KiB) and the attack test's 8 MiB of CDR to a ROS 2 service, so a request up to
/// this size still reaches its service and is refused there by name. A larger one ends
/// at the router with Zenoh's final reply and no answer: the client's `get` returns at
/// once, empty, and no service's link carries it. Without this, a stranger's 48 MB
/// queries streamed through the router to a service whose requests are at most 64 KiB,
/// and on a loaded machine the service's link could stall behind them
/// (`services/roam/tests/oversized.rs`). The map server's keys are not filtered: its cap
/// (`max_request_bytes`, 96 MiB by default) is its own, under
/// `roam_runtime::session::MAX_MESSAGE_BYTES`.
pub const EDGE_QUERY_BYTES: usize = 16 * 1024 * 1024;

/// The key expressions of every roam queryable that takes small requests, for any root
/// (`**`): what [`edge_filter`] covers.
pub fn small_request_keys() -> Vec<String> {
    let any = "**";
    vec![
        keys::planner_plan(any),
        keys::planner_plan_at(any, "*"),
        keys::planner_robot_plan(any, "*"),
        keys::planner_robot_plan_at(any, "*", "*"),
        keys::sim_control(any),
        keys::localization_peb(any),
        keys::mapper_status(any),
        // The ROS 2 node's services on rmw_zenoh's keys: <domain>/<name>/<type>/<hash>.
        format!("{any}/{}/**", roam_ros2::node::GET_PLAN),
        format!("{any}/{}/**", roam_ros2::node::PLAN_DOWNTIME),
    ]
}

/// Zenoh's `low_pass_filter` for a roam router: queries that come in larger than
/// [`EDGE_QUERY_BYTES`] to [`small_request_keys`] stop at the router.
pub fn edge_filter() -> serde_json::Value {
    serde_json::json!([{
        "id": "roam-edge",
        "flows": ["ingress"],
        "messages": ["query"],
        "key_exprs": small_request_keys(),
        "size_limit": EDGE_QUERY_BYTES,
    }])
}

/// A running router session and the endpoint clients connect to.
#[derive(Debug)]
pub struct Router {
    pub session: zenoh::Session,
    pub endpoint: String,
}

/// A free TCP port on loopback, found by binding port 0 and letting it go. Another
/// process could take it in between; [`Router::on_loopback`] retries for that reason.
pub fn free_loopback_port() -> std::io::Result<u16> {
    Ok(TcpListener::bind("127.0.0.1:0")?.local_addr()?.port())
}

impl Router {
    /// A router on `tcp/127.0.0.1:<free port>` with multicast scouting off: what the
    /// in-process stack and every integration test run around.
    pub async fn on_loopback() -> Result<Router, SessionError> {
        let mut last = None;
        for _ in 0..5 {
            let port = free_loopback_port()
                .map_err(|e| SessionError::Open(format!("no free loopback port: {e}")))?;
            let endpoint = format!("tcp/127.0.0.1:{port}");
            match Router::start(&SessionArgs::router_on(&endpoint), endpoint.clone()).await {
                Ok(router) => return Ok(router),
                Err(e) => last = Some(e),
            }
        }
        Err(last.unwrap_or_else(|| SessionError::Open("no router could be started".into())))
    }

    /// A router with the given session flags (mode forced to router).
    pub async fn start(args: &SessionArgs, endpoint: String) -> Result<Router, SessionError> {
        let mut args = args.clone();
        args.mode = Some("router".into());
        // The edge filter is the router's own layer, under `ZENOH_CONFIG` and `--cfg`: a
        // `low_pass_filter` the user gives there replaces it.
        let defaults = serde_json::json!({ "low_pass_filter": edge_filter() });
        let config = args.zenoh_config(Some(&defaults))?;
        let session = session::open(config).await?;
        Ok(Router { session, endpoint })
    }

    pub async fn close(self) {
        if let Err(e) = self.session.close().await {
            tracing::warn!("closing the router failed: {e}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use zenoh::key_expr::KeyExpr;

    fn covered(key: &str) -> bool {
        let key = KeyExpr::new(key.to_owned()).expect("key");
        small_request_keys()
            .into_iter()
            .any(|filter| KeyExpr::new(filter).expect("filter").includes(&key))
    }

    #[test]
    fn the_edge_covers_every_small_request_key_and_never_the_map_servers() {
        for root in ["roam", "site/a"] {
            assert!(covered(&keys::planner_plan(root)));
            assert!(covered(&keys::planner_plan_at(root, "planner-0")));
            assert!(covered(&keys::planner_robot_plan(root, "r1")));
            assert!(covered(&keys::planner_robot_plan_at(
                root,
                "planner-0",
                "r1"
            )));
            assert!(covered(&keys::sim_control(root)));
            assert!(covered(&keys::localization_peb(root)));
            assert!(covered(&keys::mapper_status(root)));
            for layer in ["x", "planner", "status", "peb"] {
                assert!(!covered(&keys::map_update(root, layer)), "{layer}");
                assert!(!covered(&keys::map_layer(root, layer)), "{layer}");
            }
        }
        assert!(covered(
            "0/roam/get_plan/nav_msgs::srv::dds_::GetPlan_/RIHS01_abc"
        ));
    }

    #[test]
    fn zenoh_takes_the_edge_filter() {
        let mut config = zenoh::Config::default();
        config
            .insert_json5("low_pass_filter", &edge_filter().to_string())
            .expect("Zenoh accepts the filter");
        let back = config.get_json("low_pass_filter").expect("read back");
        assert!(
            back.contains("roam-edge") && back.contains("16777216"),
            "{back}"
        );
    }

    #[test]
    fn a_users_own_filter_replaces_the_edge() {
        let defaults = serde_json::json!({ "low_pass_filter": edge_filter() });
        let mut args = SessionArgs::router_on("tcp/127.0.0.1:0");
        let config = args
            .zenoh_config_with(Some(&defaults), None)
            .expect("config");
        let ours = config.get_json("low_pass_filter").expect("filter");
        assert!(ours.contains("roam-edge"), "{ours}");
        args.cfg = vec!["low_pass_filter:[]".into()];
        let config = args
            .zenoh_config_with(Some(&defaults), None)
            .expect("config");
        let theirs = config.get_json("low_pass_filter").expect("filter");
        assert!(!theirs.contains("roam-edge"), "{theirs}");
    }
}
