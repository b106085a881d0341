//! The processes of one stack and their supervision: each role a `roam` process with
//! its log in one directory, killed with SIGKILL and started again on demand, and
//! restarted when it exits on its own (what `Restart=always` does in production).

use std::fs::{File, OpenOptions};
use std::process::{Child, Command, Stdio};

pub(crate) const ROAM: &str = env!("CARGO_BIN_EXE_roam");

/// One supervised role: how to start it, and its process now.
pub(crate) struct Role {
    /// The service name in its liveliness key (`<root>/@live/<service>/<instance>`).
    pub(crate) service: &'static str,
    pub(crate) instance: &'static str,
    pub(crate) args: Vec<String>,
    pub(crate) child: Option<Child>,
    pub(crate) restarts: u32,
}

/// The processes of one stack, their logs in one directory.
pub(crate) struct Fleet {
    pub(crate) dir: tempfile::TempDir,
    pub(crate) root: String,
    pub(crate) endpoint: String,
    pub(crate) router: Option<Child>,
    pub(crate) roles: Vec<Role>,
}

impl Fleet {
    pub(crate) fn log(&self, name: &str) -> File {
        OpenOptions::new()
            .create(true)
            .append(true)
            .open(self.dir.path().join(format!("{name}.log")))
            .expect("log file")
    }

    pub(crate) fn spawn(&self, name: &str, args: &[String]) -> Child {
        Command::new(ROAM)
            .args(args)
            .env("RUST_LOG", "info")
            .stdout(Stdio::null())
            .stderr(self.log(name))
            .spawn()
            .expect("spawn roam")
    }

    pub(crate) fn start(&mut self, i: usize) {
        let name = format!("{}-{}", self.roles[i].service, self.roles[i].instance);
        let child = self.spawn(&name, &self.roles[i].args.clone());
        self.roles[i].child = Some(child);
    }

    /// SIGKILL (Rust's `Child::kill` on Unix), then reap it.
    pub(crate) fn kill(&mut self, i: usize) {
        if let Some(mut child) = self.roles[i].child.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }

    pub(crate) fn live_key(&self, i: usize) -> String {
        format!(
            "{}/@live/{}/{}",
            self.root, self.roles[i].service, self.roles[i].instance
        )
    }

    /// Every role that died on its own since the last look is started again, as a
    /// supervisor would (a mission executive that failed, say).
    pub(crate) fn restart_exited(&mut self) {
        for i in 0..self.roles.len() {
            let exited = self.roles[i]
                .child
                .as_mut()
                .is_some_and(|c| matches!(c.try_wait(), Ok(Some(_))));
            if exited {
                self.roles[i].restarts += 1;
                self.start(i);
            }
        }
    }

    pub(crate) fn logs(&self) -> String {
        let mut all = String::new();
        let mut names: Vec<_> = std::fs::read_dir(self.dir.path())
            .map(|d| d.flatten().map(|e| e.path()).collect())
            .unwrap_or_default();
        names.sort();
        for path in names
            .iter()
            .filter(|p| p.extension().is_some_and(|e| e == "log"))
        {
            let text = std::fs::read_to_string(path).unwrap_or_default();
            let tail: Vec<&str> = text.lines().rev().take(25).collect();
            all.push_str(&format!("== {}\n", path.display()));
            for line in tail.iter().rev() {
                all.push_str(line);
                all.push('\n');
            }
        }
        all
    }
}

impl Drop for Fleet {
    fn drop(&mut self) {
        for i in 0..self.roles.len() {
            self.kill(i);
        }
        if let Some(mut r) = self.router.take() {
            let _ = r.kill();
            let _ = r.wait();
        }
    }
}

pub(crate) fn client_args(endpoint: &str, root: &str, instance: &str) -> Vec<String> {
    [
        "--mode",
        "client",
        "--connect",
        endpoint,
        "--no-multicast",
        "--root",
        root,
        "--instance",
        instance,
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

pub(crate) fn role(
    service: &'static str,
    instance: &'static str,
    extra: &[&str],
    fleet: &Fleet,
) -> Role {
    let mut args = vec![service.to_owned()];
    args.extend(client_args(&fleet.endpoint, &fleet.root, instance));
    args.extend(extra.iter().map(|s| s.to_string()));
    Role {
        service,
        instance,
        args,
        child: None,
        restarts: 0,
    }
}
