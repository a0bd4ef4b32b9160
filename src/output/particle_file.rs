//! A run's particle files read back (`DIR/particles/particles_NNNNNN.vtu`, as
//! [`super::OutputDir::write_snapshot`] wrote them): what drawing a snapshot after the run needs
//! (`wgsph plot DIR --snapshots`).

use std::path::{Path, PathBuf};

use super::vtu::reader::Vtu;
use super::{OutputError, Snapshot, PARTICLES_DIR};

/// The arrays of one particle file (the extra per-particle scalars are not read).
#[derive(Debug)]
pub struct ParticleFile {
    pub time_s: f64,
    pub pos: Vec<[f64; 3]>,
    pub vel: Vec<[f32; 3]>,
    pub rho: Vec<f32>,
    pub pressure: Vec<f32>,
    pub kind: Vec<u32>,
    pub id: Vec<u32>,
}

impl ParticleFile {
    /// Reads `path`; errors name it and say what is wrong (cut short, not written by wgsph).
    pub fn read(path: &Path) -> Result<Self, OutputError> {
        let bytes = std::fs::read(path).map_err(|e| OutputError::io("read", path, e))?;
        Self::parse(&bytes).map_err(|reason| OutputError::Read {
            path: path.to_path_buf(),
            reason,
        })
    }

    fn parse(bytes: &[u8]) -> Result<Self, String> {
        let v = Vtu::parse(bytes)?;
        let n = v.number_of_points;
        if v.number_of_cells != n {
            return Err(format!(
                "{} cells for {n} points (wgsph writes one vertex cell per particle)",
                v.number_of_cells
            ));
        }
        let triples = |name: &str, flat: Vec<f64>| -> Result<Vec<[f64; 3]>, String> {
            check_len(name, flat.len(), 3 * n)?;
            Ok(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
        };
        let pos = triples("Points", v.f64s("Points", 3)?)?;
        let vel_flat = v.f32s("velocity", 3)?;
        check_len("velocity", vel_flat.len(), 3 * n)?;
        let vel = vel_flat
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let scalar = |name: &str| -> Result<Vec<f32>, String> {
            let a = v.f32s(name, 1)?;
            check_len(name, a.len(), n)?;
            Ok(a)
        };
        let (rho, pressure) = (scalar("density")?, scalar("pressure")?);
        let (kind, id) = (v.u32s("kind")?, v.u32s("id")?);
        check_len("kind", kind.len(), n)?;
        check_len("id", id.len(), n)?;
        let time = v.f64s("TimeValue", 1)?;
        let &[time_s] = time.as_slice() else {
            return Err(format!("TimeValue has {} values, not 1", time.len()));
        };
        Ok(ParticleFile {
            time_s,
            pos,
            vel,
            rho,
            pressure,
            kind,
            id,
        })
    }

    pub fn snapshot(&self) -> Snapshot<'_> {
        Snapshot {
            time_s: self.time_s,
            pos: &self.pos,
            vel: &self.vel,
            rho: &self.rho,
            pressure: &self.pressure,
            kind: &self.kind,
            id: &self.id,
            extra: &[],
        }
    }
}

fn check_len(name: &str, len: usize, expected: usize) -> Result<(), String> {
    if len == expected {
        Ok(())
    } else {
        Err(format!(
            "array {name} has {len} values, not {expected} (NumberOfPoints)"
        ))
    }
}

/// The particle files of the run in `dir`: (index NNNNNN, path), by index. Other files in
/// `DIR/particles` (temporaries of a killed run, anything else) are left out.
pub fn particle_files(dir: &Path) -> Result<Vec<(usize, PathBuf)>, OutputError> {
    let folder = dir.join(PARTICLES_DIR);
    let entries = std::fs::read_dir(&folder).map_err(|e| OutputError::io("read", &folder, e))?;
    let mut files = Vec::new();
    for entry in entries {
        let path = entry
            .map_err(|e| OutputError::io("read", &folder, e))?
            .path();
        let index = path
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(|n| n.strip_prefix("particles_")?.strip_suffix(".vtu"))
            .filter(|digits| digits.len() == 6)
            .and_then(|digits| digits.parse().ok());
        if let Some(index) = index {
            files.push((index, path));
        }
    }
    files.sort();
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::super::test_util::temp_dir;
    use super::super::OutputDir;
    use super::*;

    #[test]
    fn particle_files_read_back_what_was_written() {
        let dir = temp_dir("particle-file");
        let mut out = OutputDir::create(&dir).unwrap();
        let n = 50;
        let pos: Vec<[f64; 3]> = (0..n).map(|i| [i as f64 / 3.0, -1e-7, 2.5]).collect();
        let vel: Vec<[f32; 3]> = (0..n).map(|i| [i as f32, 0.5, f32::NAN]).collect();
        let rho: Vec<f32> = (0..n).map(|i| 1000.0 + i as f32).collect();
        let pressure: Vec<f32> = (0..n).map(|i| i as f32 * 9.81).collect();
        let kind: Vec<u32> = (0..n).map(|i| i % 2).collect();
        let id: Vec<u32> = (0..n).rev().collect();
        let energy = vec![1.0f32; n as usize];
        for k in 0..2 {
            let snap = Snapshot {
                time_s: 0.25 * k as f64,
                pos: &pos,
                vel: &vel,
                rho: &rho,
                pressure: &pressure,
                kind: &kind,
                id: &id,
                extra: &[("energy", &energy)],
            };
            out.write_snapshot(&snap).unwrap();
        }
        std::fs::write(dir.join(PARTICLES_DIR).join("notes.txt"), "x").unwrap();
        let files = particle_files(&dir).unwrap();
        assert_eq!(files.iter().map(|f| f.0).collect::<Vec<_>>(), [0, 1]);
        let p = ParticleFile::read(&files[1].1).unwrap();
        assert_eq!(p.time_s, 0.25);
        assert_eq!((&p.pos, &p.rho, &p.pressure), (&pos, &rho, &pressure));
        assert_eq!((&p.kind, &p.id), (&kind, &id));
        assert!(p
            .vel
            .iter()
            .zip(&vel)
            .all(|(a, b)| a[0] == b[0] && a[2].is_nan()));
        // A file cut short: an error naming it.
        let bytes = std::fs::read(&files[0].1).unwrap();
        std::fs::write(&files[0].1, &bytes[..bytes.len() - 40]).unwrap();
        let err = ParticleFile::read(&files[0].1).unwrap_err().to_string();
        assert!(
            err.contains("particles_000000.vtu") && err.contains("cut short"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
