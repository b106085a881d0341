//! The secure site under test, made the way a site operator makes one: the shipped
//! `deploy/secure/make-secrets.sh --robots robot,r1,r2` writes the CA, the router's
//! certificate and key, the user dictionary, one client config per user and the router's
//! config (the shipped `deploy/secure/router.json5` with the three robots' rules) into a
//! temporary directory; the router and every session use those files, with only the
//! endpoints overridden (a free loopback port).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use roam_runtime::SessionArgs;
use roam_stack::router::{free_loopback_port, Router};
use roam_tests::{repo_path, within, Harness, SecureSite};

use crate::ROOT;

/// The fleet the secrets are made for: the built-in world's robot, and r1 and r2 of the
/// fleet world.
pub(crate) const ROBOTS: [&str; 3] = ["robot", "r1", "r2"];
/// A user the dictionary knows but the access control does not: authenticated, and
/// matching no subject. The test adds it to a copy of the generated dictionary.
pub(crate) const GUEST: &str = "guest";

/// The site's files, as the generator wrote them.
pub(crate) struct Secrets {
    _dir: tempfile::TempDir,
    /// make-secrets.sh's output directory.
    out: PathBuf,
    /// The dictionary the router reads: the generated `users.txt` and [`GUEST`].
    pub(crate) users: PathBuf,
    /// Every user's password, [`GUEST`]'s included.
    pub(crate) passwords: BTreeMap<String, String>,
}

fn make_secrets() -> Secrets {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("secrets");
    let script = repo_path("deploy/secure/make-secrets.sh");
    let made = Command::new(&script)
        .arg("--robots")
        .arg(ROBOTS.join(","))
        .arg("--out")
        .arg(&out)
        .arg("--install-dir")
        .arg(&out)
        .args(["localhost", "127.0.0.1"])
        .output()
        .unwrap_or_else(|e| panic!("{} does not run: {e}", script.display()));
    assert!(
        made.status.success(),
        "make-secrets.sh failed (it needs bash and the openssl CLI): {}",
        String::from_utf8_lossy(&made.stderr)
    );
    let generated = std::fs::read_to_string(out.join("users.txt")).expect("users.txt");
    let mut passwords: BTreeMap<String, String> = generated
        .lines()
        .filter_map(|line| line.split_once(':'))
        .map(|(user, password)| (user.to_owned(), password.to_owned()))
        .collect();
    passwords.insert(
        GUEST.to_owned(),
        format!("guest-{:016x}", rand::random::<u64>()),
    );
    let users = dir.path().join("users-and-guest.txt");
    let dictionary = format!("{generated}{GUEST}:{}\n", passwords[GUEST]);
    std::fs::write(&users, dictionary).expect("write the dictionary");
    Secrets {
        _dir: dir,
        out,
        users,
        passwords,
    }
}

/// `key:value` for `--cfg`, with the value as a JSON string.
fn cfg(key: &str, value: &str) -> String {
    format!("{key}:{}", serde_json::Value::from(value))
}

fn path_str(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 temp path")
}

/// The router, from the generated `router.json5` with only the listen endpoint (a free
/// loopback port) and the dictionary (with the guest) overridden.
async fn start_router(secrets: &Secrets) -> Router {
    let file = secrets.out.join("router.json5");
    let mut last = String::new();
    for _ in 0..5 {
        let port = free_loopback_port().expect("a free port");
        let endpoint = format!("tls/127.0.0.1:{port}");
        let args = SessionArgs {
            cfg: vec![
                format!("listen/endpoints:[\"{endpoint}\"]"),
                cfg(
                    "transport/auth/usrpwd/dictionary_file",
                    path_str(&secrets.users),
                ),
            ],
            ..SessionArgs::default()
        };
        let config = args
            .zenoh_config_with(None, Some(&file))
            .expect("the generated router.json5 is a valid Zenoh config");
        match within("router start", roam_runtime::session::open(config)).await {
            Ok(session) => return Router { session, endpoint },
            Err(e) => last = e.to_string(),
        }
    }
    panic!("no secure router could be started: {last}");
}

/// The generated client config of `user` (`<user>.json5`) connected to this router,
/// with `extra` `--cfg` settings on top.
pub(crate) fn user_config(
    secrets: &Secrets,
    endpoint: &str,
    user: &str,
    extra: &[String],
) -> zenoh::Config {
    let mut cfgs = vec![format!("connect/endpoints:[\"{endpoint}\"]")];
    cfgs.extend_from_slice(extra);
    let file = secrets.out.join(format!("{user}.json5"));
    SessionArgs {
        cfg: cfgs,
        ..SessionArgs::default()
    }
    .zenoh_config_with(None, Some(&file))
    .unwrap_or_else(|e| panic!("{} is not a valid Zenoh config: {e}", file.display()))
}

/// `--cfg` settings that give a session other credentials (`None`: none at all).
pub(crate) fn credentials(user_and_password: Option<(&str, &str)>) -> Vec<String> {
    match user_and_password {
        Some((user, password)) => vec![
            cfg("transport/auth/usrpwd/user", user),
            cfg("transport/auth/usrpwd/password", password),
        ],
        None => vec![
            "transport/auth/usrpwd/user:null".into(),
            "transport/auth/usrpwd/password:null".into(),
        ],
    }
}

fn site(secrets: &Secrets, endpoint: &str) -> SecureSite {
    // The guest has no config of its own: the operator's, with the guest's credentials.
    let guest = credentials(Some((GUEST, secrets.passwords[GUEST].as_str())));
    let roles = secrets
        .passwords
        .keys()
        .map(|user| {
            let config = if user == GUEST {
                user_config(secrets, endpoint, "operator", &guest)
            } else {
                user_config(secrets, endpoint, user, &[])
            };
            (user.clone(), config)
        })
        .collect();
    SecureSite {
        anonymous: user_config(secrets, endpoint, "operator", &credentials(None)),
        roles,
    }
}

/// A secure site: its secrets (kept until the test ends), and a harness around its router.
pub(crate) async fn secure_site() -> (Secrets, Harness) {
    let secrets = make_secrets();
    let router = start_router(&secrets).await;
    let endpoint = router.endpoint.clone();
    let site = site(&secrets, &endpoint);
    (secrets, Harness::start_secure(router, ROOT, site))
}
