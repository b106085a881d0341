//! A ROS 2 action client on rmw_zenoh's wire: the three services of an action
//! (`send_goal`, `get_result`, `cancel_goal`) called as rmw_zenoh's clients call a
//! service (a `get` on the service's key, target all-complete, no consolidation, the
//! request's CDR and the 33-byte attachment with this client's sequence number and GID),
//! each with its `SC` liveliness token so the ROS graph shows the client.

use std::sync::atomic::{AtomicI64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use serde::de::DeserializeOwned;
use serde::Serialize;
use zenoh::liveliness::LivelinessToken;
use zenoh::query::{ConsolidationMode, QueryTarget};

use super::error::Ros2Error;
use super::output::Output;
use crate::attachment::{self, Attachment};
use crate::msg::{CancelGoalRequest, CancelGoalResponse, GoalInfo, Time, Uuid};
use crate::names::{EntityKind, Qos};
use crate::types;
use crate::wire::Endpoint;

/// The largest reply read (a result with a path of a few thousand poses).
pub const MAX_REPLY_BYTES: usize = 4 * 1024 * 1024;

/// One service of an action, as its client.
#[derive(Debug)]
struct ServiceClient {
    endpoint: Endpoint,
    sequence: AtomicI64,
    _token: LivelinessToken,
}

impl ServiceClient {
    async fn declare(
        out: &Output,
        name: String,
        ros_type: &'static str,
    ) -> Result<ServiceClient, Ros2Error> {
        let endpoint = out.declared_endpoint(
            "action client",
            EntityKind::Client,
            &name,
            ros_type,
            Qos::SERVICE,
        )?;
        let token = out.token(&endpoint.token).await?;
        Ok(ServiceClient {
            endpoint,
            sequence: AtomicI64::new(0),
            _token: token,
        })
    }

    /// Calls the service with `request` and waits up to `within` for its response.
    async fn call<Req: Serialize, Resp: DeserializeOwned>(
        &self,
        session: &zenoh::Session,
        request: &Req,
        within: Duration,
    ) -> Result<Resp, String> {
        let payload = crate::cdr::encode(request).map_err(|e| e.to_string())?;
        let attachment = Attachment {
            sequence_number: self.sequence.fetch_add(1, Ordering::Relaxed) + 1,
            source_timestamp_ns: attachment::now_ns(),
            gid: self.endpoint.gid,
        };
        let key = &self.endpoint.key;
        let replies = session
            .get(key.clone())
            .payload(payload)
            .attachment(attachment.to_bytes().to_vec())
            .target(QueryTarget::AllComplete)
            .consolidation(ConsolidationMode::None)
            .timeout(within)
            .await
            .map_err(|e| format!("calling {}: {e}", self.endpoint.qualified_name))?;
        match replies.recv_async().await {
            Ok(reply) => match reply.result() {
                Ok(sample) => crate::cdr::decode(
                    &sample.payload().to_bytes(),
                    "action reply",
                    MAX_REPLY_BYTES,
                )
                .map_err(|e| format!("{}: {e}", self.endpoint.qualified_name)),
                Err(e) => Err(format!(
                    "{} answered with an error: {}",
                    self.endpoint.qualified_name,
                    String::from_utf8_lossy(&e.payload().to_bytes())
                )),
            },
            Err(_) => Err(format!(
                "{} did not answer within {within:?}: is the action server running?",
                self.endpoint.qualified_name
            )),
        }
    }
}

/// A client of one action: `send_goal` and `get_result` of `send_type` and
/// `result_type`, and action_msgs' `cancel_goal`.
#[derive(Debug, Clone)]
pub(crate) struct ActionClient {
    session: zenoh::Session,
    send_goal: Arc<ServiceClient>,
    get_result: Arc<ServiceClient>,
    cancel_goal: Arc<ServiceClient>,
}

impl ActionClient {
    /// The client of action `action` (a name in the node's namespace).
    pub(crate) async fn declare(
        out: &Output,
        action: &str,
        send_type: &'static str,
        result_type: &'static str,
    ) -> Result<ActionClient, Ros2Error> {
        let part = |p: &str| format!("{}/_action/{p}", action.trim_end_matches('/'));
        Ok(ActionClient {
            session: out.session().clone(),
            send_goal: Arc::new(ServiceClient::declare(out, part("send_goal"), send_type).await?),
            get_result: Arc::new(
                ServiceClient::declare(out, part("get_result"), result_type).await?,
            ),
            cancel_goal: Arc::new(
                ServiceClient::declare(out, part("cancel_goal"), types::CANCEL_GOAL).await?,
            ),
        })
    }

    /// Sends a goal (`request`, carrying its UUID); the server's acceptance.
    pub(crate) async fn send_goal<Req: Serialize>(
        &self,
        request: &Req,
        within: Duration,
    ) -> Result<crate::msg::SendGoalResponse, String> {
        self.send_goal.call(&self.session, request, within).await
    }

    /// The goal's result, once the server has it (it answers when the goal ends).
    pub(crate) async fn get_result<Resp: DeserializeOwned>(
        &self,
        goal_id: Uuid,
        within: Duration,
    ) -> Result<Resp, String> {
        let request = crate::msg::GetResultRequest { goal_id };
        self.get_result.call(&self.session, &request, within).await
    }

    /// Asks the server to cancel goal `goal_id`.
    pub(crate) async fn cancel(
        &self,
        goal_id: Uuid,
        within: Duration,
    ) -> Result<CancelGoalResponse, String> {
        let request = CancelGoalRequest {
            goal_info: GoalInfo {
                goal_id,
                stamp: Time::default(),
            },
        };
        self.cancel_goal.call(&self.session, &request, within).await
    }
}
