//! The particles of one output, and a run's particle files read back
//! (`DIR/particles/particles_NNNNNN.vtu`, as [`super::OutputDir::write_snapshot`] wrote them):
//! what drawing a snapshot after the run needs (`wgsph plot DIR --snapshots`).

use std::path::{Path, PathBuf};

use super::vtu::{pvtu_pieces, reader::Vtu};
use super::{particle_file_name, pieces_file_name, OutputError, Snapshot, PARTICLES_DIR};
use crate::particles::Particles;
use crate::scenario::Kind;

/// The particle files' names of the six components of [`Particles::stress`].
const STRESS_NAMES: [&str; 6] = ["tau_xx", "tau_yy", "tau_zz", "tau_xy", "tau_xz", "tau_yz"];
const ENERGY_NAME: &str = "energy";

/// The ids and positions of a run's first particle output, in id order (a subdomain's own
/// particles, or the whole run's): what `time.output_boundary = "first"` leaves out of the
/// later ones ([`Particles::without_unmoved_boundary`]).
#[derive(Clone, Debug, Default)]
pub struct FirstPositions {
    pub id: Vec<u32>,
    pub pos: Vec<[f64; 3]>,
}

impl FirstPositions {
    pub fn of(p: &Particles) -> Self {
        Self {
            id: p.id.clone(),
            pos: p.pos.clone(),
        }
    }
}

impl Particles {
    /// The per-particle scalars beyond the fixed arrays, named as in the particle files: the
    /// energy, then the stress components, where the run has them.
    pub fn extra_arrays(&self) -> Vec<(&'static str, Vec<f32>)> {
        let mut extra = Vec::new();
        if let Some(e) = &self.energy {
            extra.push((ENERGY_NAME, e.clone()));
        }
        if let Some(s) = &self.stress {
            for (c, name) in STRESS_NAMES.iter().enumerate() {
                extra.push((*name, s.iter().map(|t| t[c]).collect()));
            }
        }
        extra
    }

    /// These particles less the boundary particles (walls, obstacles and bodies, of any wall
    /// treatment) that stand where they stood in the first output, `first` (ids and positions,
    /// in id order as these are; a subdomain's own particles then): what a later output holds
    /// with `time.output_boundary = "first"`. A particle `first` lacks is kept.
    pub fn without_unmoved_boundary(&self, first: &FirstPositions) -> Particles {
        let mut k = 0;
        let mut unmoved = |i: usize| {
            while k < first.id.len() && first.id[k] < self.id[i] {
                k += 1;
            }
            Kind::from_code(self.kind[i]).is_some_and(Kind::is_boundary)
                && first.id.get(k) == Some(&self.id[i])
                && first.pos[k].map(f64::to_bits) == self.pos[i].map(f64::to_bits)
        };
        let picks: Vec<(&Particles, usize)> = (0..self.id.len())
            .filter(|&i| !unmoved(i))
            .map(|i| (self, i))
            .collect();
        gather(&picks)
    }

    /// A later output that left out unmoved boundary particles, completed with those of
    /// `first` (every boundary particle `first` has and `self` lacks; not the particles that
    /// left the domain, which a subdomain's piece leaves out too), in id order: the inverse of
    /// [`Particles::without_unmoved_boundary`].
    pub fn completed_from(&self, first: &Particles) -> Particles {
        let mut picks = Vec::with_capacity(first.id.len().max(self.id.len()));
        let mut k = 0;
        for i in 0..first.id.len() {
            while k < self.id.len() && self.id[k] < first.id[i] {
                picks.push((self, k));
                k += 1;
            }
            if k < self.id.len() && self.id[k] == first.id[i] {
                picks.push((self, k));
                k += 1;
            } else if Kind::from_code(first.kind[i]).is_some_and(Kind::is_boundary) {
                picks.push((first, i));
            }
        }
        picks.extend((k..self.id.len()).map(|k| (self, k)));
        gather(&picks)
    }

    /// These particles less those of id `id` (of a subdomain, its free entries, which hold
    /// no particle: `IdSplit::free_id`).
    pub fn without_id(&self, id: u32) -> Particles {
        let picks: Vec<(&Particles, usize)> = (0..self.id.len())
            .filter(|&i| self.id[i] != id)
            .map(|i| (self, i))
            .collect();
        gather(&picks)
    }

