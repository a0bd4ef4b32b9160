//! Crash-safe output: particle snapshots (ParaView `.vtu` + `.pvd` series), probe CSV time
//! series and the run summary JSON.
//!
//! Every file is written with [`write_atomic`]: the content goes to a temporary file in the same
//! folder, is flushed and fsynced, then renamed onto the final name. A run killed at any moment
//! therefore leaves either the previous complete version of a file or the new complete one, never
//! a truncated file. Snapshot `.vtu` files are renamed into place before the `.pvd` that lists
//! them is rewritten, so the series never references a missing or partial file.
//!
//! Layout of an output directory `DIR`:
//!
//! ```text
//! DIR/particles.pvd                     series index (time + relative file per snapshot)
//! DIR/particles/particles_000000.vtu    one file per snapshot, raw appended binary
//!     (a run over N ranks: particles_000000.pvtu naming one piece per rank,
//!     particles_000000_p0000.vtu … _pNNNN.vtu, each rank's own particles)
//! DIR/probes/<name>.csv                 "t_s,<column>" time series per probe
//! DIR/run.json                          run summary
//! DIR/snapshots/NNNNNN.png              with --snapshots: a picture of each particle snapshot
//! DIR/maps/<quantity>.asc, .png         with [maps]: flood maps (ESRI ASCII grids, pictures)
//! DIR/surface.pvd, DIR/surface/surface_NNNNNN.vtu   `wgsph surface`: the water's surface
//! ```

mod atomic;
#[cfg(test)]
mod damaged_files;
pub mod esri_ascii;
pub mod flood_maps;
mod lock;
mod manifest;
mod particle_file;
mod probes_csv;
mod pvd;
mod run_summary;
mod vtu;

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

pub use crate::particles::Particles;
pub use atomic::write_atomic;
pub use lock::{DirLock, LOCK_FILE};
pub use manifest::{
    adopt_unlisted_outputs, clear_for_new_run, is_run_output, write_listed, Manifest, MANIFEST_FILE,
};
pub use particle_file::{particle_files, FirstPositions, ParticleFile};
pub use probes_csv::ProbeWriter;
pub use run_summary::RunSummary;

/// Name of the series file inside the output directory.
pub const PVD_FILE: &str = "particles.pvd";
/// Name of the snapshot folder inside the output directory.
pub const PARTICLES_DIR: &str = "particles";
/// Name of the probe folder inside the output directory.
pub const PROBES_DIR: &str = "probes";
/// Name of the folder of snapshot pictures (`NNNNNN.png`, the index of the `.vtu`).
pub const SNAPSHOTS_DIR: &str = "snapshots";
/// Name of the run summary file inside the output directory.
pub const RUN_SUMMARY_FILE: &str = "run.json";
/// Name of the folder of free-surface meshes (`wgsph surface`: `surface_NNNNNN.vtu`, the index
/// of the particle file) and of their series file.
pub const SURFACE_DIR: &str = "surface";
pub const SURFACE_PVD_FILE: &str = "surface.pvd";

/// Folder of the plots inside a run directory (`wgsph plot`).
pub const PLOTS_DIR: &str = "plots";
/// Name of the checkpoint file inside the output directory (of one whole run; of rank 0 of
/// several, the manifest naming the other ranks' files).
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";

/// The checkpoint file of rank `rank` (> 0) of a run over several ranks, in generation
/// `generation` (0 or 1).
pub fn rank_checkpoint_file(rank: usize, generation: u32) -> String {
    format!("checkpoint_g{generation}_p{rank:04}.bin")
}

/// Whether `name` is a name [`rank_checkpoint_file`] gives.
pub fn is_rank_checkpoint(name: &str) -> bool {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    (name.strip_prefix("checkpoint_g"))
        .and_then(|r| r.strip_suffix(".bin"))
        .and_then(|r| r.split_once("_p"))
        .is_some_and(|(g, r)| digits(g) && digits(r))
}

/// A triangle mesh of the water's surface at one output (`wgsph surface`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceMesh {
    pub time_s: f64,
    pub vertices: Vec<[f64; 3]>,
    /// Vertex indices, counter-clockwise seen from outside the water.
    pub triangles: Vec<[usize; 3]>,
}

