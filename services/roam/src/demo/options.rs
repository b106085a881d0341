//! How the demo runs: its options, the live view's, and the fixed choices it plans and
//! drives with.

use std::path::PathBuf;

use roam_controller::params::ApfParams;
use roam_mission::site::Site;

/// How the demo runs.
#[derive(Debug, Clone)]
pub struct DemoOptions {
    pub out_dir: PathBuf,
    /// The sim's real-time factor.
    pub rate: f64,
    pub seed: u64,
    /// The key root (a unique one lets several demos share a machine).
    pub root: Option<String>,
    /// The live view and the recording.
    pub view: LiveView,
    /// Offer the demo to ROS 2 (`roam ros2` in the stack).
    pub ros2: Option<roam_ros2::node::Ros2Config>,
    /// The stack router's endpoint, where other processes connect (a ROS 2 system
    /// over rmw_zenoh, `roam plan`, a Zenoh client); a free loopback port when `None`.
    pub listen: Option<String>,
    /// The world and the robot's day: the built-in day, or a user's Nav2 map and day
    /// file ([`roam_mission::site`]).
    pub site: Site,
}

impl Default for DemoOptions {
    fn default() -> Self {
        DemoOptions {
            out_dir: PathBuf::from("roam-demo"),
            rate: 20.0,
            seed: 0,
            root: None,
            view: LiveView::default(),
            ros2: None,
            listen: None,
            site: Site::builtin_day(),
        }
    }
}

/// The live view of a demo, and its recording.
#[derive(Debug, Clone, Default)]
pub struct LiveView {
    /// Serve the live view (a Foxglove WebSocket server) here while the demo runs.
    pub listen: Option<std::net::SocketAddr>,
    /// Record the run to this MCAP file.
    pub record: Option<PathBuf>,
    /// Who may connect to the live view.
    pub access: roam_view::Access,
}

/// The PEB cost the demo's executive plans with (the planner's W_loc, as in `roam
/// reproduce mission`): paths through the poorly covered room cost information.
pub const DEMO_W_LOC: f64 = 2000.0;

/// The controller's parameters for the built-in world: [`ApfParams::indoor`].
pub fn indoor_apf() -> ApfParams {
    ApfParams::indoor()
}
