//! Where a load request may read: files only in the directories the operator named.
//!
//! A `load` on the wire (`<root>/map/load`, the sim's `load`) names a file relative to
//! the configured directories ([`LoadDirs`]); the file, after resolving `..` and
//! symlinks, must lie inside one of them, and so must every file it refers to (a ROS
//! map's image, a scenario's map and information image). With no directory configured,
//! loads are off. A file that does not exist and one outside the directories get the
//! same answer ([`LoadRefused`]), so a peer cannot probe which files the machine has.
//!
//! Files the operator names at start (`--map`, `--scenario`, config files) are not
//! loads from the wire and are read where they are.

use std::path::{Component, Path, PathBuf};

use roam_proto::{excerpt, ErrorCode, ErrorReply};

/// The directories load requests may read from, each resolved (absolute, no symlinks)
/// once when the service starts.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LoadDirs {
    dirs: Vec<PathBuf>,
}

/// Why a load request's file was refused. The same for a missing file and one outside
/// the directories.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LoadRefused {
    #[error("loads are off: this service has no load directories configured (set load_dirs in its config, or --load-dir)")]
    Off,
    #[error("no file '{requested}' in the load directories ({dirs}); name a file relative to one of them")]
    NotAllowed { requested: String, dirs: String },
}

impl LoadRefused {
    /// The error reply for a refused load: `not_found` either way, so a missing file and
    /// a forbidden one look alike.
    pub fn to_reply(&self) -> ErrorReply {
        let code = match self {
            LoadRefused::Off => ErrorCode::InvalidRequest,
            LoadRefused::NotAllowed { .. } => ErrorCode::NotFound,
        };
        ErrorReply::new(code, self.to_string())
    }
}

/// Why the configured directories cannot be used (at start, a config error).
#[derive(Debug, thiserror::Error)]
#[error("load directory {path} cannot be used: {reason}")]
pub struct LoadDirError {
    pub path: PathBuf,
    pub reason: String,
}

impl LoadDirs {
    /// No directory: every load is refused.
    pub fn none() -> Self {
        LoadDirs::default()
    }

    /// Resolves each directory; each must exist and be a directory.
    pub fn new<P: AsRef<Path>>(dirs: &[P]) -> Result<Self, LoadDirError> {
        let mut resolved = Vec::with_capacity(dirs.len());
        for dir in dirs {
            let dir = dir.as_ref();
            let fail = |reason: String| LoadDirError {
                path: dir.to_owned(),
                reason,
            };
            let canonical = dir.canonicalize().map_err(|e| fail(e.to_string()))?;
            if !canonical.is_dir() {
                return Err(fail("not a directory".into()));
            }
            if !resolved.contains(&canonical) {
                resolved.push(canonical);
            }
        }
        Ok(LoadDirs { dirs: resolved })
    }

    pub fn is_off(&self) -> bool {
        self.dirs.is_empty()
    }

    pub fn dirs(&self) -> &[PathBuf] {
        &self.dirs
    }

    /// The file a load request names: `requested` is relative to one of the directories
    /// (the first that has it wins); absolute paths are refused.
    pub fn resolve(&self, requested: &str) -> Result<PathBuf, LoadRefused> {
        if self.dirs.is_empty() {
            return Err(LoadRefused::Off);
        }
        let relative = Path::new(requested);
        let plain = !requested.is_empty()
            && relative.components().all(|c| {
                matches!(
                    c,
                    Component::Normal(_) | Component::ParentDir | Component::CurDir
                )
            });
        if plain {
            for dir in &self.dirs {
                if let Some(found) = self.inside(&dir.join(relative)) {
                    return Ok(found);
                }
            }
        }
        Err(self.not_allowed(requested))
    }

    /// A file that a loaded file refers to (relative to it, or absolute): allowed only
    /// inside the directories.
    pub fn check_referenced(&self, path: &Path) -> Result<PathBuf, LoadRefused> {
        if self.dirs.is_empty() {
            return Err(LoadRefused::Off);
        }
        self.inside(path)
            .ok_or_else(|| self.not_allowed(&path.to_string_lossy()))
    }

    /// The resolved path when it exists and lies inside one of the directories.
    fn inside(&self, path: &Path) -> Option<PathBuf> {
        let canonical = path.canonicalize().ok()?;
        self.dirs
            .iter()
            .any(|dir| canonical.starts_with(dir))
            .then_some(canonical)
    }

    fn not_allowed(&self, requested: &str) -> LoadRefused {
        LoadRefused::NotAllowed {
            requested: excerpt(requested).to_string(),
            dirs: self
                .dirs
                .iter()
                .map(|d| d.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
        }
    }
}

/// How a loader may follow the paths inside a file: anywhere (files the operator named)
/// or only inside the load directories (files a peer named).
#[derive(Debug, Clone, Copy)]
pub enum Access<'a> {
    Anywhere,
    Within(&'a LoadDirs),
}

impl Access<'_> {
    /// `path` as the loader should read it, or the refusal.
    pub fn check(&self, path: &Path) -> Result<PathBuf, LoadRefused> {
        match self {
            Access::Anywhere => Ok(path.to_owned()),
            Access::Within(dirs) => dirs.check_referenced(path),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    fn setup() -> (tempfile::TempDir, LoadDirs) {
        let root = tempfile::tempdir().expect("tmp");
        fs::create_dir(root.path().join("maps")).expect("mkdir");
        fs::write(root.path().join("maps/a.yaml"), "x").expect("write");
        fs::write(root.path().join("secret.txt"), "password").expect("write");
        #[cfg(unix)]
        std::os::unix::fs::symlink(
            root.path().join("secret.txt"),
            root.path().join("maps/link.yaml"),
        )
        .expect("symlink");
        let dirs = LoadDirs::new(&[root.path().join("maps")]).expect("dirs");
        (root, dirs)
    }

    #[test]
    fn a_file_in_a_directory_is_found() {
        let (root, dirs) = setup();
        let found = dirs.resolve("a.yaml").expect("allowed");
        assert_eq!(
            found,
            root.path().join("maps/a.yaml").canonicalize().expect("c")
        );
        assert!(
            dirs.resolve("./sub/../a.yaml").is_err(),
            "sub does not exist"
        );
        assert!(dirs.resolve("./a.yaml").is_ok());
    }

    #[test]
    fn escapes_and_missing_files_get_the_same_answer() {
        let (root, dirs) = setup();
        let absolute = root.path().join("maps/a.yaml");
        let tries = [
            "../secret.txt".to_owned(),
            "link.yaml".to_owned(),
            absolute.display().to_string(),
            "/etc/passwd".to_owned(),
            "missing.yaml".to_owned(),
            String::new(),
        ];
        for requested in &tries {
            let refused = dirs.resolve(requested).expect_err(requested);
            let reply = refused.to_reply();
            assert_eq!(reply.code, ErrorCode::NotFound, "{requested}");
            assert!(reply.message.contains("no file"), "{}", reply.message);
            assert!(!reply.message.contains("password"));
        }
    }

    #[test]
    fn without_directories_loads_are_off() {
        let refused = LoadDirs::none().resolve("a.yaml").expect_err("off");
        assert_eq!(refused, LoadRefused::Off);
    }

    #[test]
    fn referenced_files_must_stay_inside() {
        let (root, dirs) = setup();
        assert!(dirs
            .check_referenced(&root.path().join("maps/a.yaml"))
            .is_ok());
        assert!(dirs
            .check_referenced(&root.path().join("maps/../secret.txt"))
            .is_err());
        assert!(Access::Anywhere
            .check(&root.path().join("secret.txt"))
            .is_ok());
    }
}