impl SurfaceMesh {
    /// Reads a mesh [`write_surface`] wrote; errors name the file and what is wrong.
    pub fn read(path: &Path) -> Result<Self, OutputError> {
        let bytes = std::fs::read(path).map_err(|e| OutputError::io("read", path, e))?;
        Self::parse(&bytes).map_err(|reason| OutputError::Read {
            path: path.to_path_buf(),
            reason,
        })
    }

    pub(super) fn parse(bytes: &[u8]) -> Result<Self, String> {
        let v = vtu::reader::Vtu::parse(bytes)?;
        let points = v.f64s("Points", 3)?;
        let corners = match v.arrays.get("connectivity").map(|a| a.vtk_type.as_str()) {
            Some("Int64") => v
                .i64s("connectivity")?
                .into_iter()
                .map(|c| c as usize)
                .collect(),
            _ => (v.i32s("connectivity")?.into_iter())
                .map(|c| c as usize)
                .collect::<Vec<_>>(),
        };
        if Some(corners.len()) != v.number_of_cells.checked_mul(3)
            || corners.iter().any(|&c| c >= v.number_of_points)
        {
            return Err("its cells are not triangles of its points".into());
        }
        Ok(SurfaceMesh {
            time_s: v.f64s("TimeValue", 1)?.first().copied().unwrap_or(f64::NAN),
            vertices: points.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            triangles: corners
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        })
    }
}

/// Creates DIR/surface (an existing one is fine) and removes the temporary files a killed
/// `wgsph surface` may have left there; before the first [`write_surface`].
pub fn create_surface_dir(dir: &Path) -> Result<(), OutputError> {
    let folder = dir.join(SURFACE_DIR);
    std::fs::create_dir_all(&folder)
        .map_err(|e| OutputError::io("create directory", &folder, e))?;
    atomic::remove_stale_temps(&folder);
    Ok(())
}

/// Writes `mesh`, the surface of particle file `index`, as DIR/surface/surface_NNNNNN.vtu,
/// atomically. Returns its (time, path relative to DIR) for [`write_surface_series`].
pub fn write_surface(
    dir: &Path,
    index: usize,
    mesh: &SurfaceMesh,
) -> Result<(f64, String), OutputError> {
    let rel = format!("{SURFACE_DIR}/surface_{index:06}.vtu");
    write_listed(dir, &rel, |w| vtu::write_triangles_vtu(w, mesh))?;
    Ok((mesh.time_s, rel))
}

/// Writes DIR/surface.pvd listing the surfaces `series` ([`write_surface`]'s), atomically.
pub fn write_surface_series(dir: &Path, series: &[(f64, String)]) -> Result<PathBuf, OutputError> {
    write_listed(dir, SURFACE_PVD_FILE, |w| pvd::write_pvd(w, series))?;
    Ok(dir.join(SURFACE_PVD_FILE))
}

