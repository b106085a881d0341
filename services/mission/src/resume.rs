//! The route the robot is driving, on disk (`resume_file`), so that a restarted
//! executive drives on with it instead of starting its window over
//! ([`crate::window::Resumed`]; the window decides whether it still fits).
//!
//! One small JSON file per robot, rewritten (atomically, [`crate::state_file`]) each
//! time a route is sent:
//!
//! ```json
//! {"format":"roam-resume","robot":"r1",
//!  "route":{"task":"goal1","task_start_s":75.0,"curious":true,"points":[[-8.0,-8.0],…]}}
//! ```
//!
//! A file that is missing, damaged, too large or another robot's is not used (with a
//! warning when it exists): the window then begins as without it.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::window::Resumed;

/// The format tag in every resume file.
pub const FORMAT: &str = "roam-resume";

/// The largest resume file read or written, bytes (limit `max_resume_file_bytes`): a
/// route of ten thousand points is about 400 KB.
pub const MAX_RESUME_FILE_BYTES: u64 = 1024 * 1024;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ResumeFile {
    format: String,
    robot: String,
    route: Resumed,
}

/// Keeps `route` as `robot`'s; why not (the executive logs it and drives on).
pub fn save(path: &Path, robot: &str, route: &Resumed) -> Result<(), String> {
    let file = ResumeFile {
        format: FORMAT.to_owned(),
        robot: robot.to_owned(),
        route: route.clone(),
    };
    let bytes = serde_json::to_vec(&file).map_err(|e| e.to_string())?;
    if bytes.len() as u64 > MAX_RESUME_FILE_BYTES {
        return Err(format!(
            "{} bytes is beyond {MAX_RESUME_FILE_BYTES} (max_resume_file_bytes)",
            bytes.len()
        ));
    }
    crate::state_file::write_atomic(path, &bytes)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// `robot`'s route kept at `path`; `None` when there is none or it cannot be used
/// (logged).
pub fn load(path: &Path, robot: &str) -> Option<Resumed> {
    let read = || -> Result<Option<Resumed>, String> {
        let Some(bytes) =
            crate::state_file::read_bounded(path, MAX_RESUME_FILE_BYTES, "max_resume_file_bytes")?
        else {
            return Ok(None);
        };
        let file: ResumeFile = serde_json::from_slice(&bytes)
            .map_err(|e| roam_proto::excerpt::file_parse_reason(&e.to_string()))?;
        if file.format != FORMAT {
            return Err(format!("not a {FORMAT} file"));
        }
        if file.robot != robot {
            return Err("the file is another robot's".into());
        }
        let finite = file.route.task_start_s.is_finite()
            && file.route.points.iter().flatten().all(|v| v.is_finite());
        if !finite {
            return Err("its times or points are not finite".into());
        }
        Ok(Some(file.route))
    };
    match read() {
        Ok(route) => route,
        Err(reason) => {
            tracing::warn!(path = %path.display(), robot, "the resume file cannot be used ({reason}): the window begins afresh");
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn route() -> Resumed {
        Resumed {
            task: "goal1".into(),
            task_start_s: 75.0,
            curious: true,
            points: vec![[0.0, 0.0], [1.0, 0.5], [2.0, 1.0]],
        }
    }

    #[test]
    fn a_route_survives_a_restart_and_only_its_robot_takes_it() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("state").join("r1.resume.json");
        assert_eq!(load(&path, "r1"), None);
        save(&path, "r1", &route()).expect("save");
        assert_eq!(load(&path, "r1"), Some(route()));
        assert_eq!(load(&path, "r2"), None, "another robot's route was taken");
    }

    #[test]
    fn a_damaged_or_huge_file_is_not_used() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("r1.json");
        std::fs::write(&path, b"{\"format\":\"roam-resume\",").expect("write");
        assert_eq!(load(&path, "r1"), None);
        std::fs::write(&path, vec![b' '; MAX_RESUME_FILE_BYTES as usize + 1]).expect("write");
        assert_eq!(load(&path, "r1"), None);
        let mut bad = route();
        bad.points[1][0] = f64::NAN;
        save(&path, "r1", &bad).expect("save");
        assert_eq!(load(&path, "r1"), None, "a route with NaN was taken");
    }
}
