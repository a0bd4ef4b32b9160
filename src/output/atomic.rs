//! Write-to-temp-then-rename helper.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use super::OutputError;

/// Buffer size of the writer handed to the closure (large: snapshots are hundreds of MB).
const BUF_CAPACITY: usize = 1 << 20;

/// The temporary name used for `path`: `<path>.tmp-<pid>` in the same folder.
pub(crate) fn temp_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".tmp-{}", std::process::id()));
    path.with_file_name(name)
}

/// Removes the temporary files ([`temp_path`] names) in `dir` that a killed run left behind
/// (best effort: a file that cannot be removed stays).
pub(crate) fn remove_stale_temps(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let is_temp = name
            .to_str()
            .and_then(|n| n.rsplit_once(".tmp-"))
            .is_some_and(|(_, pid)| !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()));
        if is_temp && e.file_type().is_ok_and(|t| t.is_file()) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Writes a file atomically: `write` fills a buffered writer on `<path>.tmp-<pid>` (same folder),
/// which is then flushed, fsynced and renamed onto `path`; finally the folder is fsynced (best
/// effort) so the rename itself is durable. If anything fails — including the closure returning
/// an error — the temporary file is removed and `path` is left untouched (the previous version,
/// if any, stays in place).
pub fn write_atomic<F>(path: &Path, write: F) -> Result<(), OutputError>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let tmp = temp_path(path);
    let result = write_and_rename(path, &tmp, write);
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn write_and_rename<F>(path: &Path, tmp: &Path, write: F) -> Result<(), OutputError>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let file = File::create(tmp).map_err(|e| OutputError::io("create", tmp, e))?;
    let mut w = BufWriter::with_capacity(BUF_CAPACITY, file);
    write(&mut w).map_err(|e| OutputError::io("write", path, e))?;
    let file = w
        .into_inner()
        .map_err(|e| OutputError::io("write", path, e.into_error()))?;
    file.sync_all()
        .map_err(|e| OutputError::io("sync", tmp, e))?;
    drop(file);
    std::fs::rename(tmp, path)
        .map_err(|e| OutputError::io("rename temporary file onto", path, e))?;
    sync_parent_dir(path);
    Ok(())
}

/// Best effort: makes the directory entry change durable (no-op where folders cannot be opened).
fn sync_parent_dir(path: &Path) {
    #[cfg(unix)]
    {
        let parent = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        if let Ok(d) = File::open(parent) {
            let _ = d.sync_all();
        }
    }
    #[cfg(not(unix))]
    let _ = path;
}

#[cfg(test)]
mod tests {
    use super::super::test_util::temp_dir;
    use super::*;

    #[test]
    fn writes_content_and_leaves_no_temp() {
        let d = temp_dir("atomic-ok");
        let p = d.join("a.txt");
        write_atomic(&p, |w| w.write_all(b"hello")).unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"hello");
        // Overwrite an existing file.
        write_atomic(&p, |w| w.write_all(b"second")).unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
        assert!(!temp_path(&p).exists());
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn failing_writer_leaves_nothing() {
        let d = temp_dir("atomic-fail");
        let p = d.join("b.txt");
        let err = write_atomic(&p, |w| {
            w.write_all(&[7u8; 3 << 20])?; // more than the buffer: really hits the temp file
            Err(io::Error::other("boom"))
        })
        .unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("boom") && msg.contains("b.txt"), "{msg}");
        assert!(!p.exists());
        assert!(!temp_path(&p).exists());
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn failing_writer_keeps_previous_version() {
        let d = temp_dir("atomic-keep");
        let p = d.join("c.txt");
        write_atomic(&p, |w| w.write_all(b"old")).unwrap();
        assert!(write_atomic(&p, |w| {
            w.write_all(b"new but incomplete")?;
            Err(io::Error::other("killed"))
        })
        .is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn missing_folder_error_names_path() {
        let d = temp_dir("atomic-missing");
        let p = d.join("no/such/dir/x.txt");
        let msg = write_atomic(&p, |w| w.write_all(b"x"))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("x.txt.tmp-") && msg.contains("os error"),
            "{msg}"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn temp_name_is_in_same_folder() {
        let p = Path::new("/some/dir/run.json");
        let t = temp_path(p);
        assert_eq!(t.parent(), p.parent());
        assert_eq!(
            t.file_name().unwrap().to_str().unwrap(),
            format!("run.json.tmp-{}", std::process::id())
        );
    }
}
