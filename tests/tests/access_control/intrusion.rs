//! What an intruder tries and the checks that it had no effect: the router refusing
//! sessions without the right credentials (a robot's generated config, without them or
//! with a wrong password), the `Watch` on the robot, the map server's
//! versions and two spies with the sim's and the planner's rights, and the
//! `assert_intrusion_*` checks run against it.

use std::time::Duration;

use roam_proto::cells::Cells;
use roam_proto::map::{
    DeleteLayer, Layer, LayerChange, LayerDeleted, LayerList, LayerUpdate, LoadMap, UpdateAck,
};
use roam_proto::sim::RobotCommand;
use roam_proto::{encode, keys};
use roam_runtime::{ClientError, Requester};
use roam_tests::{repo_path, within, Harness};
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;

use crate::observe::{drain, put, sim_status, step_and_locate, subscribe, versions};
use crate::site::{credentials, user_config, Secrets};
use crate::{ROBOT, ROOT};

/// A free layer the operator (a map writer) creates, so that an intruder's deletion of it
/// is one the map server would accept.
pub(crate) const SCRATCH: &str = "scratch";

/// How long a query whose reply can never come is waited for (Zenoh in fact ends a
/// query the router drops at once, with no reply).
pub(crate) const DENIED_QUERY_WAIT: Duration = Duration::from_millis(1500);

/// What the test watches: the robot (through the sim), the map server's versions, and
/// two spies that hold the sim's and the planner's credentials, so they receive what the
/// real sim and a real planner would (the sim itself drops commands whose key names no
/// robot, and the map server does not subscribe to layers).
pub(crate) struct Watch {
    pub(crate) operator: Requester,
    pub(crate) sim_spy: Subscriber<FifoChannelHandler<Sample>>,
    pub(crate) planner_spy: Subscriber<FifoChannelHandler<Sample>>,
    inflated: Layer,
    _spy_sessions: Vec<Requester>,
}

impl Watch {
    /// The operator (having checked the built-in world has its robot), the `inflated`
    /// layer a forgery is made from, the free layer [`SCRATCH`] (created by the
    /// operator, a map writer), and the spies.
    pub(crate) async fn start(harness: &Harness) -> Self {
        let operator = harness.client_as("operator").await;
        let status = sim_status(&operator).await;
        assert!(
            status.robots.iter().any(|r| r.name == ROBOT),
            "the built-in world has '{ROBOT}': {status:?}"
        );
        let inflated: Layer = within(
            "inflated layer",
            operator.request::<Layer, Layer>(&keys::map_layer(ROOT, "inflated"), None),
        )
        .await
        .expect("the operator may read a layer");
        let scratch = LayerUpdate {
            base_version: 0,
            change: LayerChange::Replace {
                meta: inflated.meta,
                cells: Cells::F32(vec![0.5; inflated.meta.cell_count() as usize]),
            },
            world: None,
        };
        within(
            "scratch layer",
            operator.request::<LayerUpdate, UpdateAck>(
                &keys::map_update(ROOT, SCRATCH),
                Some(&scratch),
            ),
        )
        .await
        .expect("the operator may create a layer");
        // The spies have sessions of their own: a session's own puts reach its own
        // subscribers without passing the router.
        let spy_sessions = vec![
            harness.client_as("sim").await,
            harness.client_as("planner").await,
        ];
        let sim_spy = subscribe(&spy_sessions[0], &keys::robot_command_any(ROOT)).await;
        let planner_spy = subscribe(&spy_sessions[1], &keys::map_layer_any(ROOT)).await;
        Self {
            operator,
            sim_spy,
            planner_spy,
            inflated,
            _spy_sessions: spy_sessions,
        }
    }
}