/// Errors of the output module. Every message names the path involved and, for I/O failures,
/// the OS error (which is part of the message rather than a chained `source`, so that
/// `anyhow`'s `{:#}` does not print it twice).
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// An I/O operation (`action`, e.g. "create directory", "write", "rename") failed on `path`.
    #[error("cannot {action} {}: {error}", path.display())]
    Io {
        action: &'static str,
        path: PathBuf,
        error: io::Error,
    },
    /// The run summary could not be serialized to JSON.
    #[error("cannot serialize run summary for {}: {error}", path.display())]
    Json {
        path: PathBuf,
        error: serde_json::Error,
    },
    /// A snapshot array does not have one entry per particle (`pos.len()`).
    #[error(
        "snapshot for {}: array `{array}` has {len} entries, expected {expected} (one per particle)",
        path.display()
    )]
    SnapshotLength {
        path: PathBuf,
        array: &'static str,
        len: usize,
        expected: usize,
    },
    /// `ProbeWriter::record` got a number of values different from the number of probes.
    #[error("probe writer for {}: record() got {got} values for {expected} probes", dir.display())]
    ProbeCount {
        dir: PathBuf,
        expected: usize,
        got: usize,
    },
    /// A run cannot be resumed into this output (the checkpoint and the files disagree).
    #[error("cannot resume into {}: {reason}", path.display())]
    Resume { path: PathBuf, reason: String },
    /// A probe name cannot be used as a file name (empty, path separator, duplicate, ...).
    #[error("invalid probe name {name:?} in {}: {reason}", dir.display())]
    ProbeName {
        dir: PathBuf,
        name: String,
        reason: &'static str,
    },
    /// Another live run holds the output folder's lock (`lock::DirLock`).
    #[error(
        "{} is in use by another wgsph run (process {pid}, lock file {}): two runs into one \
         folder would mix their files; wait for it to finish or choose another --out (if no \
         such run is alive, remove the lock file)",
        dir.display(),
        lock.display()
    )]
    Locked {
        dir: PathBuf,
        pid: u32,
        lock: PathBuf,
    },
    /// A file the engine wrote cannot be read back (`reason` says why).
    #[error("cannot read {}: {reason}", path.display())]
    Read { path: PathBuf, reason: String },
    /// The output folder holds files by the names a run writes that no run wrote there
    /// (`manifest::clear_for_new_run`).
    #[error(
        "{} holds {} that wgsph did not write there ({}{}): a run never deletes or overwrites          files it did not write; choose another --out, or move those files away (an output          folder of a wgsph older than its manifest {}: remove the folder)",
        dir.display(),
        match files.len() { 1 => "a file".to_string(), n => format!("{n} files") },
        files.iter().take(5).map(String::as_str).collect::<Vec<_>>().join(", "),
        if files.len() > 5 { ", ..." } else { "" },
        MANIFEST_FILE
    )]
    Foreign { dir: PathBuf, files: Vec<String> },
}

impl OutputError {
    pub(crate) fn io(action: &'static str, path: &Path, error: io::Error) -> Self {
        OutputError::Io {
            action,
            path: path.to_path_buf(),
            error,
        }
    }
}

/// One snapshot of all particles, positions already in f64 world coordinates.
#[derive(Clone, Copy)]
pub struct Snapshot<'a> {
    pub time_s: f64,
    pub pos: &'a [[f64; 3]],
    pub vel: &'a [[f32; 3]],
    pub rho: &'a [f32],
    pub pressure: &'a [f32],
    /// 0 fluid, 1 wall, ...
    pub kind: &'a [u32],
    /// Stable particle id.
    pub id: &'a [u32],
    /// Further per-particle scalars written as PointData (e.g. `("energy", e)`).
    pub extra: &'a [(&'a str, &'a [f32])],
}

impl Snapshot<'_> {
    /// Number of particles (`pos.len()`).
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    /// Checks that every array has one entry per particle; `path` is only used in the error.
    pub fn validate(&self, path: &Path) -> Result<(), OutputError> {
        let n = self.pos.len();
        let lens = [
            ("vel", self.vel.len()),
            ("rho", self.rho.len()),
            ("pressure", self.pressure.len()),
            ("kind", self.kind.len()),
            ("id", self.id.len()),
        ];
        for (_, a) in self.extra {
            if a.len() != n {
                return Err(OutputError::SnapshotLength {
                    path: path.to_path_buf(),
                    array: "extra",
                    len: a.len(),
                    expected: n,
                });
            }
        }
        for (array, len) in lens {
            if len != n {
                return Err(OutputError::SnapshotLength {
                    path: path.to_path_buf(),
                    array,
                    len,
                    expected: n,
                });
            }
        }
        Ok(())
    }
}

/// The name of the particle file of output `index`: `particles_NNNNNN.vtu` (6 digits, from 0).
pub fn particle_file_name(index: usize) -> String {
    format!("particles_{index:06}.vtu")
}

/// `DIR/particles/particles_NNNNNN.vtu` of output `index` of the run in `dir`.
pub fn particle_file_path(dir: &Path, index: usize) -> PathBuf {
    dir.join(PARTICLES_DIR).join(particle_file_name(index))
}

