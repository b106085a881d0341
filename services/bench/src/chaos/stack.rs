//! The chaos day's processes and their supervision: the router and each role a process
//! of the `roam` binary, with its log in one directory; killed, frozen and started
//! again on the schedule's command, and started again when one exits on its own (what
//! systemd's `Restart=always` or compose's `restart: always` do on a site).

use std::fs::{File, OpenOptions};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use crate::BenchError;

/// One supervised process.
#[derive(Debug)]
pub struct Proc {
    /// `router`, or `<service>-<instance>` (`planner-a`).
    pub name: String,
    args: Vec<String>,
    child: Option<Child>,
    /// Killed on purpose and not to be started again until the schedule says so.
    down: bool,
    /// Started again after it exited on its own.
    pub unplanned_restarts: u32,
}

/// The processes of one stack.
#[derive(Debug)]
pub struct Processes {
    program: PathBuf,
    dir: PathBuf,
    pub procs: Vec<Proc>,
}

impl Processes {
    pub fn new(program: &Path, dir: &Path) -> Processes {
        Processes {
            program: program.to_owned(),
            dir: dir.to_owned(),
            procs: Vec::new(),
        }
    }

    /// Adds a process (not started): `roam <args>`.
    pub fn add(&mut self, service: Option<&'static str>, instance: &str, args: Vec<String>) {
        let name = match service {
            Some(s) => format!("{s}-{instance}"),
            None => instance.to_owned(),
        };
        self.procs.push(Proc {
            name,
            args,
            child: None,
            down: true,
            unplanned_restarts: 0,
        });
    }

    fn index(&self, name: &str) -> Result<usize, BenchError> {
        self.procs
            .iter()
            .position(|p| p.name == name)
            .ok_or_else(|| BenchError::Setup(format!("no process named {name}")))
    }

    fn log(&self, name: &str) -> Result<File, BenchError> {
        let path = self.dir.join(format!("{name}.log"));
        OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(|e| BenchError::Setup(format!("cannot open {}: {e}", path.display())))
    }

    pub fn start(&mut self, name: &str) -> Result<(), BenchError> {
        let i = self.index(name)?;
        let log = self.log(name)?;
        let child = Command::new(&self.program)
            .args(&self.procs[i].args)
            .env("RUST_LOG", "info")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(log)
            .spawn()
            .map_err(|e| {
                BenchError::Setup(format!(
                    "cannot start {name} ({}): {e}",
                    self.program.display()
                ))
            })?;
        self.procs[i].child = Some(child);
        self.procs[i].down = false;
        Ok(())
    }

    /// SIGKILL (`Child::kill` on Unix), reaped; not started again until [`Self::start`].
    pub fn kill(&mut self, name: &str) -> Result<(), BenchError> {
        let i = self.index(name)?;
        self.procs[i].down = true;
        if let Some(mut child) = self.procs[i].child.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
        Ok(())
    }

    /// SIGSTOP (`stop: true`) or SIGCONT the process: frozen, it answers nothing and
    /// keeps its sockets open.
    pub fn freeze(&mut self, name: &str, stop: bool) -> Result<(), BenchError> {
        use rustix::process::{kill_process, Pid, Signal};
        let i = self.index(name)?;
        let pid = self.procs[i]
            .child
            .as_ref()
            .and_then(|c| i32::try_from(c.id()).ok())
            .and_then(Pid::from_raw)
            .ok_or_else(|| BenchError::Setup(format!("{name} is not running")))?;
        let signal = if stop { Signal::STOP } else { Signal::CONT };
        kill_process(pid, signal)
            .map_err(|e| BenchError::Setup(format!("cannot signal {name}: {e}")))
    }

    /// Starts again every process that exited on its own since the last look; their
    /// names.
    pub fn restart_exited(&mut self) -> Result<Vec<String>, BenchError> {
        let mut exited = Vec::new();
        for p in &mut self.procs {
            let gone = !p.down
                && p.child
                    .as_mut()
                    .is_some_and(|c| matches!(c.try_wait(), Ok(Some(_))));
            if gone {
                p.unplanned_restarts += 1;
                exited.push(p.name.clone());
            }
        }
        for name in &exited {
            tracing::warn!(%name, "exited on its own; started again");
            self.start(name)?;
        }
        Ok(exited)
    }

    /// The last lines of each process's log, for an error message.
    pub fn log_tails(&self, lines: usize) -> String {
        let mut all = String::new();
        for p in &self.procs {
            let path = self.dir.join(format!("{}.log", p.name));
            let text = std::fs::read_to_string(&path).unwrap_or_default();
            let tail: Vec<&str> = text.lines().rev().take(lines).collect();
            all.push_str(&format!("== {}\n", path.display()));
            for line in tail.iter().rev() {
                all.push_str(line);
                all.push('\n');
            }
        }
        all
    }
}

impl Drop for Processes {
    fn drop(&mut self) {
        for p in &mut self.procs {
            if let Some(mut child) = p.child.take() {
                let _ = child.kill();
                let _ = child.wait();
            }
        }
    }
}
