//! How the two sessions meet, and what is timed between them.

use serde::Serialize;

/// How the two sessions meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Topology {
    /// Two peers, the receiver listening on `tcp/127.0.0.1:<port>`, the sender
    /// connected to it.
    PeerTcp,
    /// Two clients of a router on `tcp/127.0.0.1:<port>`.
    RouterTcp,
    /// [`Topology::PeerTcp`] over `tls/…`.
    PeerTls,
    /// [`Topology::RouterTcp`] over `tls/…`.
    RouterTls,
}

impl Topology {
    pub const ALL: [Topology; 4] = [
        Topology::PeerTcp,
        Topology::RouterTcp,
        Topology::PeerTls,
        Topology::RouterTls,
    ];

    pub(super) fn tls(self) -> bool {
        matches!(self, Topology::PeerTls | Topology::RouterTls)
    }

    pub(super) fn via_router(self) -> bool {
        matches!(self, Topology::RouterTcp | Topology::RouterTls)
    }
}

/// What is timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Operation {
    /// A put, to the receiver's subscriber reading it.
    Put,
    /// A get, to the sender reading the receiver's reply.
    Get,
}
