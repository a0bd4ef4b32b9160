//! What wgsph wrote into an output folder: DIR/.wgsph.files lists every file a run (and the
//! commands that write into its folder after it: `plot`, `surface`) made there, one path
//! relative to DIR a line, each recorded (and synced) before the file is first created, so a
//! run killed at any moment leaves no file of its own unlisted.
//!
//! A new run into the folder removes what the manifest lists, and nothing else: a folder that
//! holds a file by one of the names a run writes ([`is_run_output`]) that no manifest lists (the
//! user's own `run.json` or `probes/p1.csv`, issue 64: a case named ".." ran into the working
//! directory and deleted them) is refused, so a run never deletes or overwrites a file it did
//! not write. Each rank of a run over several writes its own list (`.wgsph.files.pRRRR`).

use std::collections::{BTreeSet, HashSet};
use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};

use super::{write_atomic, OutputError};

/// The manifest's name in the output folder (of one whole run, or rank 0 of several).
pub const MANIFEST_FILE: &str = ".wgsph.files";

/// The manifest of rank `rank` (0: [`MANIFEST_FILE`]).
fn manifest_name(rank: usize) -> String {
    match rank {
        0 => MANIFEST_FILE.to_string(),
        r => format!("{MANIFEST_FILE}.p{r:04}"),
    }
}

/// One process's manifest of an output folder.
#[derive(Debug)]
pub struct Manifest {
    dir: PathBuf,
    path: PathBuf,
    listed: HashSet<String>,
}

impl Manifest {
    /// Rank `rank`'s manifest of `dir` (0 for one whole run and the commands after it), with
    /// what every rank's lists already (a file of the run's that another rank listed is the
    /// run's too).
    pub fn open(dir: &Path, rank: usize) -> Result<Self, OutputError> {
        let path = dir.join(manifest_name(rank));
        let listed = listed(dir)?.into_iter().collect();
        Ok(Manifest {
            dir: dir.to_path_buf(),
            path,
            listed,
        })
    }

    /// Lists `rel` (a path relative to the folder, '/'-separated) unless it is listed already:
    /// appended and synced, before the file is created. A file by that name that is there and
    /// not listed is someone else's: refused, never overwritten.
    pub fn claim(&mut self, rel: &str) -> Result<(), OutputError> {
        if self.listed.contains(rel) {
            return Ok(());
        }
        if std::fs::symlink_metadata(self.dir.join(rel)).is_ok() {
            return Err(OutputError::Foreign {
                dir: self.dir.clone(),
                files: vec![rel.to_string()],
            });
        }
        self.append(rel)
    }

    /// Appends `rel` to the list on disk (synced) and in memory.
    fn append(&mut self, rel: &str) -> Result<(), OutputError> {
        let mut f = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&self.path)
            .map_err(|e| OutputError::io("open", &self.path, e))?;
        writeln!(f, "{rel}")
            .and_then(|()| f.sync_data())
            .map_err(|e| OutputError::io("write", &self.path, e))?;
        self.listed.insert(rel.to_string());
        Ok(())
    }

    /// [`claim`](Self::claim) of `path`, a file inside the folder.
    pub fn claim_path(&mut self, path: &Path) -> Result<(), OutputError> {
        let rel = relative(&self.dir, path).ok_or_else(|| OutputError::Read {
            path: path.to_path_buf(),
            reason: format!("not a file inside the output folder {}", self.dir.display()),
        })?;
        self.claim(&rel)
    }
}

/// Lists in `dir`'s manifest every file there by the names a run writes ([`is_run_output`]):
/// resuming a run whose folder an older wgsph wrote, before it kept a manifest (the checkpoint
/// the resume reads is the evidence that they are the run's). Nothing when a manifest is there.
pub fn adopt_unlisted_outputs(dir: &Path) -> Result<(), OutputError> {
    if !manifests(dir).is_empty() {
        return Ok(());
    }
    let mut m = Manifest::open(dir, 0)?;
    outputs_present(dir)
        .iter()
        .try_for_each(|rel| m.append(rel))
}

/// Writes `dir/rel` atomically (as [`write_atomic`]), listed in `dir`'s manifest first: the
/// commands that add to a finished run's folder (`plot`, `surface`, `validate`'s report).
pub fn write_listed<F>(dir: &Path, rel: &str, write: F) -> Result<(), OutputError>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    Manifest::open(dir, 0)?.claim(rel)?;
    write_atomic(&dir.join(rel), write)
}

