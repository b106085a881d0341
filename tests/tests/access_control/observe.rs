//! Looking at the site as the operator and as a spy: the sim's status, one sim step and
//! the robot's position, the map server's layer versions, the services alive, and
//! subscribing, draining and putting on a client's own session.

use std::collections::{BTreeMap, BTreeSet};
use std::time::Duration;

use roam_proto::keys;
use roam_proto::map::LayerList;
use roam_proto::sim::{SimControl, SimStatus};
use roam_runtime::Requester;
use roam_tests::{within, Harness};
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;

use crate::{ROBOT, ROOT};

/// Time for messages already sent on other sessions to reach the router and the sim
/// before a step, or every receiver: Zenoh orders messages per session, not across
/// sessions.
pub(crate) const SETTLE: Duration = Duration::from_millis(300);

pub(crate) async fn sim_status(operator: &Requester) -> SimStatus {
    within(
        "sim status",
        operator.request(&keys::sim_control(ROOT), Some(&SimControl::Status)),
    )
    .await
    .expect("the operator may ask the sim's status")
}

/// Steps the sim once (as the operator) and returns where the robot is.
pub(crate) async fn step_and_locate(operator: &Requester) -> [f64; 2] {
    tokio::time::sleep(SETTLE).await;
    let status: SimStatus = within(
        "sim step",
        operator.request(&keys::sim_control(ROOT), Some(&SimControl::Step { n: 1 })),
    )
    .await
    .expect("the operator may step the sim");
    status
        .robots
        .iter()
        .find(|r| r.name == ROBOT)
        .map(|r| r.at)
        .expect("the built-in world's robot")
}

pub(crate) async fn versions(operator: &Requester) -> BTreeMap<String, u64> {
    let list: LayerList = within(
        "layer list",
        operator.request::<LayerList, LayerList>(&keys::map_index(ROOT), None),
    )
    .await
    .expect("the operator may list the layers");
    list.layers
        .into_iter()
        .map(|l| (l.name, l.version))
        .collect()
}

pub(crate) async fn subscribe(
    client: &Requester,
    key: &str,
) -> Subscriber<FifoChannelHandler<Sample>> {
    within("subscribe", client.session().declare_subscriber(key))
        .await
        .expect("subscriber")
}

/// The keys of every sample a subscriber has received so far.
pub(crate) fn drain(subscriber: &Subscriber<FifoChannelHandler<Sample>>) -> Vec<String> {
    let mut keys = Vec::new();
    while let Ok(Some(sample)) = subscriber.try_recv() {
        keys.push(sample.key_expr().to_string());
    }
    keys
}

pub(crate) async fn put(client: &Requester, key: &str, payload: Vec<u8>) {
    // Zenoh's put succeeds locally whatever the router then does with it.
    within("put", client.session().put(key, payload))
        .await
        .expect("put");
}

/// The services whose liveliness tokens a client sees.
pub(crate) async fn alive_services(client: &Requester) -> Vec<String> {
    let tokens = within(
        "liveliness get",
        client
            .session()
            .liveliness()
            .get(keys::liveliness_all(ROOT))
            .timeout(Duration::from_secs(2)),
    )
    .await
    .expect("liveliness get");
    let mut alive = BTreeSet::new();
    while let Ok(reply) = within("liveliness reply", tokens.recv_async()).await {
        if let Ok(sample) = reply.result() {
            let key = sample.key_expr().as_str();
            if let Some(service) = key.split('/').nth(2) {
                alive.insert(service.to_owned());
            }
        }
    }
    alive.into_iter().collect()
}

/// A session with one user's credentials, subscribed to a key: where a message would
/// arrive if the router let it through.
pub(crate) struct Spy {
    pub(crate) user: &'static str,
    pub(crate) subscriber: Subscriber<FifoChannelHandler<Sample>>,
    _session: Requester,
}

impl Spy {
    pub(crate) async fn on(harness: &Harness, user: &'static str, key: &str) -> Spy {
        let session = harness.client_as(user).await;
        let subscriber = subscribe(&session, key).await;
        Spy {
            user,
            subscriber,
            _session: session,
        }
    }
}

/// Waits until `spy` receives a sample on `key`, and returns the keys of every sample it
/// received until then and within [`SETTLE`] after. A sender that ends with `key` shows
/// this way what else of its own reached the spy: anything it sent before would have
/// arrived before.
pub(crate) async fn heard_until(spy: &Spy, key: &str) -> Vec<String> {
    let mut heard = Vec::new();
    loop {
        let sample = within("a spy's sample", spy.subscriber.recv_async())
            .await
            .unwrap_or_else(|e| panic!("{} receives {key}: {e}", spy.user));
        heard.push(sample.key_expr().to_string());
        if sample.key_expr().as_str() == key {
            break;
        }
    }
    tokio::time::sleep(SETTLE).await;
    heard.extend(drain(&spy.subscriber));
    heard
}
