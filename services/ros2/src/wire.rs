//! What roam offers a ROS 2 system, as rmw_zenoh endpoints: for each topic and service,
//! its name, its ROS type, its QoS, and so its Zenoh key and liveliness token.

use crate::hash::{self, UnknownType};
use crate::names::{self, EndpointInfo, EntityKind, NameError, NodeInfo, Qos};
use crate::types;

/// An endpoint roam declares (or, for the map input, subscribes as).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Endpoint {
    pub kind: EntityKind,
    /// `/map`, `/r1/plan`, `/roam/plan_downtime`.
    pub qualified_name: String,
    /// `nav_msgs/msg/OccupancyGrid` or `nav_msgs/srv/GetPlan`.
    pub ros_type: &'static str,
    pub qos: Qos,
    /// The Zenoh key of its samples or queries.
    pub key: String,
    /// Its liveliness token.
    pub token: String,
    /// Its 16-byte GID, in every attachment it writes.
    pub gid: [u8; 16],
}

/// Why an endpoint cannot be declared.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EndpointError {
    #[error(transparent)]
    Name(#[from] NameError),
    #[error(transparent)]
    Type(#[from] UnknownType),
}

/// The endpoint `name` (resolved against the node's namespace) of type `ros_type`.
pub fn endpoint(
    node: &NodeInfo,
    id: u32,
    kind: EntityKind,
    name: &str,
    ros_type: &'static str,
    qos: Qos,
) -> Result<Endpoint, EndpointError> {
    let qualified_name = names::qualify(&node.namespace, name)?;
    let is_service = matches!(kind, EntityKind::Service | EntityKind::Client);
    let hash = if is_service {
        hash::service_type_hash(ros_type)?
    } else {
        hash::message_type_hash(ros_type)?
    };
    let dds_type =
        types::dds_type_name(ros_type).ok_or_else(|| UnknownType(ros_type.to_owned()))?;
    let key = names::entity_key(node.domain, &qualified_name, &dds_type, &hash);
    let info = EndpointInfo {
        id,
        kind,
        qualified_name: qualified_name.clone(),
        dds_type,
        hash,
        qos,
    };
    let token = names::endpoint_token(node, &info);
    Ok(Endpoint {
        kind,
        gid: names::gid(&token),
        qualified_name,
        ros_type,
        qos,
        key,
        token,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_is_published_on_rmw_zenoh_s_key() {
        let node = NodeInfo {
            domain: 0,
            session: "0123abcd".into(),
            node_id: 0,
            namespace: "/".into(),
            name: "roam".into(),
            enclave: String::new(),
        };
        let map = endpoint(
            &node,
            1,
            EntityKind::Publisher,
            "map",
            types::OCCUPANCY_GRID,
            Qos::LATCHED,
        )
        .expect("map");
        assert_eq!(
            map.key,
            "0/map/nav_msgs::msg::dds_::OccupancyGrid_/RIHS01_8d348150c12913a31ee0ec170fbf25089e4745d17035792a1ba94d6f0bc0cfc7"
        );
        assert_eq!(
            map.token,
            "@ros2_lv/0/0123abcd/0/1/MP/%/%/roam/%map/nav_msgs::msg::dds_::OccupancyGrid_/RIHS01_8d348150c12913a31ee0ec170fbf25089e4745d17035792a1ba94d6f0bc0cfc7/:1:,1:,:,:,,"
        );
        let site = NodeInfo {
            domain: 7,
            namespace: "/site1".into(),
            ..node
        };
        let plan = endpoint(
            &site,
            2,
            EntityKind::Service,
            "roam/get_plan",
            types::GET_PLAN,
            Qos::SERVICE,
        )
        .expect("get_plan");
        assert!(
            plan.key
                .starts_with("7/site1/roam/get_plan/nav_msgs::srv::dds_::GetPlan_/RIHS01_"),
            "{}",
            plan.key
        );
        assert!(endpoint(
            &site,
            3,
            EntityKind::Publisher,
            "r 1/plan",
            types::PATH,
            Qos::LATCHED
        )
        .is_err());
    }
}