    /// The snapshot of these particles at `time_s`, with `extra` (e.g. of
    /// [`Particles::extra_arrays`]) as its further scalars.
    pub fn snapshot<'a>(&'a self, time_s: f64, extra: &'a [(&'a str, &'a [f32])]) -> Snapshot<'a> {
        Snapshot {
            time_s,
            pos: &self.pos,
            vel: &self.vel,
            rho: &self.rho,
            pressure: &self.pressure,
            kind: &self.kind,
            id: &self.id,
            extra,
        }
    }
}

/// The particles `picks` name, (source, index), in that order; energy and stress where every
/// source has them.
fn gather(picks: &[(&Particles, usize)]) -> Particles {
    fn each<T: Copy>(picks: &[(&Particles, usize)], f: impl Fn(&Particles) -> &[T]) -> Vec<T> {
        picks.iter().map(|(p, i)| f(p)[*i]).collect()
    }
    Particles {
        pos: each(picks, |p| &p.pos),
        vel: each(picks, |p| &p.vel),
        rho: each(picks, |p| &p.rho),
        pressure: each(picks, |p| &p.pressure),
        kind: each(picks, |p| &p.kind),
        id: each(picks, |p| &p.id),
        energy: picks
            .iter()
            .map(|(p, i)| p.energy.as_ref().map(|e| e[*i]))
            .collect(),
        stress: picks
            .iter()
            .map(|(p, i)| p.stress.as_ref().map(|s| s[*i]))
            .collect(),
    }
}

/// One particle file read back: its time and particles (energy and stress where written).
#[derive(Debug)]
pub struct ParticleFile {
    pub time_s: f64,
    pub particles: Particles,
}

impl ParticleFile {
    /// Reads `path`; errors name it and say what is wrong (cut short, not written by wgsph).
    /// A `.pvtu` (a run over several ranks) is read as its pieces together, in id order.
    pub fn read(path: &Path) -> Result<Self, OutputError> {
        let bytes = std::fs::read(path).map_err(|e| OutputError::io("read", path, e))?;
        let failed = |reason| OutputError::Read {
            path: path.to_path_buf(),
            reason,
        };
        if path.extension().is_some_and(|e| e == "pvtu") {
            let text = String::from_utf8_lossy(&bytes);
            let folder = path.parent().unwrap_or(Path::new("."));
            let pieces = pvtu_pieces(&text)
                .map_err(failed)?
                .iter()
                .map(|p| Self::read(&folder.join(p)))
                .collect::<Result<Vec<_>, _>>()?;
            return Ok(Self::joined(&pieces));
        }
        Self::parse(&bytes).map_err(failed)
    }

    /// The pieces of one output as one, in id order (the time of the first).
    fn joined(pieces: &[ParticleFile]) -> Self {
        let mut picks: Vec<(&Particles, usize)> = pieces
            .iter()
            .flat_map(|f| (0..f.particles.id.len()).map(move |i| (&f.particles, i)))
            .collect();
        picks.sort_by_key(|(p, i)| p.id[*i]);
        ParticleFile {
            time_s: pieces.first().map_or(0.0, |f| f.time_s),
            particles: gather(&picks),
        }
    }

