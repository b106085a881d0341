//! The secure site under test: its secrets (a CA, the router's certificate and key, and a
//! user dictionary, made with rcgen in a temporary directory), the router started from the
//! shipped `deploy/secure/router.json5`, and one client config per role from the shipped
//! `deploy/secure/client.json5`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rcgen::{
    BasicConstraints, CertificateParams, CertifiedIssuer, DnType, ExtendedKeyUsagePurpose, IsCa,
    KeyPair, KeyUsagePurpose,
};
use roam_runtime::SessionArgs;
use roam_stack::router::{free_loopback_port, Router};
use roam_tests::{repo_path, within, Harness, SecureSite};

use crate::ROOT;

/// The roles of `router.json5`, each with a user in the dictionary.
const ROLES: [&str; 8] = [
    "map-server",
    "planner",
    "localization",
    "controller",
    "mapper",
    "mission",
    "sim",
    "operator",
];
/// A user the dictionary knows but the access control does not: authenticated, and
/// matching no subject.
pub(crate) const GUEST: &str = "guest";

/// The site's files: CA, router certificate and key, user dictionary.
pub(crate) struct Secrets {
    _dir: tempfile::TempDir,
    ca: PathBuf,
    router_cert: PathBuf,
    router_key: PathBuf,
    pub(crate) users: PathBuf,
    pub(crate) passwords: BTreeMap<String, String>,
}

fn make_secrets() -> Secrets {
    let dir = tempfile::tempdir().expect("temp dir");
    let write = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).expect("write a secret");
        path
    };

    let mut ca_params = CertificateParams::new(Vec::<String>::new()).expect("CA params");
    ca_params.is_ca = IsCa::Ca(BasicConstraints::Unconstrained);
    ca_params
        .distinguished_name
        .push(DnType::CommonName, "roam test CA");
    ca_params.key_usages = vec![KeyUsagePurpose::KeyCertSign, KeyUsagePurpose::CrlSign];
    let ca = CertifiedIssuer::self_signed(ca_params, KeyPair::generate().expect("CA key"))
        .expect("CA certificate");

    let mut router_params = CertificateParams::new(vec!["localhost".into(), "127.0.0.1".into()])
        .expect("router params");
    router_params
        .distinguished_name
        .push(DnType::CommonName, "router");
    router_params.key_usages = vec![KeyUsagePurpose::DigitalSignature];
    router_params.extended_key_usages = vec![ExtendedKeyUsagePurpose::ServerAuth];
    let router_key = KeyPair::generate().expect("router key");
    let router_cert = router_params
        .signed_by(&router_key, &ca)
        .expect("router certificate");

    let passwords: BTreeMap<String, String> = ROLES
        .iter()
        .copied()
        .chain([GUEST])
        .enumerate()
        .map(|(i, user)| {
            (
                user.to_owned(),
                format!("pw{i}-{:016x}", rand::random::<u64>()),
            )
        })
        .collect();
    let users: String = passwords
        .iter()
        .map(|(user, password)| format!("{user}:{password}\n"))
        .collect();

    Secrets {
        ca: write("ca.crt", &ca.pem()),
        router_cert: write("router.crt", &router_cert.pem()),
        router_key: write("router.key", &router_key.serialize_pem()),
        users: write("users.txt", &users),
        passwords,
        _dir: dir,
    }
}

/// `key:value` for `--cfg`, with the value as a JSON string.
fn cfg(key: &str, value: &str) -> String {
    format!("{key}:{}", serde_json::Value::from(value))
}

fn path_str(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 temp path")
}

/// The router, from the shipped `deploy/secure/router.json5` with only the listen
/// endpoint (a free loopback port) and the secrets' paths overridden.
async fn start_router(secrets: &Secrets) -> Router {
    let file = repo_path("deploy/secure/router.json5");
    let mut last = String::new();
    for _ in 0..5 {
        let port = free_loopback_port().expect("a free port");
        let endpoint = format!("tls/127.0.0.1:{port}");
        let args = SessionArgs {
            cfg: vec![
                format!("listen/endpoints:[\"{endpoint}\"]"),
                cfg(
                    "transport/link/tls/listen_certificate",
                    path_str(&secrets.router_cert),
                ),
                cfg(
                    "transport/link/tls/listen_private_key",
                    path_str(&secrets.router_key),
                ),
                cfg(
                    "transport/link/tls/root_ca_certificate",
                    path_str(&secrets.ca),
                ),
                cfg(
                    "transport/auth/usrpwd/dictionary_file",
                    path_str(&secrets.users),
                ),
            ],
            ..SessionArgs::default()
        };
        let config = args
            .zenoh_config_with(None, Some(&file))
            .expect("deploy/secure/router.json5 is a valid Zenoh config");
        match within("router start", roam_runtime::session::open(config)).await {
            Ok(session) => return Router { session, endpoint },
            Err(e) => last = e.to_string(),
        }
    }
    panic!("no secure router could be started: {last}");
}

/// A client config from the shipped `deploy/secure/client.json5`: this router, the
/// test CA, and the given credentials (none: the user and password are removed).
pub(crate) fn client_config(
    secrets: &Secrets,
    endpoint: &str,
    credentials: Option<(&str, &str)>,
    extra: &[String],
) -> zenoh::Config {
    let mut cfgs = vec![
        format!("connect/endpoints:[\"{endpoint}\"]"),
        cfg(
            "transport/link/tls/root_ca_certificate",
            path_str(&secrets.ca),
        ),
    ];
    match credentials {
        Some((user, password)) => {
            cfgs.push(cfg("transport/auth/usrpwd/user", user));
            cfgs.push(cfg("transport/auth/usrpwd/password", password));
        }
        None => {
            cfgs.push("transport/auth/usrpwd/user:null".into());
            cfgs.push("transport/auth/usrpwd/password:null".into());
        }
    }
    cfgs.extend_from_slice(extra);
    SessionArgs {
        cfg: cfgs,
        ..SessionArgs::default()
    }
    .zenoh_config_with(None, Some(&repo_path("deploy/secure/client.json5")))
    .expect("deploy/secure/client.json5 is a valid Zenoh config")
}

fn site(secrets: &Secrets, endpoint: &str) -> SecureSite {
    let roles = secrets
        .passwords
        .iter()
        .map(|(user, password)| {
            (
                user.clone(),
                client_config(secrets, endpoint, Some((user, password)), &[]),
            )
        })
        .collect();
    SecureSite {
        anonymous: client_config(secrets, endpoint, None, &[]),
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
