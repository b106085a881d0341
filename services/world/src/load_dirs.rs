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
///
/// Its message names the server's directories and paths: it is for the service's own
/// log. What goes back to the peer is [`LoadRefused::to_reply`], which names only the
/// file as the peer gave it, so a peer learns nothing of the server's file system.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LoadRefused {
    #[error("loads are off: this service has no load directories configured (set load_dirs in its config, or --load-dir)")]
    Off,
    #[error("no file '{requested}' in the load directories ({dirs})")]
    NotAllowed { requested: String, dirs: String },
    #[error("the loaded file refers to {path}, which does not exist or is outside the load directories ({dirs})")]
    Referenced { path: String, dirs: String },
}

impl LoadRefused {
    /// The error reply to a peer that asked to load `requested`: `not_found` for a
    /// missing file and a forbidden one alike, naming the file as the peer gave it and
    /// none of the server's paths.
    pub fn to_reply(&self, requested: &str) -> ErrorReply {
        let requested = excerpt(requested);
        match self {
            LoadRefused::Off => ErrorReply::new(ErrorCode::InvalidRequest, self.to_string()),
            LoadRefused::NotAllowed { .. } => ErrorReply::new(
                ErrorCode::NotFound,
                format!(
                    "'{requested}' does not exist or is outside the configured load directories; name a file relative to one of them"
                ),
            ),
            LoadRefused::Referenced { .. } => ErrorReply::new(
                ErrorCode::NotFound,
                format!(
                    "'{requested}' refers to a file (a map image, a scenario's map) that does not exist or is outside the configured load directories"
                ),
            ),
        }
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
        self.inside(path).ok_or_else(|| LoadRefused::Referenced {
            path: excerpt(&path.to_string_lossy()).to_string(),
            dirs: self.listed(),
        })
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
            dirs: self.listed(),
        }
    }

    /// The directories, for the service's own log.
    fn listed(&self) -> String {
        self.dirs
            .iter()
            .map(|d| d.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// `text` (an error about a file read for a load request) with each directory's
    /// absolute path taken out: a file inside one is named relative to it, so a reply
    /// to the peer tells nothing of where the directories are.
    pub fn redact(&self, text: &str) -> String {
        let mut redacted = text.to_owned();
        for dir in &self.dirs {
            let dir = dir.display().to_string();
            redacted = redacted
                .replace(&format!("{dir}{}", std::path::MAIN_SEPARATOR), "")
                .replace(&dir, "<load dir>");
        }
        redacted
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
            let reply = refused.to_reply(requested);
            assert_eq!(reply.code, ErrorCode::NotFound, "{requested}");
            assert_eq!(
                reply.message.replacen(&format!("'{requested}'"), "'<file>'", 1),
                "'<file>' does not exist or is outside the configured load directories; name a file relative to one of them"
            );
            assert!(!reply.message.contains("password"));
            let maps = dirs.dirs()[0].display().to_string();
            assert!(
                requested.contains(&maps) || !reply.message.contains(&maps),
                "the reply names the server's directory: {}",
                reply.message
            );
            assert!(refused.to_string().contains(&maps), "the log keeps it");
        }
    }

    #[test]
    fn without_directories_loads_are_off() {
        let refused = LoadDirs::none().resolve("a.yaml").expect_err("off");
        assert_eq!(refused, LoadRefused::Off);
    }

    #[test]
    fn redacted_errors_name_files_relative_to_their_directory() {
        let (root, dirs) = setup();
        let maps = dirs.dirs()[0].clone();
        let text = format!(
            "map file {} is invalid, beside {}",
            maps.join("a.yaml").display(),
            maps.display()
        );
        assert_eq!(
            dirs.redact(&text),
            "map file a.yaml is invalid, beside <load dir>"
        );
        let refused = dirs
            .check_referenced(&root.path().join("secret.txt"))
            .expect_err("outside");
        let reply = refused.to_reply("a.yaml");
        assert_eq!(reply.code, ErrorCode::NotFound);
        assert!(reply.message.starts_with("'a.yaml' refers to a file"));
        assert!(!reply.message.contains(&root.path().display().to_string()));
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
