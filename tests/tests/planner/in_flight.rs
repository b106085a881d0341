//! Plans kept in flight for the tests of progress, cancel and the CPU budget: a request
//! sent in the background with its progress subscribed first, and the tokens used.

use super::*;

pub(crate) type ProgressSubscriber =
    zenoh::pubsub::Subscriber<zenoh::handlers::FifoChannelHandler<zenoh::sample::Sample>>;

/// Sends `request` (which names its id) in the background, with a subscriber to its
/// progress declared first.
pub(crate) async fn start_plan(
    client: &Requester,
    root: &str,
    request: PlanRequest,
) -> (
    ProgressSubscriber,
    tokio::task::JoinHandle<Result<Plan, ClientError>>,
) {
    let id = request.request_id.clone().expect("a named request");
    let subscriber = within(
        "subscribe",
        client
            .session()
            .declare_subscriber(keys::planner_progress(root, &id)),
    )
    .await
    .expect("progress subscriber");
    // The plans started here take longer than a harness client's 5 s.
    let client = Requester::new(client.session().clone(), Duration::from_secs(60));
    let root = root.to_owned();
    let pending = tokio::spawn(async move {
        client
            .request::<PlanRequest, Plan>(&keys::planner_plan(&root), Some(&request))
            .await
    });
    (subscriber, pending)
}

/// A plan that runs until it is cancelled (50,000 generations: a cost of 2e9, inside
/// `max_plan_cost`; 30 s of the CPU budget), cancellable with `token`.
pub(crate) fn endless(id: &str, token: Option<&str>) -> PlanRequest {
    PlanRequest {
        request_id: Some(id.into()),
        cancel_token: token.map(str::to_owned),
        params: GaOverrides {
            max_generations: Some(50_000),
            ..GaOverrides::default()
        },
        ..request([-8.0, -8.0], [6.0, -7.0], 80.0, 1)
    }
}

/// Starts [`endless`], with a subscriber to its progress.
pub(crate) async fn start_endless_plan(
    client: &Requester,
    root: &str,
    id: &str,
    token: Option<&str>,
) -> (
    ProgressSubscriber,
    tokio::task::JoinHandle<Result<Plan, ClientError>>,
) {
    start_plan(client, root, endless(id, token)).await
}

/// How long a plan may take to report its first progress. Three plans start at once on
/// three workers in a debug build; beside the rest of the test suite on two cores the
/// first report once took longer than the harness's [`roam_tests::STEP`]. What these
/// tests check is what a cancel does, not how fast a plan starts.
pub(crate) const FIRST_PROGRESS: Duration = Duration::from_secs(60);

/// Waits for the first progress message of a plan: it is planning.
pub(crate) async fn planning(subscriber: &ProgressSubscriber) {
    tokio::time::timeout(FIRST_PROGRESS, subscriber.recv_async())
        .await
        .expect("no progress from the plan within FIRST_PROGRESS")
        .expect("the plan is planning");
}

pub(crate) const TOKEN_A: &str = "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa";
pub(crate) const TOKEN_B: &str = "bbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbb";
pub(crate) const TOKEN_C: &str = "cccccccccccccccccccccccccccccccc";
/// Right length, right alphabet, wrong secret.
pub(crate) const GUESS: &str = "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaab";
