//! The client side of the planner: find the live instances and spread plans over them.
//!
//! Zenoh sends a query on a key several queryables serve to one nearest instance
//! (failover, not load sharing). So each instance also answers on its own key
//! `<root>/planner/instance/<instance>/plan` and announces itself with the liveliness
//! token `<root>/@live/planner/<instance>`. The client lists the tokens, takes the
//! instances in turn (round robin), and moves on to the next one when an instance is
//! busy, stopping or gone. Any language can do the same: a liveliness `get` on
//! `<root>/@live/planner/*`, then a `get` on the chosen instance's key.
//!
//! Every request this client sends carries a request id and a secret `cancel_token`,
//! fresh and random for each request unless the caller set them ([`PlanTicket`]): only
//! the holder of the token can cancel the plan ([`PlannerClient::cancel`]). A plan whose
//! future is dropped before its reply (the caller gave up) is cancelled with its token,
//! so the planner does not keep computing a path nobody waits for.
//!
//! Every request names its client (`?client=<name>` on the key, by default this
//! session's Zenoh id), so that each planner instance gives each client its fair share
//! of its queue ([`crate::queue`]).
//!
//! A client for one robot ([`PlannerClient::for_robot`]: the robot's mission executive)
//! asks and cancels on that robot's keys (`<root>/planner/robot/<id>/plan`,
//! `…/instance/<instance>/robot/<id>/plan`, `<root>/planner/robot/<id>/cancel/<request_id>`;
//! [`crate::scope`]), so a router's access control can give each robot's credentials its
//! own robot's plans only.

use roam_runtime::Delivery;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use roam_proto::planner::{CancelPlan, Plan, PlanRequest};
use roam_proto::{encode, keys, ErrorCode};
use roam_runtime::{ClientError, Requester};

use crate::token::random_hex128;

/// Extra time a client waits beyond the plan's own deadline for the reply.
pub const REPLY_MARGIN: Duration = Duration::from_secs(10);

#[derive(Debug)]
pub struct PlannerClient {
    session: zenoh::Session,
    root: String,
    /// The robot whose plans this client asks for; `None`: the shared keys.
    robot: Option<String>,
    /// The name sent for the queue's fair share.
    client: String,
    next: AtomicUsize,
}

/// What cancels one plan: its request id and its secret token. Keep it to yourself:
/// whoever holds it can cancel the plan.
#[derive(Clone)]
pub struct PlanTicket {
    pub request_id: String,
    token: String,
}

impl std::fmt::Debug for PlanTicket {
    // The token is a secret: never in a debug print.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlanTicket")
            .field("request_id", &self.request_id)
            .finish_non_exhaustive()
    }
}

impl PlanTicket {
    /// Gives `request` a fresh random request id and cancel token where it has none
    /// ([`random_hex128`]: 128 bits each), and returns what cancels it.
    pub fn issue(request: &mut PlanRequest) -> PlanTicket {
        let request_id = request.request_id.get_or_insert_with(random_hex128).clone();
        let token = request
            .cancel_token
            .get_or_insert_with(random_hex128)
            .clone();
        PlanTicket { request_id, token }
    }

    /// The cancel message for this plan.
    pub fn cancel_message(&self) -> CancelPlan {
        CancelPlan {
            request_id: self.request_id.clone(),
            token: Some(self.token.clone()),
        }
    }
}

/// Cancels a plan when dropped before [`CancelOnDrop::disarm`]: the caller stopped
/// waiting. The put is spawned on the current runtime (a drop cannot await); best
/// effort, like any cancel.
struct CancelOnDrop<'a> {
    client: &'a PlannerClient,
    ticket: Option<PlanTicket>,
}

impl CancelOnDrop<'_> {
    fn disarm(mut self) {
        self.ticket = None;
    }
}

impl Drop for CancelOnDrop<'_> {
    fn drop(&mut self) {
        let Some(ticket) = self.ticket.take() else {
            return;
        };
        let Ok(runtime) = tokio::runtime::Handle::try_current() else {
            return;
        };
        let session = self.client.session.clone();
        let key = self.client.cancel_key(&ticket.request_id);
        let message = encode(&ticket.cancel_message());
        // Delivered: a lost cancel keeps an instance busy until the plan's deadline.
        runtime.spawn(async move {
            roam_runtime::publish_bytes(&session, &key, message, Delivery::Reliable).await;
        });
    }
}

impl PlannerClient {
    /// A client named by its session's Zenoh id.
    pub fn new(session: zenoh::Session, root: &str) -> Self {
        PlannerClient {
            client: session.zid().to_string(),
            session,
            root: root.to_owned(),
            robot: None,
            next: AtomicUsize::new(0),
        }
    }

    /// A client that asks for `robot`'s plans, on the robot's own plan and cancel keys.
    pub fn for_robot(session: zenoh::Session, root: &str, robot: &str) -> Self {
        PlannerClient {
            robot: Some(robot.to_owned()),
            ..PlannerClient::new(session, root)
        }
    }

    /// The key every instance answers on (used when no instance is seen).
    fn shared_key(&self) -> String {
        match &self.robot {
            Some(robot) => keys::planner_robot_plan(&self.root, robot),
            None => keys::planner_plan(&self.root),
        }
    }

    /// The key `instance` alone answers on.
    fn instance_key(&self, instance: &str) -> String {
        match &self.robot {
            Some(robot) => keys::planner_robot_plan_at(&self.root, instance, robot),
            None => keys::planner_plan_at(&self.root, instance),
        }
    }

