//! A robot's calibration on disk, so that a restarted executive plans with what its
//! robot has shown, not with Table I again.
//!
//! One small JSON file per robot (the executive drives one robot):
//!
//! ```json
//! {"format":"roam-time-calibration","robot":"r1",
//!  "model":{"v_lin":1.27,"v_ang":1.31},
//!  "statistics":{"dd":…,"dtheta":…,"thetatheta":…,"dt":…,"thetat":…,"seconds":…,
//!                "chunks":…,"stops":…,"jumps":…,"stretches":…}}
//! ```
//!
//! `statistics` are the fit's sums (see [`super::fit`]): a calibration's size never
//! grows with the driving behind it. `model` is the fit when the file was written, for
//! people reading it; a load refits from the sums with the caller's prior and config.
//! The file is written atomically ([`crate::state_file`]): a crash mid-write leaves the
//! previous one whole. A file that is missing starts from the prior;
//! one that is damaged, too large, of another robot or implausible also starts from the
//! prior, with a warning: a calibration is worth keeping, not worth refusing to run for.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::config::CalibrationConfig;
use super::error::CalibrationError;
use super::fit::{Calibration, Statistics};
use super::time_model::TimeModel;

/// The format tag in every calibration file.
pub const FORMAT: &str = "roam-time-calibration";

/// The largest calibration file read, bytes (limit `max_calibration_file_bytes`): a
/// real one is a few hundred bytes.
pub const MAX_CALIBRATION_FILE_BYTES: u64 = 64 * 1024;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CalibrationFile {
    format: String,
    robot: String,
    model: TimeModel,
    statistics: Statistics,
}

/// What [`load`] found.
#[derive(Debug, Clone, PartialEq)]
pub enum Loaded {
    /// No file yet: the prior.
    Missing,
    /// The file's calibration.
    Restored,
    /// The file could not be used (why): the prior, and a warning was logged.
    Refused(String),
}

/// Writes `calibration` of `robot` to `path` atomically (a temporary file renamed over
/// it), making its folder if needed.
pub fn save(path: &Path, robot: &str, calibration: &Calibration) -> Result<(), CalibrationError> {
    let fail = |reason: String| CalibrationError::Write {
        path: path.display().to_string(),
        reason,
    };
    let file = CalibrationFile {
        format: FORMAT.to_owned(),
        robot: robot.to_owned(),
        model: calibration.model(),
        statistics: *calibration.statistics(),
    };
    let bytes = serde_json::to_vec(&file).map_err(|e| fail(e.to_string()))?;
    if bytes.len() as u64 > MAX_CALIBRATION_FILE_BYTES {
        return Err(fail(format!(
            "{} bytes is beyond {MAX_CALIBRATION_FILE_BYTES} (max_calibration_file_bytes); use a shorter robot name",
            bytes.len()
        )));
    }
    crate::state_file::write_atomic(path, &bytes).map_err(fail)
}

/// `robot`'s calibration from `path`, with `prior` and `config`; the prior alone when
/// the file is missing or cannot be used (logged as a warning, and said in [`Loaded`]).
/// Refused only when `prior` or `config` is out of range.
pub fn load(
    path: &Path,
    robot: &str,
    prior: TimeModel,
    config: CalibrationConfig,
) -> Result<(Calibration, Loaded), CalibrationError> {
    let fresh = Calibration::new(prior, config)?;
    match read(path, robot) {
        Ok(None) => Ok((fresh, Loaded::Missing)),
        Ok(Some(statistics)) => Ok((fresh.with_statistics(statistics), Loaded::Restored)),
        Err(reason) => {
            tracing::warn!(
                path = %path.display(),
                robot,
                "the time calibration cannot be used ({reason}): starting from the prior"
            );
            Ok((fresh, Loaded::Refused(reason)))
        }
    }
}

/// The file's statistics; `None` when there is no file; why it cannot be used.
fn read(path: &Path, robot: &str) -> Result<Option<Statistics>, String> {
    let Some(bytes) = crate::state_file::read_bounded(
        path,
        MAX_CALIBRATION_FILE_BYTES,
        "max_calibration_file_bytes",
    )?
    else {
        return Ok(None);
    };
    // The parser's message quotes nothing of the file (see roam_proto::excerpt).
    let file: CalibrationFile = serde_json::from_slice(&bytes)
        .map_err(|e| roam_proto::excerpt::file_parse_reason(&e.to_string()))?;
    if file.format != FORMAT {
        return Err(format!("not a {FORMAT} file"));
    }
    if file.robot != robot {
        return Err("the file is another robot's".into());
    }
    if !file.statistics.is_plausible() {
        return Err("its sums are not finite, negative or inconsistent".into());
    }
    Ok(Some(file.statistics))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::{Sample, Stretch};
    use std::path::PathBuf;

    fn dir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("roam-calibration-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    /// A calibration that has seen 20 m of straight driving at 1 s/m.
    fn driven() -> Calibration {
        let config = CalibrationConfig::default();
        let mut c = Calibration::new(TimeModel::table_i(), config).expect("calibration");
        let samples = (0..=100).map(|i| Sample {
            time_s: f64::from(i) * 0.2,
            at: [f64::from(i) * 0.2, 0.0],
        });
        c.add(&Stretch::from_samples(samples).expect("stretch"));
        c
    }

    #[test]
    fn a_calibration_survives_a_restart() {
        let d = dir("roundtrip");
        let path = d.join("state").join("r1.json");
        let config = CalibrationConfig::default();
        let (fresh, loaded) = load(&path, "r1", TimeModel::table_i(), config).expect("load");
        assert_eq!(loaded, Loaded::Missing);
        assert_eq!(fresh.model(), TimeModel::table_i());
        let c = driven();
        assert!(c.model().v_lin < 1.5, "{:?}", c.model());
        save(&path, "r1", &c).expect("save");
        assert!(!path.with_extension("json.tmp").exists());
        let (back, loaded) = load(&path, "r1", TimeModel::table_i(), config).expect("load");
        assert_eq!(loaded, Loaded::Restored);
        assert_eq!(back, c);
        assert_eq!(back.model(), c.model());
        let size = std::fs::metadata(&path).expect("meta").len();
        assert!(size < 1024, "{size} bytes");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_damaged_or_foreign_file_falls_back_to_the_prior() {
        let d = dir("damaged");
        std::fs::create_dir_all(&d).expect("dir");
        let path = d.join("r1.json");
        let config = CalibrationConfig::default();
        let prior = TimeModel::table_i();
        let refused = |path: &Path| match load(path, "r1", prior, config).expect("load") {
            (c, Loaded::Refused(why)) => {
                assert_eq!(c.model(), prior);
                why
            }
            (_, other) => panic!("{other:?}"),
        };
        std::fs::write(&path, b"{\"format\": \"roam-time-calib").expect("write");
        refused(&path);
        save(&path, "r2", &driven()).expect("save");
        assert!(refused(&path).contains("another robot"));
        let text = std::fs::read_to_string(&path)
            .expect("read")
            .replace("\"r2\"", "\"r1\"");
        let poisoned = text.replacen("\"dd\":", "\"dd\":-", 1);
        std::fs::write(&path, poisoned).expect("write");
        assert!(refused(&path).contains("not finite, negative"));
        std::fs::write(&path, vec![b' '; MAX_CALIBRATION_FILE_BYTES as usize + 1]).expect("write");
        assert!(refused(&path).contains("max_calibration_file_bytes"));
        assert!(refused(&d).contains("regular file"));
        let _ = std::fs::remove_dir_all(&d);
    }
}