    pub(super) fn parse(bytes: &[u8]) -> Result<Self, String> {
        let v = Vtu::parse(bytes)?;
        let n = v.number_of_points;
        if v.number_of_cells != n {
            return Err(format!(
                "{} cells for {n} points (wgsph writes one vertex cell per particle)",
                v.number_of_cells
            ));
        }
        let sized = |name: &str, a: Vec<f32>, per: usize| -> Result<Vec<f32>, String> {
            check_len(name, a.len(), per, n)?;
            Ok(a)
        };
        let points = v.f64s("Points", 3)?;
        check_len("Points", points.len(), 3, n)?;
        let vel = sized("velocity", v.f32s("velocity", 3)?, 3)?;
        let (kind, id) = (v.u32s("kind")?, v.u32s("id")?);
        check_len("kind", kind.len(), 1, n)?;
        check_len("id", id.len(), 1, n)?;
        let optional = |name: &str| -> Result<Option<Vec<f32>>, String> {
            match v.arrays.contains_key(name) {
                true => Ok(Some(sized(name, v.f32s(name, 1)?, 1)?)),
                false => Ok(None),
            }
        };
        // The six components, or none of them.
        let stress = STRESS_NAMES
            .iter()
            .map(|name| optional(name))
            .collect::<Result<Option<Vec<_>>, _>>()?
            .map(|c| (0..n).map(|i| std::array::from_fn(|k| c[k][i])).collect());
        let time = v.f64s("TimeValue", 1)?;
        let &[time_s] = time.as_slice() else {
            return Err(format!("TimeValue has {} values, not 1", time.len()));
        };
        Ok(ParticleFile {
            time_s,
            particles: Particles {
                pos: points.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
                vel: vel.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
                rho: sized("density", v.f32s("density", 1)?, 1)?,
                pressure: sized("pressure", v.f32s("pressure", 1)?, 1)?,
                kind,
                id,
                energy: optional(ENERGY_NAME)?,
                stress,
            },
        })
    }
}

