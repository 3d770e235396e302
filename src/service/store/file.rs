//! The database file's identity (device and inode on Unix), taken when the store opens it and
//! compared with whatever is at the path later. An open SQLite connection keeps writing to a
//! file deleted or replaced under it, and all of that is lost when the server stops; comparing
//! the identity is how the server notices instead of accepting jobs into an unlinked file.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

/// The file as opened.
#[derive(Debug)]
pub struct DbFile {
    path: PathBuf,
    identity: Identity,
    /// Whether the loss was logged already (loudly, with the path, once; the workers' periodic
    /// check repeats it).
    reported: AtomicBool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Identity {
    dev: u64,
    ino: u64,
}

fn identity(path: &std::path::Path) -> std::io::Result<Identity> {
    let meta = std::fs::metadata(path)?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        Ok(Identity {
            dev: meta.dev(),
            ino: meta.ino(),
        })
    }
    #[cfg(not(unix))]
    {
        // No inode to compare: only a deleted file is noticed.
        let _ = meta;
        Ok(Identity { dev: 0, ino: 0 })
    }
}

impl DbFile {
    /// The file's path.
    pub fn path(&self) -> &std::path::Path {
        &self.path
    }

    /// Records the identity of the file now at `path`.
    pub fn opened(path: PathBuf) -> std::io::Result<DbFile> {
        let identity = identity(&path)?;
        Ok(DbFile {
            path,
            identity,
            reported: AtomicBool::new(false),
        })
    }

    /// `Err` saying what happened (without the path, which clients need not see) when the
    /// path no longer holds the file opened; the log names the path.
    pub fn check(&self) -> Result<(), String> {
        let problem = match identity(&self.path) {
            Ok(now) if now == self.identity => return Ok(()),
            Ok(_) => "was replaced by another file",
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => "was deleted",
            Err(_) => "cannot be read",
        };
        if !self.reported.swap(true, Ordering::Relaxed) {
            self.log(problem);
        }
        Err(format!(
            "the database file {problem} while the server was running; nothing more is \
             written until it is restored or the server restarts"
        ))
    }

    fn log(&self, problem: &str) {
        tracing::error!(
            path = %self.path.display(),
            "the database file {problem} while the server was running: every write is refused \
             (503) and what was written since it went is lost at shutdown; restore the file or \
             restart the server"
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_deleted_or_replaced_file_is_noticed_and_a_restored_one_is_not_the_same() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("db");
        std::fs::write(&path, b"a").unwrap();
        let f = DbFile::opened(path.clone()).unwrap();
        assert!(f.check().is_ok());
        // Keep the old inode alive so the new file cannot reuse its number.
        let keep = dir.path().join("old");
        std::fs::rename(&path, &keep).unwrap();
        let err = f.check().unwrap_err();
        assert!(err.contains("was deleted"), "{err}");
        std::fs::write(&path, b"b").unwrap();
        let err = f.check().unwrap_err();
        assert!(err.contains("was replaced"), "{err}");
    }
}
