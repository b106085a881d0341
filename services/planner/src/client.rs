//! The client side of the planner: find the live instances and spread plans over them.
//!
//! Zenoh sends a query on a key several queryables serve to one nearest instance
//! (failover, not load sharing). So each instance also answers on its own key
//! `<root>/planner/instance/<instance>/plan` and announces itself with the liveliness
//! token `<root>/@live/planner/<instance>`. The client lists the tokens, takes the
//! instances in turn (round robin), and moves on to the next one when an instance is
//! busy, stopping or gone. Any language can do the same: a liveliness `get` on
//! `<root>/@live/planner/*`, then a `get` on the chosen instance's key.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use roam_proto::planner::{Plan, PlanRequest};
use roam_proto::{keys, ErrorCode};
use roam_runtime::{ClientError, Requester};

/// Extra time a client waits beyond the plan's own deadline for the reply.
pub const REPLY_MARGIN: Duration = Duration::from_secs(10);

#[derive(Debug)]
pub struct PlannerClient {
    session: zenoh::Session,
    root: String,
    next: AtomicUsize,
}

impl PlannerClient {
    pub fn new(session: zenoh::Session, root: &str) -> Self {
        PlannerClient {
            session,
            root: root.to_owned(),
            next: AtomicUsize::new(0),
        }
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

    /// Asks one live instance after another (round robin) until one plans; an instance
    /// that is busy, stopping or silent is skipped. Refusals about the request itself
    /// (a blocked goal, a short budget) come back at once.
    pub async fn plan(&self, request: &PlanRequest) -> Result<Plan, ClientError> {
        let instances = self.live_instances().await?;
        let timeout = Duration::from_secs_f64(request.deadline_s.clamp(0.0, 600.0)) + REPLY_MARGIN;
        let requester = Requester::new(self.session.clone(), timeout);
        if instances.is_empty() {
            // No token seen (yet): fall back to the shared key.
            return requester
                .request(&keys::planner_plan(&self.root), Some(request))
                .await;
        }
        let first = self.next.fetch_add(1, Ordering::Relaxed);
        let mut last_error = None;
        for k in 0..instances.len() {
            let instance = &instances[(first + k) % instances.len()];
            match requester
                .request(&keys::planner_plan_at(&self.root, instance), Some(request))
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
            key: keys::planner_plan(&self.root),
            timeout,
        }))
    }
}