    /// The key a cancel of `request_id` goes to.
    fn cancel_key(&self, request_id: &str) -> String {
        match &self.robot {
            Some(robot) => keys::planner_robot_cancel(&self.root, robot, request_id),
            None => keys::planner_cancel(&self.root, request_id),
        }
    }

    /// The key `key` with this client's name as its `client` parameter.
    fn named(&self, key: String) -> String {
        format!("{key}?{}={}", crate::service::CLIENT_PARAMETER, self.client)
    }

    /// The instances that hold a liveliness token now, sorted by name.
    pub async fn live_instances(&self) -> Result<Vec<String>, ClientError> {
        let key = keys::liveliness_of(&self.root, crate::service::SERVICE_NAME);
        let replies = self
            .session
            .liveliness()
            .get(&key)
            .timeout(Duration::from_secs(2))
            .await
            .map_err(|e| ClientError::Zenoh {
                key: key.clone(),
                reason: e.to_string(),
            })?;
        let mut instances = Vec::new();
        while let Ok(reply) = replies.recv_async().await {
            if let Ok(sample) = reply.result() {
                if let Some(instance) = sample.key_expr().as_str().rsplit('/').next() {
                    instances.push(instance.to_owned());
                }
            }
        }
        instances.sort();
        instances.dedup();
        Ok(instances)
    }

    /// Cancels the plan of `ticket` on every instance: the one planning it stops and
    /// replies with its best path so far (`stop_reason: cancelled`).
    pub async fn cancel(&self, ticket: &PlanTicket) -> Result<(), ClientError> {
        let key = self.cancel_key(&ticket.request_id);
        self.session
            .put(&key, encode(&ticket.cancel_message()))
            .await
            .map_err(|e| ClientError::Zenoh {
                key,
                reason: e.to_string(),
            })
    }

    /// Asks one live instance after another (round robin) until one plans; an instance
    /// that is busy, stopping or silent is skipped. Refusals about the request itself
    /// (a blocked goal, a short budget) come back at once. The request gets a fresh id
    /// and cancel token where it has none ([`PlanTicket::issue`]; to cancel it
    /// yourself, issue the ticket first), and is cancelled if this future is dropped
    /// before the reply.
    pub async fn plan(&self, request: &PlanRequest) -> Result<Plan, ClientError> {
        let mut request = request.clone();
        let ticket = PlanTicket::issue(&mut request);
        let guard = CancelOnDrop {
            client: self,
            ticket: Some(ticket),
        };
        let result = self.plan_on_any(&request).await;
        guard.disarm();
        result
    }

    async fn plan_on_any(&self, request: &PlanRequest) -> Result<Plan, ClientError> {
        let instances = self.live_instances().await?;
        let timeout = Duration::from_secs_f64(request.deadline_s.clamp(0.0, 600.0)) + REPLY_MARGIN;
        let requester = Requester::new(self.session.clone(), timeout);
        if instances.is_empty() {
            // No token seen (yet): fall back to the shared key.
            return requester
                .request(&self.named(self.shared_key()), Some(request))
                .await;
        }
        let first = self.next.fetch_add(1, Ordering::Relaxed);
        let mut last_error = None;
        for k in 0..instances.len() {
            let instance = &instances[(first + k) % instances.len()];
            match requester
                .request(&self.named(self.instance_key(instance)), Some(request))
                .await
            {
                Ok(plan) => return Ok(plan),
                Err(ClientError::Refused(reply))
                    if !matches!(reply.code, ErrorCode::Busy | ErrorCode::Unavailable) =>
                {
                    return Err(ClientError::Refused(reply));
                }
                Err(e) => {
                    tracing::debug!(%instance, "planner instance skipped: {e}");
                    last_error = Some(e);
                }
            }
        }
        Err(last_error.unwrap_or_else(|| ClientError::NoReply {
            key: self.shared_key(),
            timeout,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::planner::{GaOverrides, PlannerModel, ShortestPathUse};

    fn request() -> PlanRequest {
        PlanRequest {
            request_id: None,
            cancel_token: None,
            start: [0.0, 0.0],
            goal: [1.0, 1.0],
            t_exec_s: 10.0,
            deadline_s: 1.0,
            model: PlannerModel::Model1,
            params: GaOverrides::default(),
            seed: 0,
            map_version: None,
            shortest: ShortestPathUse::Omit,
            seed_route: Vec::new(),
        }
    }

    #[test]
    fn every_request_gets_a_fresh_id_and_token_unless_it_has_them() {
        let (mut a, mut b) = (request(), request());
        let (ta, tb) = (PlanTicket::issue(&mut a), PlanTicket::issue(&mut b));
        assert_ne!(ta.request_id, tb.request_id);
        assert_ne!(a.cancel_token, b.cancel_token);
        let token = a.cancel_token.clone().expect("token");
        assert!(crate::token::check_token(&token).is_ok());
        assert_eq!(ta.cancel_message().token.as_deref(), Some(token.as_str()));
        assert_eq!(a.request_id.as_deref(), Some(ta.request_id.as_str()));
        // The caller's own id and token are kept.
        let mut own = PlanRequest {
            request_id: Some("trip-42".into()),
            cancel_token: Some("my-own-secret-token".into()),
            ..request()
        };
        let ticket = PlanTicket::issue(&mut own);
        assert_eq!(ticket.request_id, "trip-42");
        assert_eq!(
            ticket.cancel_message().token.as_deref(),
            Some("my-own-secret-token")
        );
        // A debug print never shows the token.
        assert!(!format!("{ticket:?}").contains("secret"));
    }
}
