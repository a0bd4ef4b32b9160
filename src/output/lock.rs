//! The exclusive lock of an output folder: DIR/.wgsph.lock, holding the pid of the run that
//! writes there. Two runs into one folder would mix their files (one renaming its CSVs while
//! the other removes them, issue 36), so a second `run` or `resume` of the folder is refused
//! while the first lives. The file is created with `create_new` (atomic: of two runs starting
//! at once, one gets it) and removed when the run ends, on its error paths too (Drop; Ctrl-C
//! and SIGTERM end a run normally, with a checkpoint). A run killed outright (SIGKILL, power
//! loss) leaves it behind: a lock whose pid is no longer alive is taken over, and so is one
//! whose pid now names another process (the lock holds the process's start time too: a
//! reused pid was taken for "another wgsph run", issue 64).

use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use super::OutputError;

/// The lock file's name in the output folder.
pub const LOCK_FILE: &str = ".wgsph.lock";

/// Held for a run's life; dropping it removes the lock file.
#[derive(Debug)]
pub struct DirLock {
    path: PathBuf,
    pid: u32,
}

impl DirLock {
    /// Takes the lock of `dir` (which must exist) for this process; errors naming the folder
    /// and the other process when a live one holds it.
    pub fn acquire(dir: &Path) -> Result<Self, OutputError> {
        let path = dir.join(LOCK_FILE);
        let pid = std::process::id();
        // Each pass either takes the lock, refuses, or removes one stale lock; a few passes
        // are only needed when other runs race for the same folder.
        for _ in 0..16 {
            match OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(mut f) => {
                    write_pid(&mut f, pid).map_err(|e| OutputError::io("write", &path, e))?;
                    return Ok(DirLock { path, pid });
                }
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
                Err(e) => return Err(OutputError::io("create", &path, e)),
            }
            let (holder, started) = match read_holder(&path) {
                Ok(p) => p,
                // Removed between our attempt and the read: try again.
                Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
                Err(e) => return Err(OutputError::io("read", &path, e)),
            };
            match holder {
                Some(other)
                    if alive(other) && started.is_none_or(|s| start_time(other) == Some(s)) =>
                {
                    return Err(OutputError::Locked {
                        dir: dir.to_path_buf(),
                        pid: other,
                        lock: path,
                    })
                }
                // A run that created the file but has not written its pid yet.
                None if fresh(&path) => {
                    std::thread::sleep(std::time::Duration::from_millis(50));
                    continue;
                }
                _ => take_over(dir, &path, holder, pid)?,
            }
        }
        Err(OutputError::Locked {
            dir: dir.to_path_buf(),
            pid: read_pid(&path).ok().flatten().unwrap_or(0),
            lock: path,
        })
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        // Only our own lock: never one another run took over since (it could not while this
        // process lives, but a pid read back costs nothing).
        if read_pid(&self.path).ok().flatten() == Some(self.pid) {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// "pid start-time": the process and when it started (where that can be read).
fn write_pid(f: &mut File, pid: u32) -> io::Result<()> {
    match start_time(pid) {
        Some(start) => writeln!(f, "{pid} {start}")?,
        None => writeln!(f, "{pid}")?,
    }
    f.sync_all()
}

/// The pid in a lock file; None when it holds none (empty or garbled).
fn read_pid(path: &Path) -> io::Result<Option<u32>> {
    Ok(read_holder(path)?.0)
}

/// The pid in a lock file and its process's start time, where written (a lock of an older
/// wgsph holds the pid alone).
fn read_holder(path: &Path) -> io::Result<(Option<u32>, Option<u64>)> {
    let text = std::fs::read_to_string(path)?;
    let mut words = text.split_whitespace();
    let pid = words.next().and_then(|w| w.parse().ok());
    Ok((pid, words.next().and_then(|w| w.parse().ok())))
}

/// When process `pid` started (clock ticks since boot: /proc/PID/stat's 22nd field), on Linux;
/// a pid that names another process after its own ended has another.
fn start_time(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // After "pid (command)": state is field 3, so the start time is the 20th word after ')'.
    let (_, rest) = stat.rsplit_once(')')?;
    rest.split_whitespace().nth(19)?.parse().ok()
}

/// Whether a lock file without a pid is young enough to be a run still writing it.
fn fresh(path: &Path) -> bool {
    std::fs::metadata(path)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.elapsed().ok())
        .is_some_and(|age| age.as_secs_f64() < 2.0)
}

/// Removes the stale lock `path` (held by `stale`, a dead pid, or by none): renamed aside
/// first, atomically, so that of two runs taking it over at once only one removes it; the
/// other's rename fails, or catches the lock the first has just created, which it then puts
/// back.
fn take_over(dir: &Path, path: &Path, stale: Option<u32>, pid: u32) -> Result<(), OutputError> {
    let aside = dir.join(format!("{LOCK_FILE}.stale-{pid}"));
    match std::fs::rename(path, &aside) {
        Ok(()) => {}
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(OutputError::io("rename", path, e)),
    }
    let caught = read_pid(&aside).ok().flatten();
    if caught != stale {
        // Another run's fresh lock: back where it was (hard_link never replaces a file).
        let _ = std::fs::hard_link(&aside, path);
    } else if let Some(dead) = stale {
        log::warn!(
            "{}: taking over the lock of process {dead}, which is no longer running (a run \
             killed before it could remove it)",
            dir.display()
        );
    }
    std::fs::remove_file(&aside).map_err(|e| OutputError::io("remove", &aside, e))
}

/// Whether process `pid` is alive. On Linux by /proc, where a zombie (a process that ended
/// and that its parent has not reaped yet: a rank just killed with its MPI job) keeps its
/// entry but runs nothing; elsewhere a lock is never taken to be stale (the error says to
/// remove the file).
fn alive(pid: u32) -> bool {
    if !cfg!(target_os = "linux") {
        return true;
    }
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
        return false;
    };
    // "pid (command) state …": the command may hold spaces and parentheses.
    let state = stat
        .rsplit_once(')')
        .and_then(|(_, rest)| rest.trim_start().chars().next());
    !matches!(state, Some('Z' | 'X'))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("wgsph-lock-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn a_second_lock_is_refused_and_the_first_is_removed_on_drop() {
        let d = scratch("twice");
        std::fs::create_dir_all(&d).unwrap();
        let first = DirLock::acquire(&d).unwrap();
        let lock = d.join(LOCK_FILE);
        assert_eq!(read_pid(&lock).unwrap(), Some(std::process::id()));
        let e = DirLock::acquire(&d).unwrap_err().to_string();
        assert!(e.contains(&std::process::id().to_string()), "{e}");
        assert!(e.contains(&d.display().to_string()), "{e}");
        drop(first);
        assert!(!lock.exists());
        drop(DirLock::acquire(&d).unwrap());
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A process that has ended but is not reaped yet (a zombie) holds no lock.
    #[test]
    #[cfg(target_os = "linux")]
    fn a_zombie_is_not_alive() {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        let start = std::time::Instant::now();
        while alive(pid) {
            assert!(start.elapsed().as_secs() < 10, "`true` still runs");
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        // Not reaped until now: its /proc entry was there all along.
        assert!(Path::new("/proc").join(pid.to_string()).exists());
        child.wait().unwrap();
        assert!(alive(std::process::id()));
    }

    #[test]
    fn a_dead_or_garbled_lock_is_taken_over() {
        let d = scratch("stale");
        std::fs::create_dir_all(&d).unwrap();
        let lock = d.join(LOCK_FILE);
        // Beyond Linux's pid_max (2^22): no process has it.
        for stale in ["4194305\n", "not a pid"] {
            std::fs::write(&lock, stale).unwrap();
            if stale.starts_with('n') {
                // Old enough not to be a run still writing its pid.
                let old = std::time::SystemTime::now() - std::time::Duration::from_secs(10);
                File::options()
                    .write(true)
                    .open(&lock)
                    .unwrap()
                    .set_modified(old)
                    .unwrap();
            }
            let l = DirLock::acquire(&d).unwrap();
            assert_eq!(read_pid(&lock).unwrap(), Some(std::process::id()));
            drop(l);
        }
        // A live pid that started at another time: the pid of a run that ended, reused.
        #[cfg(target_os = "linux")]
        {
            let me = std::process::id();
            let start = start_time(me).expect("this process's start time");
            std::fs::write(&lock, format!("{me} {}\n", start + 1)).unwrap();
            let l = DirLock::acquire(&d).expect("a reused pid holds no lock");
            assert_eq!(
                std::fs::read_to_string(&lock).unwrap(),
                format!("{me} {start}\n")
            );
            drop(l);
        }
        assert_eq!(
            std::fs::read_dir(&d).unwrap().count(),
            0,
            "nothing left aside"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }
}