/// The index of output `index` of a run over several ranks: `particles_NNNNNN.pvtu`.
pub fn pieces_file_name(index: usize) -> String {
    format!("particles_{index:06}.pvtu")
}

/// Rank `rank`'s piece of the output whose `.pvtu` is `pvtu` (a path or a name):
/// `particles_NNNNNN_pRRRR.vtu` beside it.
fn piece_of(pvtu: &str, rank: usize) -> String {
    format!("{}_p{rank:04}.vtu", pvtu.trim_end_matches(".pvtu"))
}

/// Which piece of a run over several ranks an [`OutputDir`] writes.
#[derive(Clone, Copy, Debug)]
pub struct Piece {
    pub rank: usize,
    pub ranks: usize,
}

/// An output directory: owns the snapshot series and creates probe writers.
#[derive(Debug)]
pub struct OutputDir {
    dir: PathBuf,
    /// (time, path relative to `dir` with '/' separators) of every snapshot written so far
    /// (of a run over several ranks, its `.pvtu`).
    snapshots: Vec<(f64, String)>,
    /// Set for a run over several ranks: each output is one `.vtu` piece per rank and a
    /// `.pvtu` naming them (written by rank 0, [`OutputDir::publish_pieces`]).
    piece: Option<Piece>,
    /// The further scalars of the last piece written (what the `.pvtu` declares).
    extra_names: Vec<String>,
    /// What this process wrote here (rank r of several: its own list).
    manifest: Manifest,
}

impl OutputDir {
    /// Creates DIR, DIR/particles, DIR/probes (existing folders are fine) and removes the
    /// temporary files a killed run may have left in them. Errors name the path.
    pub fn create(dir: &Path) -> Result<Self, OutputError> {
        for d in [
            dir.to_path_buf(),
            dir.join(PARTICLES_DIR),
            dir.join(PROBES_DIR),
        ] {
            std::fs::create_dir_all(&d).map_err(|e| OutputError::io("create directory", &d, e))?;
            atomic::remove_stale_temps(&d);
        }
        atomic::remove_stale_temps(&dir.join(SNAPSHOTS_DIR));
        Ok(OutputDir {
            dir: dir.to_path_buf(),
            snapshots: Vec::new(),
            piece: None,
            extra_names: Vec::new(),
            manifest: Manifest::open(dir, 0)?,
        })
    }

    /// The output directory of rank `piece.rank` of a run over several ranks. Rank 0 creates it
    /// as [`OutputDir::create`] does; the others only make sure its folders are there (rank 0
    /// may already be writing into them), and must come after rank 0's.
    pub fn for_piece(dir: &Path, piece: Piece) -> Result<Self, OutputError> {
        let mut out = match piece.rank {
            0 => Self::create(dir)?,
            _ => {
                let particles = dir.join(PARTICLES_DIR);
                std::fs::create_dir_all(&particles)
                    .map_err(|e| OutputError::io("create directory", &particles, e))?;
                OutputDir {
                    dir: dir.to_path_buf(),
                    snapshots: Vec::new(),
                    piece: None,
                    extra_names: Vec::new(),
                    manifest: Manifest::open(dir, piece.rank)?,
                }
            }
        };
        out.piece = Some(piece);
        Ok(out)
    }

    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// DIR/particles.pvd
    pub fn pvd_path(&self) -> PathBuf {
        self.dir.join(PVD_FILE)
    }

    /// Number of snapshots written so far (also the index of the next one).
    pub fn snapshot_count(&self) -> usize {
        self.snapshots.len()
    }

    /// Particle output `index`'s file (of a run over several ranks, its `.pvtu`), if written.
    pub fn snapshot_file(&self, index: usize) -> Option<PathBuf> {
        (self.snapshots.get(index)).map(|(_, rel)| self.dir.join(rel))
    }