/// `len` values in array `name`, where NumberOfPoints asks for `per` a point (a corrupt
/// count may overflow the product: then no array matches it).
fn check_len(name: &str, len: usize, per: usize, n: usize) -> Result<(), String> {
    let expected = per.checked_mul(n);
    if Some(len) == expected {
        Ok(())
    } else {
        Err(format!(
            "array {name} has {len} values, not {per} × {n} (NumberOfPoints)"
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
        // The names `particle_file_name` and `pieces_file_name` give, and no others (not the
        // pieces).
        let index = path.file_name().and_then(|n| n.to_str()).and_then(|name| {
            let stem = name.strip_prefix("particles_")?;
            let digits = stem.strip_suffix(".vtu").or(stem.strip_suffix(".pvtu"))?;
            digits
                .parse()
                .ok()
                .filter(|&i| particle_file_name(i) == name || pieces_file_name(i) == name)
        });
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

    /// `n` particles with every array, energy and stress included.
    fn particles(n: u32) -> Particles {
        Particles {
            pos: (0..n).map(|i| [i as f64 / 3.0, -1e-7, 2.5]).collect(),
            vel: (0..n).map(|i| [i as f32, 0.5, -0.25]).collect(),
            rho: (0..n).map(|i| 1000.0 + i as f32).collect(),
            pressure: (0..n).map(|i| i as f32 * 9.81).collect(),
            kind: (0..n).map(|i| i % 2).collect(),
            id: (0..n).rev().collect(),
            energy: Some((0..n).map(|i| i as f32 * 0.5).collect()),
            stress: Some(
                (0..n)
                    .map(|i| std::array::from_fn(|c| (i * 6 + c as u32) as f32))
                    .collect(),
            ),
        }
    }

    /// Unmoved boundary particles are left out, everything else kept (a moved boundary
    /// particle, fluid, solids, excluded ones); completing from the first output gives back the
    /// whole set in id order.
    #[test]
    fn unmoved_boundary_is_left_out_and_completed_back() {
        let first = Particles {
            id: (0..12).collect(),
            ..particles(12)
        };
        let mut later = first.clone();
        // kinds by id order: 1 wall (unmoved), 1 wall (moved by 1e-12 m), 0 fluid (unmoved),
        // 2–4 ghost and repulsive (unmoved), 5 solid, 7 inlet, 15 excluded (unmoved)
        let kinds = [1, 1, 0, 2, 3, 4, 5, 7, 15, 1, 0, 4];
        later.kind = kinds.to_vec();
        later.pos[1][0] += 1e-12;
        for (i, v) in later.vel.iter_mut().enumerate() {
            v[1] = -(i as f32);
        }
        let fewer = later.without_unmoved_boundary(&FirstPositions::of(&first));
        let kept: Vec<u32> = fewer.kind.clone();
        assert_eq!(kept, [1, 0, 5, 7, 15, 0], "{fewer:?}");
        assert_eq!(fewer.id, [1, 2, 6, 7, 8, 10]);
        assert_eq!(fewer.stress.as_ref().map(Vec::len), Some(6));
        let mut first_with_kinds = first.clone();
        first_with_kinds.kind = kinds.to_vec();
        // The first output holds the unmoved ones as they were (same position, kind; their
        // velocity and pressure from then).
        let back = fewer.completed_from(&first_with_kinds);
        assert_eq!(back.id, later.id);
        assert_eq!(back.pos, later.pos);
        assert_eq!(back.kind, later.kind);
        for i in 0..12 {
            let from_later = fewer.id.contains(&later.id[i]);
            let want = if from_later {
                later.vel[i]
            } else {
                first.vel[i]
            };
            assert_eq!(back.vel[i], want, "particle {i}");
        }
        // Nothing left out: the same particles back.
        let all = later.without_unmoved_boundary(&FirstPositions::default());
        assert_eq!(all, later);
        assert_eq!(all.completed_from(&first_with_kinds), later);
    }

    #[test]
    fn particle_files_read_back_what_was_written() {
        let dir = temp_dir("particle-file");
        let mut out = OutputDir::create(&dir).unwrap();
        let all = particles(50);
        let bare = Particles {
            energy: None,
            stress: None,
            ..all.clone()
        };
        for (k, p) in [&bare, &all].into_iter().enumerate() {
            let extra = p.extra_arrays();
            let extra: Vec<(&str, &[f32])> =
                extra.iter().map(|(n, v)| (*n, v.as_slice())).collect();
            out.write_snapshot(&p.snapshot(0.25 * k as f64, &extra))
                .unwrap();
        }
        std::fs::write(dir.join(PARTICLES_DIR).join("notes.txt"), "x").unwrap();
        let files = particle_files(&dir).unwrap();
        assert_eq!(files.iter().map(|f| f.0).collect::<Vec<_>>(), [0, 1]);
        let read = |k: usize| ParticleFile::read(&files[k].1).unwrap();
        assert_eq!((read(0).time_s, read(0).particles), (0.0, bare));
        assert_eq!((read(1).time_s, read(1).particles), (0.25, all));
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

    /// A run over three ranks: each writes its piece of every output, rank 0 the `.pvtu`
    /// naming them and the series; the `.pvtu` reads back as the pieces together in id order,
    /// extra arrays included, and is what `particle_files` lists. Truncating the series
    /// removes each rank's pieces and rank 0's `.pvtu`.
    #[test]
    fn pieces_of_several_ranks_read_back_as_one_output() {
        use super::super::Piece;
        let dir = temp_dir("pieces");
        let all = Particles {
            id: (0..30).collect(),
            ..particles(30)
        };
        let ranks = 3;
        let mut outs: Vec<OutputDir> = (0..ranks)
            .map(|rank| OutputDir::for_piece(&dir, Piece { rank, ranks }).unwrap())
            .collect();
        for k in 0..2 {
            for (rank, out) in outs.iter_mut().enumerate() {
                // Rank r holds the ids r, r + 3, …, not in id order.
                let mine: Vec<(&Particles, usize)> = (0..30)
                    .rev()
                    .filter(|i| i % ranks == rank)
                    .map(|i| (&all, i))
                    .collect();
                let piece = gather(&mine);
                let extra = piece.extra_arrays();
                let extra: Vec<(&str, &[f32])> =
                    extra.iter().map(|(n, v)| (*n, v.as_slice())).collect();
                out.write_snapshot(&piece.snapshot(0.5 * k as f64, &extra))
                    .unwrap();
            }
            for out in &mut outs {
                out.publish_pieces().unwrap();
            }
        }
        let files = particle_files(&dir).unwrap();
        assert_eq!(files.len(), 2, "{files:?}");
        assert!(files[1].1.ends_with("particles/particles_000001.pvtu"));
        let read = ParticleFile::read(&files[1].1).unwrap();
        assert_eq!((read.time_s, read.particles), (0.5, all));
        let pvd = std::fs::read_to_string(dir.join("particles.pvd")).unwrap();
        assert!(
            pvd.contains("file=\"particles/particles_000001.pvtu\""),
            "{pvd}"
        );
        for out in &mut outs {
            assert_eq!(out.truncate_after(0.25).unwrap(), 1..2);
        }
        let left: Vec<String> = std::fs::read_dir(dir.join(PARTICLES_DIR))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains("000001"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
        assert_eq!(particle_files(&dir).unwrap().len(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
