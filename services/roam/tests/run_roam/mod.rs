//! `roam <args>` as a user runs it from a shell, for the tests of long commands.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const ROAM: &str = env!("CARGO_BIN_EXE_roam");

/// `roam <args>`, killed after `limit`: its exit status, stdout and stderr.
pub fn roam(args: &[&str], limit: Duration) -> (bool, String, String) {
    let mut child = Command::new(ROAM)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn roam");
    let started = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if started.elapsed() > limit {
            let _ = child.kill();
            let output = child.wait_with_output().expect("output");
            panic!(
                "roam {args:?} ran longer than {limit:?}; stderr:\n{}",
                String::from_utf8_lossy(&output.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let output = child.wait_with_output().expect("output");
    (
        output.status.success(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}