    /// Writes DIR/particles/particles_NNNNNN.vtu (NNNNNN = index, 6 digits, starting at 0)
    /// atomically, then rewrites DIR/particles.pvd atomically listing every snapshot written so
    /// far (time + relative file). The .vtu is fully written and renamed before the .pvd that
    /// references it. Returns the path of the .vtu.
    ///
    /// Of a run over several ranks: writes this rank's piece, `particles_NNNNNN_pRRRR.vtu`, and
    /// returns its path; the series lists the `.pvtu` that [`OutputDir::publish_pieces`]
    /// writes once every rank's piece is in place.
    pub fn write_snapshot(&mut self, snap: &Snapshot) -> Result<PathBuf, OutputError> {
        let index = self.snapshots.len();
        if let Some(piece) = self.piece {
            let rel = format!("{PARTICLES_DIR}/{}", pieces_file_name(index));
            let path = self.dir.join(piece_of(&rel, piece.rank));
            snap.validate(&path)?;
            self.manifest.claim_path(&path)?;
            write_atomic(&path, |w| vtu::write_vtu(w, snap))?;
            self.snapshots.push((snap.time_s, rel));
            self.extra_names = snap.extra.iter().map(|(n, _)| n.to_string()).collect();
            return Ok(path);
        }
        let rel = format!("{PARTICLES_DIR}/{}", particle_file_name(index));
        let vtu_path = particle_file_path(&self.dir, index);
        snap.validate(&vtu_path)?;
        self.manifest.claim(&rel)?;
        write_atomic(&vtu_path, |w| vtu::write_vtu(w, snap))?;
        // The .vtu is complete and in place: from now on it belongs to the series, even if
        // rewriting the .pvd fails (the next snapshot's .pvd rewrite will list it).
        self.snapshots.push((snap.time_s, rel));
        self.write_series()?;
        Ok(vtu_path)
    }

    /// Rank 0 of a run over several ranks, once every rank has written its piece of the last
    /// output: writes that output's `.pvtu`, then the `.pvd` listing it. Nothing on other ranks.
    pub fn publish_pieces(&mut self) -> Result<(), OutputError> {
        let (Some(piece), Some((_, rel))) = (self.piece, self.snapshots.last()) else {
            return Ok(());
        };
        if piece.rank != 0 {
            return Ok(());
        }
        let name = rel.rsplit('/').next().unwrap_or(rel);
        let pieces: Vec<String> = (0..piece.ranks).map(|r| piece_of(name, r)).collect();
        let extra: Vec<&str> = self.extra_names.iter().map(String::as_str).collect();
        let rel = rel.clone();
        self.manifest.claim(&rel)?;
        write_atomic(&self.dir.join(&rel), |w| {
            vtu::write_pvtu(w, &extra, &pieces)
        })?;
        self.write_series()
    }

    /// Rewrites DIR/particles.pvd listing the snapshots so far, atomically.
    fn write_series(&mut self) -> Result<(), OutputError> {
        self.manifest.claim(PVD_FILE)?;
        write_atomic(&self.pvd_path(), |w| pvd::write_pvd(w, &self.snapshots))
    }

    /// Lists `path`, a file of this run inside its folder, in the folder's manifest before it
    /// is written (what the run writes beside the particles: checkpoints, pictures).
    pub fn claim(&mut self, path: &Path) -> Result<(), OutputError> {
        self.manifest.claim_path(path)
    }