/// `path` relative to `dir`, '/'-separated; None when it is not inside.
fn relative(dir: &Path, path: &Path) -> Option<String> {
    let rel = path.strip_prefix(dir).ok()?;
    let parts: Option<Vec<&str>> = rel.components().map(|c| c.as_os_str().to_str()).collect();
    let parts = parts?;
    (!parts.is_empty()
        && parts
            .iter()
            .all(|p| !p.is_empty() && *p != ".." && *p != "."))
    .then(|| parts.join("/"))
}

/// The lines of a manifest (none when it is not there).
fn read_list(path: &Path) -> Result<Vec<String>, OutputError> {
    match std::fs::read(path) {
        Ok(bytes) => Ok(String::from_utf8_lossy(&bytes)
            .lines()
            .filter(|l| !l.is_empty())
            .map(str::to_string)
            .collect()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Vec::new()),
        Err(e) => Err(OutputError::io("read", path, e)),
    }
}

/// Every rank's manifest in `dir`.
fn manifests(dir: &Path) -> Vec<PathBuf> {
    let entries = std::fs::read_dir(dir).into_iter().flatten().flatten();
    let mut found: Vec<PathBuf> = entries
        .map(|e| e.path())
        .filter(|p| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or_default();
            name == MANIFEST_FILE
                || name
                    .strip_prefix(MANIFEST_FILE)
                    .and_then(|r| r.strip_prefix(".p"))
                    .is_some_and(|r| !r.is_empty() && r.bytes().all(|b| b.is_ascii_digit()))
        })
        .collect();
    found.sort();
    found
}

/// What the manifests of `dir` list that is a path inside it (a line that climbs out of the
/// folder is not one wgsph wrote, and is never followed).
fn listed(dir: &Path) -> Result<BTreeSet<String>, OutputError> {
    let mut all = BTreeSet::new();
    for m in manifests(dir) {
        for line in read_list(&m)? {
            if relative(dir, &dir.join(&line)).as_deref() == Some(line.as_str()) {
                all.insert(line);
            }
        }
    }
    Ok(all)
}

/// Whether `rel` (relative to an output folder, '/'-separated) is a name some run or command
/// of wgsph writes there: a new run refuses a folder holding such a file that it did not write.
pub fn is_run_output(rel: &str) -> bool {
    let top = [
        super::PVD_FILE,
        super::RUN_SUMMARY_FILE,
        super::SURFACE_PVD_FILE,
        super::CHECKPOINT_FILE,
    ];
    if top.contains(&rel) || super::is_rank_checkpoint(rel) {
        return true;
    }
    let Some((folder, name)) = rel.split_once('/') else {
        return false;
    };
    let ext = name.rsplit_once('.').map_or("", |(_, e)| e);
    !name.contains('/')
        && match folder {
            super::PARTICLES_DIR => matches!(ext, "vtu" | "pvtu"),
            super::PROBES_DIR => ext == "csv",
            super::SNAPSHOTS_DIR => matches!(ext, "png" | "gif"),
            super::SURFACE_DIR => ext == "vtu",
            super::PLOTS_DIR => matches!(ext, "png" | "csv"),
            _ => false,
        }
}

/// Makes `dir` ready for a new run from t = 0: removes every file its manifests list (an
/// earlier run's outputs, plots and surfaces) and the manifests, after checking that it holds
/// no file a run writes ([`is_run_output`]) that they do not list. Other files stay.
pub fn clear_for_new_run(dir: &Path) -> Result<(), OutputError> {
    let listed = listed(dir)?;
    let foreign: Vec<String> = outputs_present(dir)
        .into_iter()
        .filter(|rel| !listed.contains(rel))
        .collect();
    if !foreign.is_empty() {
        return Err(OutputError::Foreign {
            dir: dir.to_path_buf(),
            files: foreign,
        });
    }
    for rel in &listed {
        let path = dir.join(rel);
        match std::fs::remove_file(&path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(OutputError::io("remove", &path, e))
            }
            _ => {}
        }
    }
    for m in manifests(dir) {
        std::fs::remove_file(&m).map_err(|e| OutputError::io("remove", &m, e))?;
    }
    Ok(())
}

