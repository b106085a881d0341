//! The node's fixed limits on what its config asks: the ROS domain id, the Nav2 robots
//! one node drives.

/// The largest ROS domain id (ROS 2 allows 0 to 232).
pub const MAX_DOMAIN_ID: u32 = 232;

/// The most Nav2 robots one node drives.
pub const MAX_NAV2_ROBOTS: usize = 64;
