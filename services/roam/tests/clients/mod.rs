//! What the tests that drive roam with a client roam did not write share: a `roam`
//! process started until it says it is ready and stopped on every way out of the test,
//! a client script run with a time limit, and whether python3 has the client's packages
//! (the test skips with a notice without them, except in CI, where it fails). Each test
//! binary uses some of it.
#![allow(dead_code)]

use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

const ROAM: &str = env!("CARGO_BIN_EXE_roam");

/// How long a `roam` process may take to say it is ready.
pub const READY_TIMEOUT: Duration = Duration::from_secs(60);

/// A `roam` process, stopped on every way out of the test, a failed assertion
/// included: SIGTERM, up to 10 s for it to exit, then SIGKILL.
#[derive(Debug)]
pub struct RoamProcess {
    child: Child,
    /// The stderr lines after the ready line, for [`RoamProcess::stderr_tail`].
    lines: mpsc::Receiver<String>,
}

impl RoamProcess {
    /// Starts `roam <args>` under the key root `root` and returns once a stderr line
    /// contains `ready`; the rest of stderr keeps being drained so the process never
    /// blocks on a full pipe.
    pub fn start(args: &[&str], root: &str, ready: &str) -> RoamProcess {
        Self::start_in(Command::new(ROAM), args, root, ready)
    }

    /// [`RoamProcess::start`] in the environment a user's shell gives it: without the
    /// `ZENOH_RUNTIME` that `.cargo/config.toml` sets for the tests, so that the
    /// binary's own setting is what runs.
    pub fn start_as_installed(args: &[&str], root: &str, ready: &str) -> RoamProcess {
        let mut command = Command::new(ROAM);
        command.env_remove(roam_runtime::zenoh_threads::ZENOH_RUNTIME_ENV);
        Self::start_in(command, args, root, ready)
    }

    fn start_in(mut command: Command, args: &[&str], root: &str, ready: &str) -> RoamProcess {
        let mut child = command
            .args(args)
            .env("ROAM_ROOT", root)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn roam");
        let stderr = child.stderr.take().expect("stderr");
        let (lines_tx, lines_rx) = mpsc::channel::<String>();
        thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                let _ = lines_tx.send(line);
            }
        });
        // Stopped on every way out from here, a panic included.
        let process = RoamProcess {
            child,
            lines: lines_rx,
        };
        let started = Instant::now();
        let mut seen = Vec::new();
        loop {
            match process
                .lines
                .recv_timeout(READY_TIMEOUT.saturating_sub(started.elapsed()))
            {
                Ok(line) if line.contains(ready) => return process,
                Ok(line) => seen.push(line),
                Err(mpsc::RecvTimeoutError::Timeout) => panic!(
                    "roam {args:?} not ready within {READY_TIMEOUT:?}; stderr:\n{}",
                    seen.join("\n")
                ),
                Err(mpsc::RecvTimeoutError::Disconnected) => panic!(
                    "roam {args:?} exited before it was ready; stderr:\n{}",
                    seen.join("\n")
                ),
            }
        }
    }

    /// The last `max` lines the process wrote to stderr since it was ready (for a
    /// failure's message: what Zenoh and the services logged).
    pub fn stderr_tail(&self, max: usize) -> String {
        let mut tail = std::collections::VecDeque::with_capacity(max);
        while let Ok(line) = self.lines.try_recv() {
            if tail.len() == max {
                tail.pop_front();
            }
            tail.push_back(line);
        }
        Vec::from(tail).join("\n")
    }

    /// SIGTERM, then SIGKILL after 10 s; the exit status when it exited.
    pub fn stop(&mut self) -> Option<ExitStatus> {
        let _ = Command::new("kill")
            .args(["-TERM", &self.child.id().to_string()])
            .status();
        let started = Instant::now();
        while started.elapsed() < Duration::from_secs(10) {
            if let Ok(Some(status)) = self.child.try_wait() {
                return Some(status);
            }
            thread::sleep(Duration::from_millis(50));
        }
        let _ = self.child.kill();
        self.child.wait().ok()
    }
}

impl Drop for RoamProcess {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            self.stop();
        }
    }
}

/// How a client script ended.
#[derive(Debug)]
pub struct ScriptRun {
    pub status: ExitStatus,
    pub stdout: String,
    pub stderr: String,
}

fn drain(mut pipe: impl Read + Send + 'static) -> thread::JoinHandle<String> {
    thread::spawn(move || {
        let mut text = String::new();
        let _ = pipe.read_to_string(&mut text);
        text
    })
}

/// Runs `python3 <script> <args>`, killed if it takes longer than `limit`.
pub fn run_python(script: &Path, args: &[&str], limit: Duration) -> ScriptRun {
    let mut child = Command::new("python3")
        .arg(script)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn python3");
    let stdout = drain(child.stdout.take().expect("stdout"));
    let stderr = drain(child.stderr.take().expect("stderr"));
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for python3") {
            break status;
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{} {args:?} took longer than {limit:?}", script.display());
        }
        thread::sleep(Duration::from_millis(50));
    };
    ScriptRun {
        status,
        stdout: stdout.join().expect("stdout reader"),
        stderr: stderr.join().expect("stderr reader"),
    }
}

/// Whether python3 can run `import <modules>`. Without it `test` is skipped with a
/// notice naming `install`, except in CI (`CI` set), where the test fails.
pub fn python_has(modules: &str, test: &str, install: &str) -> bool {
    let found = Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !found {
        if std::env::var_os("CI").is_some() {
            panic!("python3 cannot `import {modules}`; CI installs {install}");
        }
        eprintln!("SKIPPED {test}: python3 cannot `import {modules}` (pip install {install})");
    }
    found
}