/// The files in `dir` (and its output subfolders) by the names a run writes.
fn outputs_present(dir: &Path) -> Vec<String> {
    let names = |d: &Path| -> Vec<String> {
        let entries = std::fs::read_dir(d).into_iter().flatten().flatten();
        let mut v: Vec<String> = entries
            .filter(|e| e.file_type().is_ok_and(|t| !t.is_dir()))
            .filter_map(|e| e.file_name().to_str().map(str::to_string))
            .collect();
        v.sort();
        v
    };
    let top = names(dir).into_iter();
    let sub = [
        super::PARTICLES_DIR,
        super::PROBES_DIR,
        super::SNAPSHOTS_DIR,
        super::SURFACE_DIR,
        super::PLOTS_DIR,
    ]
    .into_iter()
    .flat_map(|s| {
        names(&dir.join(s))
            .into_iter()
            .map(move |n| format!("{s}/{n}"))
    });
    top.chain(sub).filter(|rel| is_run_output(rel)).collect()
}

#[cfg(test)]
mod tests {
    use super::super::test_util::temp_dir;
    use super::*;

    fn put(dir: &Path, rel: &str) {
        let p = dir.join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, "x").unwrap();
    }

    #[test]
    fn listed_files_are_removed_and_others_kept() {
        let d = temp_dir("manifest");
        let mut m = Manifest::open(&d, 0).unwrap();
        for rel in [
            "run.json",
            "probes/p1.csv",
            "particles/particles_000000.vtu",
        ] {
            m.claim(rel).unwrap();
            m.claim(rel).unwrap();
            put(&d, rel);
        }
        let mut r1 = Manifest::open(&d, 1).unwrap();
        r1.claim("particles/particles_000000_p0001.vtu").unwrap();
        put(&d, "particles/particles_000000_p0001.vtu");
        put(&d, "notes.txt");
        put(&d, "probes/readme.md");
        // Listed once, however often claimed.
        assert_eq!(read_list(&d.join(MANIFEST_FILE)).unwrap().len(), 3);
        clear_for_new_run(&d).unwrap();
        assert!(d.join("notes.txt").is_file() && d.join("probes/readme.md").is_file());
        assert!(outputs_present(&d).is_empty());
        assert!(manifests(&d).is_empty());
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A folder holding files by a run's names that no manifest lists is refused, naming them,
    /// and nothing in it is removed (issue 64: `name = ".."` ran into the working directory).
    #[test]
    fn a_folder_with_files_the_run_did_not_write_is_refused() {
        let d = temp_dir("manifest-foreign");
        Manifest::open(&d, 0)
            .unwrap()
            .claim("probes/p1.csv")
            .unwrap();
        put(&d, "run.json");
        put(&d, "probes/p1.csv");
        put(&d, "plots/p1.png");
        let e = clear_for_new_run(&d).unwrap_err().to_string();
        assert!(e.contains("run.json") && e.contains("plots/p1.png"), "{e}");
        assert!(!e.contains("probes/p1.csv"), "{e}");
        for rel in ["run.json", "probes/p1.csv", "plots/p1.png"] {
            assert!(d.join(rel).is_file(), "{rel}");
        }
        // Nor is a file that is there and not listed ever written over.
        let e = Manifest::open(&d, 0)
            .unwrap()
            .claim("run.json")
            .unwrap_err();
        assert!(e.to_string().contains("run.json"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A manifest line that leads out of the folder is never followed.
    #[test]
    fn lines_leaving_the_folder_are_ignored() {
        let base = temp_dir("manifest-escape");
        let d = base.join("out");
        put(&base, "victim.csv");
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join(MANIFEST_FILE), "../victim.csv\n/etc/passwd\n./x\n").unwrap();
        clear_for_new_run(&d).unwrap();
        assert!(base.join("victim.csv").is_file());
        let mut m = Manifest::open(&d, 0).unwrap();
        assert!(m.claim_path(&base.join("victim.csv")).is_err());
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn run_output_names() {
        for yes in [
            "run.json",
            "particles.pvd",
            "checkpoint.bin",
            "checkpoint_g1_p0002.bin",
            "particles/particles_000003.vtu",
            "particles/particles_000003.pvtu",
            "probes/anything.csv",
            "snapshots/000001.png",
            "surface/surface_000001.vtu",
            "surface.pvd",
            "plots/errors.csv",
        ] {
            assert!(is_run_output(yes), "{yes}");
        }
        for no in [
            "notes.txt",
            "probes/a.txt",
            "data/run.json",
            "checkpoint_x.bin",
            ".wgsph.lock",
        ] {
            assert!(!is_run_output(no), "{no}");
        }
    }
}
