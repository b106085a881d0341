//! Sending the storm: queries with bounded concurrency and a reply check each, and
//! puts.

use super::*;

#[derive(Debug, Default)]
pub(crate) struct Outcome {
    pub(crate) sent: usize,
    pub(crate) ok: usize,
    pub(crate) refused: usize,
    pub(crate) failures: Vec<String>,
}

pub(crate) fn show(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(300)]).into_owned();
    format!("{} bytes: {text:?}", bytes.len())
}

/// One query: exactly one reply within the timeout; a refusal for a payload that is not
/// the request; a refusal that decodes as `ErrorReply`; a success that decodes.
pub(crate) async fn query_once(
    session: &Session,
    key: &str,
    expects: Expects,
    bytes: Vec<u8>,
) -> Result<bool, String> {
    let must_refuse = expects.must_refuse(&bytes);
    let replies = session
        .get(key)
        .payload(bytes.clone())
        .timeout(QUERY_TIMEOUT)
        .await
        .map_err(|e| format!("get on {key} failed: {e}; payload {}", show(&bytes)))?;
    let wait = QUERY_TIMEOUT + Duration::from_secs(2);
    let first = tokio::time::timeout(wait, replies.recv_async())
        .await
        .map_err(|_| format!("HANG: no reply on {key}; payload {}", show(&bytes)))?
        .map_err(|_| format!("no reply on {key}; payload {}", show(&bytes)))?;
    let refused = match first.result() {
        Ok(sample) => {
            if must_refuse {
                return Err(format!(
                    "{key} accepted a payload that is not its request; payload {}",
                    show(&bytes)
                ));
            }
            let reply = sample.payload().to_bytes();
            if !expects.reply_decodes(&reply) {
                return Err(format!(
                    "{key} replied with something undecodable ({}); payload {}",
                    show(&reply),
                    show(&bytes)
                ));
            }
            false
        }
        Err(error) => {
            let reply = error.payload().to_bytes();
            if decode::<ErrorReply>(&reply).is_err() {
                return Err(format!(
                    "{key} refused without an ErrorReply ({}); payload {}",
                    show(&reply),
                    show(&bytes)
                ));
            }
            true
        }
    };
    // The stream ends once the service has answered: a second reply is a bug.
    match tokio::time::timeout(wait, replies.recv_async()).await {
        Ok(Err(_)) => Ok(refused),
        Ok(Ok(_)) => Err(format!("a second reply on {key}; payload {}", show(&bytes))),
        Err(_) => Err(format!(
            "HANG: the query on {key} never ended; payload {}",
            show(&bytes)
        )),
    }
}

pub(crate) async fn storm_queries(
    session: Session,
    targets: Vec<Target>,
    all: Arc<Vec<Vec<u8>>>,
    seed: u64,
) -> BTreeMap<String, Outcome> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let robots_added = AtomicU32::new(0);
    // Interleave the keys so every service is under load at the same time.
    let mut order: Vec<usize> = targets
        .iter()
        .enumerate()
        .flat_map(|(i, t)| std::iter::repeat_n(i, t.count))
        .collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    let targets = Arc::new(targets);
    let mut outcomes: BTreeMap<String, Outcome> = BTreeMap::new();
    let mut tasks = tokio::task::JoinSet::new();
    let record = |outcomes: &mut BTreeMap<String, Outcome>,
                  (key, result): (String, Result<bool, String>)| {
        let o = outcomes.entry(key).or_default();
        match result {
            Ok(true) => o.refused += 1,
            Ok(false) => o.ok += 1,
            Err(e) => o.failures.push(e),
        }
    };
    for i in order {
        let target = &targets[i];
        let bytes = bounded(
            target.expects,
            payload(&mut rng, target, &all),
            &robots_added,
        );
        outcomes.entry(target.key.clone()).or_default().sent += 1;
        while tasks.len() >= IN_FLIGHT {
            let done = tasks.join_next().await.expect("a task").expect("no panic");
            record(&mut outcomes, done);
        }
        let (session, key, expects) = (session.clone(), target.key.clone(), target.expects);
        tasks.spawn(async move {
            let result = query_once(&session, &key, expects, bytes).await;
            (key, result)
        });
    }
    while let Some(done) = tasks.join_next().await {
        record(&mut outcomes, done.expect("no panic"));
    }
    outcomes
}

pub(crate) async fn storm_puts(
    session: Session,
    targets: Vec<Target>,
    all: Arc<Vec<Vec<u8>>>,
    seed: u64,
) -> BTreeMap<String, usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut order: Vec<usize> = targets
        .iter()
        .enumerate()
        .flat_map(|(i, t)| std::iter::repeat_n(i, t.count))
        .collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    let mut counts = BTreeMap::new();
    for (n, i) in order.into_iter().enumerate() {
        let target = &targets[i];
        let bytes = payload(&mut rng, target, &all);
        session.put(&target.key, bytes).await.expect("put");
        *counts.entry(target.key.clone()).or_insert(0) += 1;
        if n % 256 == 0 {
            // Let the services' subscribers run between bursts.
            tokio::task::yield_now().await;
        }
    }
    counts
}
