//! The processes of one stack and their supervision, on `roam bench chaos`'s own
//! supervisor (`roam_bench::chaos::Processes`): each role a `roam` process with its log
//! in one directory, killed with SIGKILL and started again on demand, and restarted
//! when it exits on its own (what `Restart=always` does in production).

use roam_bench::chaos::{client_args, Processes};
use roam_proto::keys;

pub(crate) const ROAM: &str = env!("CARGO_BIN_EXE_roam");

/// One supervised role: its process's name and its liveliness key.
pub(crate) struct Role {
    pub(crate) name: String,
    pub(crate) live_key: String,
}

/// The processes of one stack, their logs in one directory.
pub(crate) struct Fleet {
    pub(crate) root: String,
    pub(crate) endpoint: String,
    pub(crate) procs: Processes,
    pub(crate) roles: Vec<Role>,
    /// Last: the processes are killed before their directory goes.
    pub(crate) dir: tempfile::TempDir,
}

impl Fleet {
    pub(crate) fn new(root: String, endpoint: String) -> Fleet {
        let dir = tempfile::tempdir().expect("temp dir");
        Fleet {
            procs: Processes::new(std::path::Path::new(ROAM), dir.path()),
            root,
            endpoint,
            roles: Vec::new(),
            dir,
        }
    }

    /// Adds role `service` `instance` (not started), a client of the fleet's router.
    pub(crate) fn add(&mut self, service: &'static str, instance: &str, extra: &[&str]) {
        let mut args = vec![service.to_owned()];
        args.extend(client_args(&self.endpoint, &self.root, instance));
        args.extend(extra.iter().map(|s| s.to_string()));
        self.procs.add(Some(service), instance, args);
        self.roles.push(Role {
            name: format!("{service}-{instance}"),
            live_key: keys::liveliness(&self.root, service, instance),
        });
    }

    pub(crate) fn start(&mut self, name: &str) {
        self.procs.start(name).expect("start a role");
    }

    pub(crate) fn kill(&mut self, name: &str) {
        self.procs.kill(name).expect("kill a role");
    }

    /// Every role that died on its own since the last look is started again.
    pub(crate) fn restart_exited(&mut self) {
        self.procs.restart_exited().expect("restart what exited");
    }

    pub(crate) fn logs(&self) -> String {
        self.procs.log_tails(25)
    }
}
