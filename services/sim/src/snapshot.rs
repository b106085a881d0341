//! The sim's state on disk, so a sim that crashes (or is killed) comes back where it
//! was instead of at step 0 with every robot at its start.
//!
//! A snapshot holds what the fleet around the sim has already acted on: the scenario
//! and seed it belongs to, the step (so the clock goes on), and each robot's start and
//! position (and a unicycle's headings there). It does not hold the random streams: a resumed sim replays the world to the
//! step (blocks follow their script; walkers redraw from the world's stream, blocked by
//! the robots' starts instead of where the robots were) and restarts each robot's stream
//! from `(seed, name, step)`. So a resumed run is reproducible from its snapshot, bit for
//! bit, but it is not the run that would have happened without the crash. The clock and
//! the robots' positions, which missions and maps depend on, are kept exactly.
//!
//! The file is JSON, written to `<file>.tmp` and renamed over `<file>`, so a crash
//! mid-write leaves the previous snapshot whole.

use std::io::Write;
use std::path::{Path, PathBuf};

use roam_world::ros_map::read_bounded;
use serde::{Deserialize, Serialize};

/// The latest step a snapshot may hold: a resume replays the world to it (blocks and
/// walkers), so an absurd step from a damaged file must not hang the start. 10 million
/// steps are 46 days at the default 0.4 s per step; a replay to it takes seconds.
pub const MAX_SNAPSHOT_STEP: u64 = 10_000_000;

/// The format tag in every snapshot file.
const FORMAT: &str = "roam-sim-snapshot";

/// One robot as the snapshot keeps it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotState {
    pub name: String,
    pub start: [f64; 2],
    pub at: [f64; 2],
    /// A unicycle's heading at its start and now, radians (absent for a point robot,
    /// so its snapshot is what it was before headings existed, and old files load).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_heading_rad: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heading_rad: Option<f64>,
}

/// What the sim writes to its `state_file`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimSnapshot {
    pub format: String,
    /// The scenario's name as the sim reports it (its path, or the built-in world).
    pub scenario: String,
    pub seed: u64,
    pub step: u64,
    pub robots: Vec<RobotState>,
}

impl SimSnapshot {
    pub fn new(scenario: &str, seed: u64, step: u64, robots: Vec<RobotState>) -> SimSnapshot {
        SimSnapshot {
            format: FORMAT.to_owned(),
            scenario: scenario.to_owned(),
            seed,
            step,
            robots,
        }
    }
}

/// Why a snapshot could not be written or read back.
#[derive(Debug, thiserror::Error)]
pub enum SnapshotError {
    #[error("cannot write the sim snapshot {path}: {reason}")]
    Write { path: PathBuf, reason: String },
    #[error("cannot read the sim snapshot {path}: {reason}; fix or delete the file to start the sim at step 0")]
    Read { path: PathBuf, reason: String },
    #[error("cannot resume from the sim snapshot {path}: {reason}; fix or delete the file to start the sim at step 0")]
    Resume { path: PathBuf, reason: String },
}

/// Writes `snapshot` to `path` atomically (a temporary file renamed over it).
pub fn save(path: &Path, snapshot: &SimSnapshot) -> Result<(), SnapshotError> {
    let fail = |e: std::io::Error| SnapshotError::Write {
        path: path.to_owned(),
        reason: e.to_string(),
    };
    let bytes = serde_json::to_vec(snapshot).map_err(|e| SnapshotError::Write {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(fail)?;
    }
    {
        let mut file = std::fs::File::create(&tmp).map_err(fail)?;
        file.write_all(&bytes).map_err(fail)?;
        file.sync_all().map_err(fail)?;
    }
    std::fs::rename(&tmp, path).map_err(fail)
}

/// Reads the snapshot at `path`; `None` when there is no file yet.
pub fn load(path: &Path) -> Result<Option<SimSnapshot>, SnapshotError> {
    let fail = |reason: String| SnapshotError::Read {
        path: path.to_owned(),
        reason,
    };
    if !path.exists() {
        return Ok(None);
    }
    // Regular files only, and bounded (max_file_bytes), like every file roam reads.
    let bytes = read_bounded(path).map_err(|e| fail(e.to_string()))?;
    let snapshot: SimSnapshot = serde_json::from_slice(&bytes).map_err(|e| fail(e.to_string()))?;
    if snapshot.format != FORMAT {
        return Err(fail(format!(
            "format '{}', expected '{FORMAT}'",
            snapshot.format
        )));
    }
    if snapshot.step > MAX_SNAPSHOT_STEP {
        return Err(fail(format!(
            "step {} is beyond {MAX_SNAPSHOT_STEP} (max_snapshot_step)",
            snapshot.step
        )));
    }
    Ok(Some(snapshot))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("roam-sim-snapshot-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("temp dir");
        d
    }

    #[test]
    fn a_snapshot_reads_back_and_a_missing_file_is_none() {
        let d = dir("roundtrip");
        let path = d.join("sim.json");
        assert!(load(&path).expect("no file is fine").is_none());
        let s = SimSnapshot::new(
            "built-in",
            7,
            1234,
            vec![
                RobotState {
                    name: "r1".into(),
                    start: [1.0, 2.0],
                    at: [1.5, 2.5],
                    start_heading_rad: None,
                    heading_rad: None,
                },
                RobotState {
                    name: "u1".into(),
                    start: [1.0, 2.0],
                    at: [1.5, 2.5],
                    start_heading_rad: Some(0.5),
                    heading_rad: Some(-2.25),
                },
            ],
        );
        save(&path, &s).expect("save");
        assert_eq!(load(&path).expect("load"), Some(s));
        // A point robot's entry is written as it always was, and such a file still loads.
        let text = std::fs::read_to_string(&path).expect("read");
        assert!(
            text.contains(r#"{"name":"r1","start":[1.0,2.0],"at":[1.5,2.5]}"#),
            "{text}"
        );
        assert!(
            text.contains(r#""start_heading_rad":0.5,"heading_rad":-2.25"#),
            "{text}"
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_step_beyond_the_limit_is_refused_and_a_new_folder_is_made() {
        let d = dir("limit");
        let path = d.join("state").join("sim.json");
        let far = SimSnapshot::new("built-in", 0, MAX_SNAPSHOT_STEP + 1, Vec::new());
        save(&path, &far).expect("the folder is made");
        let e = load(&path).expect_err("too far");
        assert!(e.to_string().contains("max_snapshot_step"), "{e}");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_corrupt_file_is_an_error_that_says_what_to_do() {
        let d = dir("corrupt");
        let path = d.join("sim.json");
        std::fs::write(&path, b"{\"format\": \"roam-sim-snap").expect("write");
        let e = load(&path).expect_err("corrupt");
        assert!(e.to_string().contains("delete the file"), "{e}");
        let _ = std::fs::remove_dir_all(&d);
    }
}