/// Everything an intruder (a session without a right to it) tries: command the robot on
/// its own key, on a robot wildcard and on `roam/**`; publish a forged `inflated` layer
/// with a huge version; update a layer (the derived `inflated`, which the server would
/// refuse anyway, and `occupancy`, which it would accept); delete the free layer
/// [`SCRATCH`] at its version (which it would accept); load a map. Asserts that none of
/// it had any effect.
pub(crate) async fn assert_intrusion_has_no_effect(who: &str, intruder: &Requester, watch: &Watch) {
    let before = versions(&watch.operator).await;
    let at_before = step_and_locate(&watch.operator).await;
    drain(&watch.sim_spy);
    drain(&watch.planner_spy);

    let command = encode(&RobotCommand {
        u: [1.0, 1.0],
        step: None,
    });
    put(intruder, &keys::robot_command(ROOT, ROBOT), command.clone()).await;
    put(intruder, &keys::robot_command_any(ROOT), command.clone()).await;
    put(intruder, &format!("{ROOT}/**"), command).await;
    let forged = Layer {
        version: 1_000_000_000,
        cells: match &watch.inflated.cells {
            Cells::I8(v) => Cells::I8(vec![0; v.len()]),
            Cells::U8(v) => Cells::U8(vec![0; v.len()]),
            Cells::F32(v) => Cells::F32(vec![0.0; v.len()]),
        },
        ..watch.inflated.clone()
    };
    put(
        intruder,
        &keys::map_layer(ROOT, "inflated"),
        encode(&forged),
    )
    .await;

    let occupancy_version = before.get("occupancy").copied().unwrap_or(0);
    let clear_occupancy = LayerUpdate {
        base_version: occupancy_version,
        change: LayerChange::SetCells {
            cells: vec![roam_proto::map::CellWrite {
                x: 0,
                y: 0,
                value: 0.0,
            }],
        },
        world: None,
    };
    let overwrite_inflated = LayerUpdate {
        base_version: before.get("inflated").copied().unwrap_or(0),
        change: LayerChange::Replace {
            meta: forged.meta,
            cells: forged.cells.clone(),
        },
        world: None,
    };
    let scratch_version = before.get(SCRATCH).copied();
    assert!(
        scratch_version.is_some(),
        "the layer to delete exists: {before:?}"
    );
    let delete_scratch = DeleteLayer {
        base_version: scratch_version.unwrap_or(0),
    };
    let load = LoadMap {
        path: repo_path("config/scenarios/es1.yaml").display().to_string(),
        base_version: None,
    };
    let asker = Requester::new(intruder.session().clone(), DENIED_QUERY_WAIT);
    let update_inflated_key = keys::map_update(ROOT, "inflated");
    let update_occupancy_key = keys::map_update(ROOT, "occupancy");
    let load_key = keys::map_load(ROOT);
    let delete_key = keys::map_delete(ROOT, SCRATCH);
    let (inflated, occupancy, deleted, loaded) = within("intruder queries", async {
        tokio::join!(
            asker
                .request::<LayerUpdate, UpdateAck>(&update_inflated_key, Some(&overwrite_inflated)),
            asker.request::<LayerUpdate, UpdateAck>(&update_occupancy_key, Some(&clear_occupancy)),
            asker.request::<DeleteLayer, LayerDeleted>(&delete_key, Some(&delete_scratch)),
            asker.request::<LoadMap, LayerList>(&load_key, Some(&load)),
        )
    })
    .await;
    for (what, outcome) in [
        ("update inflated", inflated.map(|_| ())),
        ("update occupancy", occupancy.map(|_| ())),
        ("delete a free layer", deleted.map(|_| ())),
        ("load a map", loaded.map(|_| ())),
    ] {
        assert!(
            matches!(outcome, Err(ClientError::NoReply { .. })),
            "{who}: '{what}' must never reach the map server (no reply at all), got {outcome:?}"
        );
    }

    let at_after = step_and_locate(&watch.operator).await;
    assert_eq!(
        at_after, at_before,
        "{who}: the robot moved on commands it must never receive"
    );
    assert_eq!(
        drain(&watch.sim_spy),
        Vec::<String>::new(),
        "{who}: a command reached a session with the sim's rights"
    );
    assert_eq!(
        drain(&watch.planner_spy),
        Vec::<String>::new(),
        "{who}: a forged layer reached a session with the planner's rights"
    );
    assert_eq!(
        versions(&watch.operator).await,
        before,
        "{who}: the map server's layers changed"
    );
}

/// The operator reads every publication, but its commands (on the robot's key, a robot
/// wildcard or `roam/**`) never reach the sim.
pub(crate) async fn assert_intrusion_has_no_effect_on_robot(who: &str, watch: &Watch) {
    let at_before = step_and_locate(&watch.operator).await;
    drain(&watch.sim_spy);
    let command = encode(&RobotCommand {
        u: [1.0, 1.0],
        step: None,
    });
    for key in [
        keys::robot_command(ROOT, ROBOT),
        keys::robot_command_any(ROOT),
        format!("{ROOT}/**"),
    ] {
        put(&watch.operator, &key, command.clone()).await;
    }
    let at_after = step_and_locate(&watch.operator).await;
    assert_eq!(at_after, at_before, "{who}: the robot moved");
    assert_eq!(
        drain(&watch.sim_spy),
        Vec::<String>::new(),
        "{who}: a command reached a session with the sim's rights"
    );
}

/// The router's authentication: a session without credentials or with a wrong password
/// is refused, and the same config with the right credentials opens.
pub(crate) async fn assert_only_the_right_credentials_open(secrets: &Secrets, endpoint: &str) {
    // No credentials (TLS with the site CA, no user/password) or a wrong password: the
    // router refuses the session while it opens. (`connect/timeout_ms: 0` so the refused
    // client gives up instead of retrying as deployed services do.)
    let user = "controller-robot";
    let give_up = "connect/timeout_ms:0".to_owned();
    let with = |mut settings: Vec<String>| {
        settings.push(give_up.clone());
        user_config(secrets, endpoint, user, &settings)
    };
    let anonymous = with(credentials(None));
    let refused = within("anonymous open", roam_runtime::session::open(anonymous)).await;
    assert!(
        refused.is_err(),
        "a session without credentials must be refused at open"
    );
    let wrong = with(credentials(Some((user, "not-the-password"))));
    let refused = within("wrong password open", roam_runtime::session::open(wrong)).await;
    assert!(
        refused.is_err(),
        "a session with a wrong password must be refused at open"
    );
    // ... while the generated config itself opens (so the refusals above are the
    // authentication's, not a TLS or config problem).
    let right = with(Vec::new());
    let accepted = within("right password open", roam_runtime::session::open(right))
        .await
        .unwrap_or_else(|e| panic!("{user}'s generated config opens a session: {e}"));
    accepted.close().await.expect("close");
}
