//! Creating a recording's file.

use std::fs::File;
use std::io;
use std::path::Path;

/// Creates `path`, replacing an old regular file by removing it first rather than truncating it:
/// on ext4 a file truncated and written again is flushed to disk synchronously when it is closed
/// (`auto_da_alloc`), which cost a 30 s run that overwrote its previous recordings 30–60 ms.
/// Anything else at `path` (a symlink, `/dev/null`, a FIFO) is opened and written as it is.
///
/// The old file is opened before its name is removed, so the removal itself is quick: its data is
/// freed when that last handle closes, on a thread of its own ([`Replaced`]). Freeing a recording
/// the kernel is still writing to disk waits for the disk: 3–5 ms of a 30 s run's start, with one
/// core idle, when it overwrote the last run's files.
pub fn create_replacing(path: &Path) -> io::Result<(File, Replaced)> {
    let mut replaced = Replaced { freeing: None };
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_file()) {
        let old = File::open(path).ok();
        // in a folder we may not remove from, `create` still truncates it (or says what is wrong)
        if std::fs::remove_file(path).is_ok()
            && let Some(old) = old
        {
            // (if no thread can be started, the handle closes here, as a plain removal would)
            replaced.freeing = std::thread::Builder::new().name("free old file".into()).spawn(move || drop(old)).ok();
        }
    }
    Ok((File::create(path)?, replaced))
}

/// The old file a [`create_replacing`] removed, being freed on a thread of its own. Dropping it
/// waits for that (keep it until the new file is written: by then it is long done), so that the
/// process never ends with the old data still held.
#[must_use = "dropped at once, it waits for the old file to be freed"]
pub struct Replaced {
    freeing: Option<std::thread::JoinHandle<()>>,
}

impl Drop for Replaced {
    fn drop(&mut self) {
        if let Some(freeing) = self.freeing.take() {
            let _ = freeing.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::create_replacing;
    use std::io::Write;

    #[test]
    fn a_replaced_file_holds_only_the_new_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.rrd");
        std::fs::write(&path, b"an older and longer recording").unwrap();
        let (mut file, replaced) = create_replacing(&path).unwrap();
        file.write_all(b"new").unwrap();
        drop(replaced);
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        // the old data went with its name: nothing else is left in the folder
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        // and a file that was not there is created
        let fresh = dir.path().join("fresh.mcap");
        create_replacing(&fresh).unwrap().0.write_all(b"x").unwrap();
        assert_eq!(std::fs::read(&fresh).unwrap(), b"x");
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_is_written_through_not_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let (target, link) = (dir.path().join("kept.rrd"), dir.path().join("latest.rrd"));
        std::fs::write(&target, b"old").unwrap();
        std::os::unix::fs::symlink(&target, &link).unwrap();
        create_replacing(&link).unwrap().0.write_all(b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link is still a link");
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
    }

    #[cfg(unix)]
    #[test]
    fn dev_null_is_written_to_not_removed() {
        // as root, removing it would delete the system's /dev/null
        create_replacing(std::path::Path::new("/dev/null")).unwrap().0.write_all(b"discarded").unwrap();
        assert!(!std::fs::symlink_metadata("/dev/null").unwrap().file_type().is_file());
    }

    #[test]
    fn a_path_that_cannot_be_a_file_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        assert!(create_replacing(dir.path()).is_err(), "a directory is not replaced");
    }
}