    /// Drops the snapshots after `t_s` from the series: their files are removed and the `.pvd`
    /// rewritten (a run stopped unstable keeps what was still sound). Returns the indices of
    /// the snapshots dropped. Of a run over several ranks, each rank removes its pieces and
    /// rank 0 the `.pvtu` files and the `.pvd`.
    pub fn truncate_after(&mut self, t_s: f64) -> Result<std::ops::Range<usize>, OutputError> {
        let keep = self.snapshots.partition_point(|(t, _)| *t <= t_s);
        let remove = |file: PathBuf| match std::fs::remove_file(&file) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(OutputError::io("remove", &file, e))
            }
            _ => Ok(()),
        };
        let index_writer = self.piece.is_none_or(|p| p.rank == 0);
        for (_, rel) in &self.snapshots[keep..] {
            if let Some(piece) = self.piece {
                remove(self.dir.join(piece_of(rel, piece.rank)))?;
            }
            if index_writer {
                remove(self.dir.join(rel))?;
            }
        }
        let dropped = keep..self.snapshots.len();
        self.snapshots.truncate(keep);
        if index_writer {
            self.write_series()?;
        }
        Ok(dropped)
    }

    /// The (time, relative path) of every snapshot written so far.
    pub fn snapshots(&self) -> &[(f64, String)] {
        &self.snapshots
    }

    /// Resuming a run: the series is what the checkpoint lists (snapshots a killed run wrote
    /// after its checkpoint are dropped from the `.pvd` and overwritten by the resumed run).
    ///
    /// Of a run over several ranks, each rank checks its pieces and rank 0 the `.pvtu` files,
    /// and only rank 0 writes the `.pvd`.
    pub fn resume_series(&mut self, snapshots: Vec<(f64, String)>) -> Result<(), OutputError> {
        let index_writer = self.piece.is_none_or(|p| p.rank == 0);
        for (_, rel) in &snapshots {
            // Only particle files of this folder: the run removes and overwrites them.
            let name = rel.strip_prefix(&format!("{PARTICLES_DIR}/"));
            if !name.is_some_and(|n| is_run_output(rel) && n.starts_with("particles_")) {
                return Err(OutputError::Resume {
                    path: self.dir.join(rel),
                    reason: "the checkpoint lists a snapshot that is no particle file of the run"
                        .into(),
                });
            }
            let piece = self.piece.map(|p| self.dir.join(piece_of(rel, p.rank)));
            let index = index_writer.then(|| self.dir.join(rel));
            if let Some(file) = piece.into_iter().chain(index).find(|f| !f.is_file()) {
                return Err(OutputError::Resume {
                    path: file,
                    reason: "a snapshot the checkpoint lists is missing".into(),
                });
            }
        }
        self.snapshots = snapshots;
        if !index_writer {
            return Ok(());
        }
        self.write_series()
    }

    /// Creates one CSV per probe at DIR/probes/<name>.csv with header `t_s,<column>` (written
    /// at once, atomically); rows are appended with [`ProbeWriter::record`] and made durable by
    /// [`ProbeWriter::flush`].
    pub fn probe_writer(
        &mut self,
        names_and_columns: &[(String, String)],
    ) -> Result<ProbeWriter, OutputError> {
        let probes = self.dir.join(PROBES_DIR);
        ProbeWriter::create(&probes, names_and_columns, &mut self.manifest)
    }

    /// Creates DIR/probes/<name>.csv files with several value columns each (`t_s,<columns>`),
    /// e.g. the bodies' motion and loads; rows are added with [`ProbeWriter::record_rows`].
    pub fn table_writer(
        &mut self,
        tables: &[(String, Vec<String>)],
    ) -> Result<ProbeWriter, OutputError> {
        let probes = self.dir.join(PROBES_DIR);
        ProbeWriter::create_tables(&probes, tables, &mut self.manifest)
    }

    /// Writes DIR/run.json atomically (pretty-printed; non-finite numbers become `null`).
    pub fn write_run_summary(&mut self, summary: &RunSummary) -> Result<(), OutputError> {
        self.manifest.claim(RUN_SUMMARY_FILE)?;
        run_summary::write_run_summary(&self.dir.join(RUN_SUMMARY_FILE), summary)
    }
}

/// Formats an f64 so that parsing it back gives the same value: shortest round-trip digits,
/// plain notation for ordinary magnitudes, exponent notation for very large or small ones.
/// Non-finite values are written as `nan`, `inf`, `-inf`.
pub fn fmt_f64(x: f64) -> F64Text {
    F64Text(x)
}

/// Display wrapper returned by [`fmt_f64`].
#[derive(Clone, Copy, Debug)]
pub struct F64Text(pub f64);

