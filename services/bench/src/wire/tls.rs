//! The TLS rows' throwaway CA and certificate, made with the openssl CLI, and the
//! session settings that use them.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::{setup, BenchError};

/// The throwaway CA and the listening side's certificate; the directory goes when this
/// is dropped.
pub(super) struct Certs {
    _dir: tempfile::TempDir,
    ca: PathBuf,
    cert: PathBuf,
    key: PathBuf,
}

/// The openssl commands that make [`Certs`], run in its directory, each split at its
/// spaces: a CA, then a key and a certificate the CA signs for `localhost` and
/// `127.0.0.1` (`wire.ext`).
const OPENSSL_STEPS: [&str; 5] = [
    "genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out ca.key",
    "req -x509 -new -key ca.key -sha256 -days 1 -subj /CN=roam-bench-wire-CA \
     -addext basicConstraints=critical,CA:TRUE -addext keyUsage=critical,keyCertSign,cRLSign \
     -out ca.crt",
    "genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out wire.key",
    "req -new -key wire.key -subj /CN=localhost -out wire.csr",
    "x509 -req -in wire.csr -CA ca.crt -CAkey ca.key -CAcreateserial -sha256 -days 1 \
     -extfile wire.ext -out wire.crt",
];

impl Certs {
    /// A P-256 CA and a certificate it signs for `localhost` and `127.0.0.1`, valid one
    /// day, made with the openssl CLI the way `deploy/secure/make-secrets.sh` makes a
    /// site's.
    pub(super) fn make() -> Result<Certs, BenchError> {
        let dir = tempfile::tempdir().map_err(setup)?;
        std::fs::write(
            dir.path().join("wire.ext"),
            "basicConstraints=critical,CA:FALSE\n\
             keyUsage=critical,digitalSignature,keyEncipherment\n\
             extendedKeyUsage=serverAuth\n\
             subjectAltName=DNS:localhost,IP:127.0.0.1\n",
        )
        .map_err(setup)?;
        for args in OPENSSL_STEPS {
            let out = Command::new("openssl")
                .args(args.split_whitespace())
                .current_dir(dir.path())
                .output()
                .map_err(|e| {
                    BenchError::Setup(format!(
                        "the TLS rows need the openssl CLI to make a throwaway certificate: {e}"
                    ))
                })?;
            if !out.status.success() {
                return Err(BenchError::Setup(format!(
                    "openssl {args} failed: {}",
                    String::from_utf8_lossy(&out.stderr).trim()
                )));
            }
        }
        Ok(Certs {
            ca: dir.path().join("ca.crt"),
            cert: dir.path().join("wire.crt"),
            key: dir.path().join("wire.key"),
            _dir: dir,
        })
    }
}

/// `--cfg key:"path"`.
fn cfg_path(key: &str, path: &Path) -> String {
    format!(
        "{key}:{}",
        serde_json::Value::from(path.to_string_lossy().into_owned())
    )
}

/// The settings of the side that listens over TLS: the certificate and its key.
pub(super) fn tls_listen(certs: &Certs) -> Vec<String> {
    vec![
        cfg_path("transport/link/tls/listen_certificate", &certs.cert),
        cfg_path("transport/link/tls/listen_private_key", &certs.key),
    ]
}

/// The settings of the side that connects over TLS: the CA it checks the listener's
/// certificate against.
pub(super) fn tls_connect(certs: &Certs) -> Vec<String> {
    vec![cfg_path(
        "transport/link/tls/root_ca_certificate",
        &certs.ca,
    )]
}