impl fmt::Display for F64Text {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if x.is_nan() {
            f.write_str("nan")
        } else if x.is_infinite() {
            f.write_str(if x > 0.0 { "inf" } else { "-inf" })
        } else {
            let a = x.abs();
            if a == 0.0 || (1e-5..1e16).contains(&a) {
                write!(f, "{x}")
            } else {
                write!(f, "{x:e}")
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod test_util {
    use std::path::PathBuf;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A fresh, empty, unique folder under the system temp dir.
    pub fn temp_dir(tag: &str) -> PathBuf {
        static N: AtomicUsize = AtomicUsize::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        let d = std::env::temp_dir().join(format!(
            "wgsph-output-test-{}-{}-{tag}",
            std::process::id(),
            n
        ));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// Damaged copies of a file's `bytes` (what a full disk, a bad copy or a hostile edit
    /// leaves), each with what was done: cut short at every `step`-th length; at every
    /// `step`-th offset eight bytes set to 0xff (a length word of 2^64 - 1) and to zero, and
    /// one byte flipped.
    pub fn damaged(bytes: &[u8], step: usize) -> impl Iterator<Item = (String, Vec<u8>)> + '_ {
        let at = move |fill: Option<u8>| {
            (0..bytes.len()).step_by(step).map(move |k| {
                let mut b = bytes.to_vec();
                let what = match fill {
                    Some(v) => {
                        let end = (k + 8).min(b.len());
                        b[k..end].fill(v);
                        format!("8 bytes of {v:#04x} at {k}")
                    }
                    None => {
                        b[k] ^= 0xa5;
                        format!("byte {k} flipped")
                    }
                };
                (what, b)
            })
        };
        let cut = (0..bytes.len())
            .step_by(step)
            .map(move |k| (format!("cut at {k}"), bytes[..k].to_vec()));
        cut.chain(at(Some(0xff))).chain(at(Some(0))).chain(at(None))
    }

    /// Runs `read` on every damaged copy of `bytes` ([`damaged`]): none may panic (an error or a
    /// value are both fine). Returns how many were read without an error.
    pub fn survives_damage<T, E>(
        what: &str,
        bytes: &[u8],
        step: usize,
        read: impl Fn(&[u8]) -> Result<T, E>,
    ) -> usize {
        let mut ok = 0;
        for (how, b) in damaged(bytes, step) {
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| read(&b)));
            match r {
                Ok(r) => ok += r.is_ok() as usize,
                Err(_) => panic!("reading {what} with {how} panicked"),
            }
        }
        ok
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmt_f64_round_trips() {
        let vals = [
            0.0,
            -0.0,
            0.01,
            0.1 + 0.2,
            1.0 / 3.0,
            -2.5,
            1e-5,
            9.99e-6,
            1e-300,
            5e-324,
            1e15,
            1e16,
            123456789012345680000.0,
            f64::MAX,
            f64::MIN_POSITIVE,
            -1.2345678901234567e-7,
        ];
        for v in vals {
            let s = fmt_f64(v).to_string();
            let back: f64 = s.parse().unwrap();
            assert_eq!(back.to_bits(), v.to_bits(), "{v:e} -> {s}");
        }
        assert_eq!(fmt_f64(0.01).to_string(), "0.01");
        assert_eq!(fmt_f64(1e-300).to_string(), "1e-300");
        assert_eq!(fmt_f64(f64::NAN).to_string(), "nan");
        assert_eq!(fmt_f64(f64::INFINITY).to_string(), "inf");
        assert_eq!(fmt_f64(f64::NEG_INFINITY).to_string(), "-inf");
    }

    #[test]
    fn create_makes_subfolders_and_is_idempotent() {
        let base = test_util::temp_dir("create");
        let dir = base.join("a/b/out");
        let out = OutputDir::create(&dir).unwrap();
        assert_eq!(out.path(), dir.as_path());
        assert!(dir.join("particles").is_dir());
        assert!(dir.join("probes").is_dir());
        OutputDir::create(&dir).unwrap();
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn create_error_names_path() {
        let base = test_util::temp_dir("create-err");
        let file = base.join("not-a-dir");
        std::fs::write(&file, b"x").unwrap();
        let dir = file.join("out");
        let err = OutputDir::create(&dir).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains(&dir.display().to_string()), "{msg}");
        assert!(msg.contains("os error"), "{msg}");
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn snapshot_length_mismatch_is_an_error_and_writes_nothing() {
        let base = test_util::temp_dir("mismatch");
        let mut out = OutputDir::create(&base).unwrap();
        let pos = [[0.0; 3]; 2];
        let vel = [[0.0f32; 3]; 2];
        let s = [0.0f32; 2];
        let u = [0u32; 2];
        let short = [0u32; 1];
        let snap = Snapshot {
            extra: &[],
            time_s: 0.0,
            pos: &pos,
            vel: &vel,
            rho: &s,
            pressure: &s,
            kind: &u,
            id: &short,
        };
        let err = out.write_snapshot(&snap).unwrap_err();
        assert!(matches!(
            err,
            OutputError::SnapshotLength { array: "id", .. }
        ));
        assert!(err.to_string().contains("particles_000000.vtu"));
        assert_eq!(out.snapshot_count(), 0);
        assert_eq!(
            std::fs::read_dir(base.join("particles")).unwrap().count(),
            0
        );
        assert!(!base.join("particles.pvd").exists());
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn snapshot_series_vtu_then_pvd() {
        let base = test_util::temp_dir("series");
        let mut out = OutputDir::create(&base).unwrap();
        let times = [0.0, 0.01, 0.1 + 0.2];
        for (k, &t) in times.iter().enumerate() {
            let n = 5 + k;
            let pos: Vec<[f64; 3]> = (0..n)
                .map(|i| [i as f64 + t, 1e8 + 1.0 / 3.0, -1.0])
                .collect();
            let vel = vec![[0.5f32; 3]; n];
            let rho = vec![1000.0f32; n];
            let pressure = vec![0.0f32; n];
            let kind = vec![0u32; n];
            let id: Vec<u32> = (0..n as u32).rev().collect();
            let snap = Snapshot {
                extra: &[],
                time_s: t,
                pos: &pos,
                vel: &vel,
                rho: &rho,
                pressure: &pressure,
                kind: &kind,
                id: &id,
            };
            let p = out.write_snapshot(&snap).unwrap();
            assert_eq!(p, base.join(format!("particles/particles_{k:06}.vtu")));
            let v = vtu::reader::Vtu::parse(&std::fs::read(&p).unwrap()).unwrap();
            assert_eq!(v.number_of_points, n);
            assert_eq!(v.u32s("id").unwrap(), id);
            let pts = v.f64s("Points", 3).unwrap();
            assert_eq!(pts[3 * (n - 1)], pos[n - 1][0]);
            assert_eq!(pts[1], 1e8 + 1.0 / 3.0);

            // The .pvd lists exactly the snapshots written so far, each of which exists.
            let pvd_text = std::fs::read_to_string(base.join("particles.pvd")).unwrap();
            let listed = pvd::tests::parse_pvd(&pvd_text);
            assert_eq!(listed.len(), k + 1);
            for (j, (tj, file)) in listed.iter().enumerate() {
                assert_eq!(tj.to_bits(), times[j].to_bits());
                assert_eq!(file, &format!("particles/particles_{j:06}.vtu"));
                assert!(base.join(file).is_file());
            }
        }
        assert_eq!(out.snapshot_count(), 3);
        // No temporary files left anywhere.
        let mut names: Vec<String> = std::fs::read_dir(&base)
            .unwrap()
            .chain(std::fs::read_dir(base.join("particles")).unwrap())
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(
            names,
            [
                MANIFEST_FILE,
                "particles",
                "particles.pvd",
                "particles_000000.vtu",
                "particles_000001.vtu",
                "particles_000002.vtu",
                "probes"
            ]
        );
        // A stopped run's series cut after t = 0.01: the last file gone, the .pvd lists two.
        assert_eq!(out.truncate_after(0.01).unwrap(), 2..3);
        assert!(!base.join("particles/particles_000002.vtu").exists());
        let pvd_text = std::fs::read_to_string(base.join("particles.pvd")).unwrap();
        assert_eq!(pvd::tests::parse_pvd(&pvd_text).len(), 2);
        assert_eq!(out.snapshot_count(), 2);
        assert_eq!(out.truncate_after(1.0).unwrap(), 2..2);
        std::fs::remove_dir_all(&base).unwrap();
    }
}
