//! Checkpoint files: `DIR/checkpoint.bin`, the last state a run can resume from.
//!
//! Layout (little-endian): the magic `WGSPHCKP`, a format version (u32), the length of a JSON
//! header (u64), the header, the binary sections it lists (particle arrays, straight from the
//! GPU), and an FNV-1a 64 checksum of everything before it. The header holds the scalars as
//! bit patterns (exact), the output series so far (snapshot list, probe CSV texts) and where
//! the case came from. The file is written to a temporary name and renamed into place like
//! every output, so a run killed while checkpointing keeps the previous checkpoint.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use crate::layout::{MapCell, Pos, SimState, SolidState, ID_MASK, KIND_SHIFT};
use crate::output::write_atomic;
use crate::scenario::{Kind, Scenario};
use crate::sph::state::SolverState;
use crate::sph::DensityPeaks;

pub use crate::output::{rank_checkpoint_file, CHECKPOINT_FILE};
const MAGIC: &[u8; 8] = b"WGSPHCKP";
/// 2: the solid section holds the solid particles only, in id order. Format 1 (every particle,
/// in the saved GPU order) is still read.
/// 3: `SimState` ends with the density-variation monitor (24 bytes); the shorter state of
/// formats 1 and 2 is read with the monitor cleared (it changes no dynamics).
const FORMAT: u32 = 3;
/// `SimState`'s size before format 3.
const SIM_STATE_BYTES_V2: usize = 48;

/// When a run writes its checkpoint (`DIR/checkpoint.bin`, the last one replacing the one
/// before). Checkpoints are taken at probe times, the first one at or after each due time; an
/// interrupt (Ctrl-C, SIGTERM) always writes one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CheckpointPolicy {
    /// Every so many simulated seconds.
    pub every_sim_s: Option<f64>,
    /// Every so many wall-clock seconds.
    pub every_wall_s: Option<f64>,
}

impl CheckpointPolicy {
    /// What `wgsph run` does without `--checkpoint-every`: every 30 wall minutes.
    pub fn default_for_runs() -> Self {
        Self {
            every_sim_s: None,
            every_wall_s: Some(30.0 * 60.0),
        }
    }
}

impl std::str::FromStr for CheckpointPolicy {
    type Err = anyhow::Error;

    /// `0.5` or `0.5s`: every 0.5 simulated seconds; `10min`: every 10 wall minutes;
    /// `never`: only on interrupts.
    fn from_str(text: &str) -> Result<Self> {
        let t = text.trim();
        let number = |s: &str| -> Result<f64> {
            match s.trim().parse::<f64>() {
                Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
                _ => anyhow::bail!(
                    "--checkpoint-every '{text}': give a positive number of simulated seconds \
                     (0.5 or 0.5s), of wall minutes (10min), or 'never'"
                ),
            }
        };
        Ok(if t == "never" {
            Self::default()
        } else if let Some(m) = t.strip_suffix("min") {
            Self {
                every_sim_s: None,
                every_wall_s: Some(60.0 * number(m)?),
            }
        } else {
            Self {
                every_sim_s: Some(number(t.strip_suffix('s').unwrap_or(t))?),
                every_wall_s: None,
            }
        })
    }
}

/// The case file and `--set` overrides a run was started with, so `wgsph resume` can rebuild
/// the scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseSource {
    pub path: PathBuf,
    pub overrides: Vec<String>,
}

/// Where a run's outputs stood when the checkpoint was taken.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct OutputState {
    /// Simulated time of the next particle output.
    pub next_output_s: f64,
    /// (time, relative path) of every particle snapshot written.
    pub snapshots: Vec<(f64, String)>,
    /// Full text of every probe CSV, then of every body CSV.
    pub probe_tables: Vec<String>,
    pub body_tables: Vec<String>,
    /// Wall time spent so far [s].
    pub wall_s: f64,
    /// The fluid's largest density variation so far and when it was seen [s], and how many
    /// times the fluid went beyond `time.density_variation_warn` (run.json's warning).
    pub max_density_variation: (f64, f64),
    pub density_episodes: u32,
}

/// Everything needed to continue a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    pub case_name: String,
    /// [`fingerprint`] of the scenario the run was built from.
    pub fingerprint: u64,
    pub source: Option<CaseSource>,
    /// The colour field of PNG snapshots (`--snapshots`), if the run draws them.
    pub snapshot_field: Option<String>,
    /// The adapter the state was computed on (bit-identity holds on the same adapter only).
    pub adapter: String,
    /// When the run checkpoints (`--checkpoint-every`), which `wgsph resume` keeps; None in a
    /// file written before it was recorded.
    pub policy: Option<CheckpointPolicy>,
    pub time_s: f64,
    pub outputs: OutputState,
    pub solver: SolverState,
    /// Of a run over several ranks: this rank's part (its `solver` is its subdomain's).
    pub subdomain: Option<RankCheckpoint>,
}

/// A rank's part of the checkpoint of a run over several ranks. Rank 0's is `checkpoint.bin`,
/// written last: the manifest, naming the generation (one of two alternating sets) of the
/// other ranks' files ([`rank_checkpoint_file`]) that belong with it. A run killed while
/// checkpointing keeps the last complete set: the manifest still names the other one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RankCheckpoint {
    pub rank: usize,
    pub ranks: usize,
    pub generation: u32,
    pub ranked: crate::sph::subdomain::Ranked,
}

#[derive(Serialize, Deserialize)]
struct Header {
    format: u32,
    case_name: String,
    fingerprint: String,
    source: Option<CaseSource>,
    snapshot_field: Option<String>,
    adapter: String,
    #[serde(default)]
    policy: Option<CheckpointPolicy>,
    #[serde(default)]
    max_density_variation: (f64, f64),
    #[serde(default)]
    density_episodes: u32,
    /// For people reading the header; `time_bits` is what resumes.
    time_s: f64,
    time_bits: u64,
    wall_s: f64,
    next_output_bits: u64,
    snapshots: Vec<(u64, String)>,
    probe_tables: Vec<String>,
    body_tables: Vec<String>,
    parity: u32,
    t_base_bits: u64,
    steps: u64,
    initial_dt_bits: u32,
    filter_last: u32,
    body_bits: Vec<u64>,
    /// The density peaks of the probe interval so far: the variation's f32 bits, the fluid
    /// particles beyond the warning and stop limits (zero at a probe time; before a run could
    /// stop between probe times, never written).
    #[serde(default)]
    density_peaks: (u32, u32, u32),
    #[serde(default)]
    subdomain: Option<RankCheckpoint>,
    /// (name, bytes) of the binary sections, in file order.
    sections: Vec<(String, u64)>,
}

/// FNV-1a 64: a checksum without a dependency; enough to tell a damaged file or a different
/// case, not an adversary.
#[derive(Clone, Copy)]
pub struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    pub fn finish(self) -> u64 {
        self.0
    }
}

/// A hash of what a run's state depends on: the particles as built (positions, velocities,
/// densities, kinds), the physics, walls, domain, probes, bodies, elastic solids (material,
/// bodies, initial stress), inlets and outlets. Time control is left out, so a resumed run may
/// be given a later end time.
pub fn fingerprint(sc: &Scenario) -> u64 {
    let mut h = Fnv::default();
    // Friction only when on, so checkpoints written before it existed still match (without
    // it, its regularisation speed changes nothing); pairs with their own μ only when given.
    let mut walls = format!("{:?}", sc.walls);
    if sc.walls.friction_pairs.is_empty() {
        walls = walls.replace(", friction_pairs: []", "");
    }
    if sc.walls.friction == 0.0 && sc.walls.friction_pairs.is_empty() {
        walls = walls.replace(
            &format!(
                ", friction: {:?}, friction_slip: {:?}",
                sc.walls.friction, sc.walls.friction_slip
            ),
            "",
        );
    }
    let settings = format!(
        "{}|{:?}|{:?}|{}|{:?}|{:?}|{:?}",
        sc.name, sc.physics, sc.domain, walls, sc.periodic, sc.probes, sc.bodies
    );
    h.update(settings.as_bytes());
    // Only when there are any, so checkpoints written before points existed still match.
    if !sc.points.is_empty() {
        h.update(format!("|{:?}", sc.points).as_bytes());
    }
    if let Some(maps) = &sc.maps {
        h.update(format!("|{maps:?}").as_bytes());
    }
    if !sc.inlets.is_empty() || !sc.outlets.is_empty() {
        h.update(format!("|{:?}|{:?}", sc.inlets, sc.outlets).as_bytes());
    }
    if let Some(solids) = &sc.solids {
        h.update(format!("|{:?}", solids.materials).as_bytes());
        for (body, tau) in solids.body.iter().zip(&solids.tau0) {
            h.update(&body.to_le_bytes());
            for x in tau {
                h.update(&x.to_bits().to_le_bytes());
            }
        }
    }
    for p in &sc.particles {
        for x in p.pos.iter().chain(&p.vel).chain([&p.rho]) {
            h.update(&x.to_bits().to_le_bytes());
        }
        h.update(&[p.kind as u8]);
    }
    h.finish()
}

impl Checkpoint {
    /// Writes the checkpoint to `path` atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let s = &self.solver;
        let mut sections: Vec<(&str, &[u8])> = vec![
            ("sim", bytemuck::bytes_of(&s.sim)),
            ("pos", bytemuck::cast_slice(&s.pos)),
            ("velrho", bytemuck::cast_slice(&s.velrho)),
            ("code", bytemuck::cast_slice(&s.code)),
            ("rate", bytemuck::cast_slice(&s.rate)),
        ];
        if let Some(e) = &s.energy {
            sections.push(("energy", bytemuck::cast_slice(e)));
        }
        if let Some(solid) = &s.solid {
            sections.push(("solid", bytemuck::cast_slice(solid)));
        }
        if let Some(maps) = &s.maps {
            sections.push(("maps", bytemuck::cast_slice(maps)));
        }
        let o = &self.outputs;
        let header = Header {
            format: FORMAT,
            case_name: self.case_name.clone(),
            fingerprint: format!("{:016x}", self.fingerprint),
            source: self.source.clone(),
            snapshot_field: self.snapshot_field.clone(),
            adapter: self.adapter.clone(),
            policy: self.policy,
            max_density_variation: o.max_density_variation,
            density_episodes: o.density_episodes,
            time_s: self.time_s,
            time_bits: self.time_s.to_bits(),
            wall_s: o.wall_s,
            next_output_bits: o.next_output_s.to_bits(),
            snapshots: o
                .snapshots
                .iter()
                .map(|(t, f)| (t.to_bits(), f.clone()))
                .collect(),
            probe_tables: o.probe_tables.clone(),
            body_tables: o.body_tables.clone(),
            parity: s.parity,
            t_base_bits: s.t_base.to_bits(),
            steps: s.steps,
            initial_dt_bits: s.initial_dt.to_bits(),
            filter_last: s.filter_last,
            body_bits: s.bodies.iter().map(|x| x.to_bits()).collect(),
            density_peaks: (
                s.peaks.variation.to_bits(),
                s.peaks.beyond_warn,
                s.peaks.beyond_stop,
            ),
            subdomain: self.subdomain.clone(),
            sections: sections
                .iter()
                .map(|(n, b)| (n.to_string(), b.len() as u64))
                .collect(),
        };
        let json = serde_json::to_vec(&header).context("encoding the checkpoint header")?;
        write_atomic(path, |w| {
            let mut sum = Fnv::default();
            let mut put = |w: &mut dyn Write, bytes: &[u8]| {
                sum.update(bytes);
                w.write_all(bytes)
            };
            put(w, MAGIC)?;
            put(w, &FORMAT.to_le_bytes())?;
            put(w, &(json.len() as u64).to_le_bytes())?;
            put(w, &json)?;
            for (_, bytes) in &sections {
                put(w, bytes)?;
            }
            w.write_all(&sum.finish().to_le_bytes())
        })?;
        Ok(())
    }

    /// Reads a checkpoint, checking its magic, version, checksum and section sizes.
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path)
            .with_context(|| format!("cannot read the checkpoint {}", path.display()))?;
        Self::decode(&bytes).with_context(|| format!("checkpoint {}", path.display()))
    }

    fn decode(bytes: &[u8]) -> Result<Self> {
        if bytes.len() < 28 || &bytes[..8] != MAGIC {
            bail!("not a wgsph checkpoint (no WGSPHCKP magic)");
        }
        let (body, tail) = bytes.split_at(bytes.len() - 8);
        let mut sum = Fnv::default();
        sum.update(body);
        if sum.finish().to_le_bytes() != tail {
            bail!("damaged: its checksum does not match its content");
        }
        let format = u32::from_le_bytes(body[8..12].try_into().expect("4 bytes"));
        if !(1..=FORMAT).contains(&format) {
            bail!("format {format}; this wgsph reads formats 1 to {FORMAT}");
        }
        let json_len = u64::from_le_bytes(body[12..20].try_into().expect("8 bytes")) as usize;
        let json = body
            .get(20..20usize.saturating_add(json_len))
            .context("truncated header")?;
        let h: Header = serde_json::from_slice(json).context("bad header")?;
        let mut rest = &body[20 + json_len..];
        let mut section = |name: &str| -> Result<&[u8]> {
            let (_, len) = h
                .sections
                .iter()
                .find(|(n, _)| n == name)
                .with_context(|| format!("no '{name}' section"))?;
            let len = *len as usize;
            if rest.len() < len {
                bail!("section '{name}' is truncated");
            }
            let (mine, more) = rest.split_at(len);
            rest = more;
            Ok(mine)
        };
        let sim = sim_state(section("sim")?, format)?;
        let pos: Vec<Pos> = pod_vec(section("pos")?, "pos")?;
        let velrho: Vec<[f32; 4]> = pod_vec(section("velrho")?, "velrho")?;
        let code: Vec<u32> = pod_vec(section("code")?, "code")?;
        let rate: Vec<[f32; 4]> = pod_vec(section("rate")?, "rate")?;
        let energy = if h.sections.iter().any(|(n, _)| n == "energy") {
            Some(pod_vec::<[f32; 2]>(section("energy")?, "energy")?)
        } else {
            None
        };
        let solid = if h.sections.iter().any(|(n, _)| n == "solid") {
            let solid = pod_vec::<SolidState>(section("solid")?, "solid")?;
            Some(if format == 1 {
                solid_by_id(&solid, &code)?
            } else {
                solid
            })
        } else {
            None
        };
        let maps = if h.sections.iter().any(|(n, _)| n == "maps") {
            Some(pod_vec::<MapCell>(section("maps")?, "maps")?)
        } else {
            None
        };
        let fingerprint = u64::from_str_radix(&h.fingerprint, 16).context("bad fingerprint")?;
        Ok(Checkpoint {
            case_name: h.case_name,
            fingerprint,
            source: h.source,
            snapshot_field: h.snapshot_field,
            adapter: h.adapter,
            policy: h.policy,
            time_s: f64::from_bits(h.time_bits),
            outputs: OutputState {
                next_output_s: f64::from_bits(h.next_output_bits),
                snapshots: h
                    .snapshots
                    .into_iter()
                    .map(|(t, f)| (f64::from_bits(t), f))
                    .collect(),
                probe_tables: h.probe_tables,
                body_tables: h.body_tables,
                wall_s: h.wall_s,
                max_density_variation: h.max_density_variation,
                density_episodes: h.density_episodes,
            },
            solver: SolverState {
                parity: h.parity,
                t_base: f64::from_bits(h.t_base_bits),
                steps: h.steps,
                initial_dt: f32::from_bits(h.initial_dt_bits),
                sim,
                peaks: DensityPeaks {
                    variation: f32::from_bits(h.density_peaks.0),
                    beyond_warn: h.density_peaks.1,
                    beyond_stop: h.density_peaks.2,
                },
                filter_last: h.filter_last,
                pos,
                velrho,
                code,
                rate,
                energy,
                solid,
                bodies: h.body_bits.into_iter().map(f64::from_bits).collect(),
                maps,
            },
            subdomain: h.subdomain,
        })
    }
}

/// A format-1 solid section (one state per particle, in the GPU order of `code`) as format 2
/// has it: the solid particles' states in id order.
fn solid_by_id(per_particle: &[SolidState], code: &[u32]) -> Result<Vec<SolidState>> {
    if per_particle.len() != code.len() {
        bail!(
            "section 'solid' has {} states for {} particles",
            per_particle.len(),
            code.len()
        );
    }
    let mut by_id: Vec<(u32, SolidState)> = code
        .iter()
        .zip(per_particle)
        .filter(|(c, _)| Kind::code_is_solid(*c >> KIND_SHIFT))
        .map(|(c, s)| (c & ID_MASK, *s))
        .collect();
    by_id.sort_unstable_by_key(|(id, _)| *id);
    Ok(by_id.into_iter().map(|(_, s)| s).collect())
}

fn pod_vec<T: bytemuck::Pod>(bytes: &[u8], name: &str) -> Result<Vec<T>> {
    if !bytes.len().is_multiple_of(std::mem::size_of::<T>()) {
        bail!(
            "section '{name}' has {} bytes, not whole elements",
            bytes.len()
        );
    }
    Ok(bytemuck::pod_collect_to_vec(bytes))
}

/// The time-step state of a checkpoint of `format`.
fn sim_state(bytes: &[u8], format: u32) -> Result<SimState> {
    if format < 3 && bytes.len() == SIM_STATE_BYTES_V2 {
        let mut full = [0u8; std::mem::size_of::<SimState>()];
        full[..bytes.len()].copy_from_slice(bytes);
        return pod_one(&full, "sim");
    }
    pod_one(bytes, "sim")
}

fn pod_one<T: bytemuck::Pod>(bytes: &[u8], name: &str) -> Result<T> {
    if bytes.len() != std::mem::size_of::<T>() {
        bail!("section '{name}' has {} bytes", bytes.len());
    }
    Ok(bytemuck::pod_read_unaligned(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Kind;

    fn sample() -> Checkpoint {
        let n = 5;
        Checkpoint {
            case_name: "c".into(),
            fingerprint: 0x0123_4567_89ab_cdef,
            source: Some(CaseSource {
                path: "/cases/a.toml".into(),
                overrides: vec!["time.end_s=1".into()],
            }),
            snapshot_field: Some("speed".into()),
            adapter: "llvmpipe".into(),
            policy: Some(CheckpointPolicy {
                every_sim_s: Some(0.25),
                every_wall_s: None,
            }),
            time_s: 0.1 + 0.2,
            outputs: OutputState {
                next_output_s: 1.0 / 3.0,
                snapshots: vec![(0.0, "particles/particles_000000.vtu".into())],
                probe_tables: vec!["t_s,pressure_pa\n0,1.5\n".into()],
                body_tables: vec![],
                // A widened f32 (as the run's peaks are) that serde_json's default float
                // parser read back one ulp off (issue 64).
                max_density_variation: (f64::from(0.010_712_147_f32), 0.15),
                density_episodes: 2,
                wall_s: 12.5,
            },
            solver: SolverState {
                parity: 1,
                t_base: 0.3,
                steps: 1234,
                initial_dt: 1e-4,
                sim: SimState {
                    t_rel: 1e-7,
                    dt: 2e-4,
                    steps: 77,
                    ..Default::default()
                },
                peaks: DensityPeaks {
                    variation: 0.031,
                    beyond_warn: 12,
                    beyond_stop: 1,
                },
                filter_last: 60,
                pos: (0..n)
                    .map(|i| Pos {
                        off: [i as f32 * 0.1, -0.0, f32::MIN_POSITIVE],
                        block: i,
                    })
                    .collect(),
                velrho: (0..n).map(|i| [i as f32, 1.0, 2.0, 1000.5]).collect(),
                code: (0..n).rev().collect(),
                rate: (0..n).map(|i| [0.5, i as f32, -3.0, 1e-9]).collect(),
                energy: Some((0..n).map(|i| [i as f32, 7.0]).collect()),
                solid: Some(
                    (0..n)
                        .map(|i| SolidState {
                            tau_a: [i as f32, -1.0, 2.5, 1e3],
                            body: i,
                            ..Default::default()
                        })
                        .collect(),
                ),
                bodies: vec![1.0 / 7.0; crate::body::SAVED_PER_BODY],
                maps: Some(
                    (0..5)
                        .map(|i| MapCell {
                            max_depth: i as f32 * 0.25,
                            arrival: if i == 0 { -1.0 } else { 0.1 * i as f32 },
                            wet_samples: i,
                            ..MapCell::UNSEEN
                        })
                        .collect(),
                ),
            },
            subdomain: None,
        }
    }

    fn temp(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("wgsph-ckp-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d.join(CHECKPOINT_FILE)
    }

    /// Asserts that `change` to the case `text` leaves its particles and physics as they are
    /// but changes the fingerprint.
    fn assert_fingerprint_sees(text: &str, change: &str) {
        let a = crate::case::load_str(text, "x.toml", &[]).unwrap();
        let b = crate::case::load_str(text, "x.toml", &[change.to_string()]).unwrap();
        assert_eq!((&a.particles, &a.physics), (&b.particles, &b.physics));
        assert_ne!(fingerprint(&a), fingerprint(&b), "{change}");
    }

    /// Moving an outlet changes no particle, but a run resumed with it would differ.
    #[test]
    fn the_fingerprint_sees_outlets() {
        let text = include_str!("../cases/free_overfall_2d.toml");
        assert_fingerprint_sees(text, "outlet[0].min_m=[0.45, -0.4]");
    }

    /// A plate with more artificial viscosity has the same particles and physics, but a run
    /// resumed with it would differ.
    #[test]
    fn the_fingerprint_sees_the_solid_material() {
        let text = include_str!("../cases/oscillating_plate_2d.toml");
        assert_fingerprint_sees(text, "solid[0].alpha=0.2");
    }

    /// Friction changes a run; without it, neither it nor its regularisation speed enters the
    /// fingerprint, which is then that of a build from before friction existed.
    #[test]
    fn the_fingerprint_sees_friction_only_when_on() {
        let text = include_str!("../cases/floating_box_2d.toml");
        assert_fingerprint_sees(text, "walls.friction_coefficient=0.3");
        let a = crate::case::load_str(text, "x.toml", &[]).unwrap();
        let b = crate::case::load_str(text, "x.toml", &["walls.friction_slip_m_s=0.01".into()])
            .unwrap();
        assert_eq!(fingerprint(&a), fingerprint(&b));
        let walls = format!("{:?}", a.walls);
        assert!(
            walls.contains(", friction: 0.0, friction_slip: 0.001, friction_pairs: [],"),
            "{walls}"
        );
        // A pair with a coefficient of its own is seen, even one of 0 (the default's value).
        let paired =
            format!("{text}\n[[friction]]\nbetween = [\"box\", \"walls\"]\ncoefficient = 0.0\n");
        let c = crate::case::load_str(&paired, "x.toml", &[]).unwrap();
        assert_eq!(c.walls.friction_pairs.len(), 1);
        assert_ne!(fingerprint(&a), fingerprint(&c));
    }

    #[test]
    fn round_trips_exactly() {
        let path = temp("roundtrip");
        let c = sample();
        c.write(&path).unwrap();
        assert_eq!(Checkpoint::read(&path).unwrap(), c);
        let mut no_energy = c.clone();
        no_energy.solver.energy = None;
        no_energy.solver.solid = None;
        no_energy.solver.maps = None;
        no_energy.write(&path).unwrap();
        assert_eq!(Checkpoint::read(&path).unwrap(), no_energy);
        // A rank's part of a run over ranks: its counts and cuts.
        let mut ranked = crate::sph::subdomain::Ranked::default();
        ranked.halo_sent = 12_345;
        ranked.bytes_sent = 790_080;
        ranked.owned = 2_000;
        ranked.rebalances = 3;
        ranked.slabs = Some(crate::decomposition::Slabs::balanced(1, &[1.0; 9], 3, 1).unwrap());
        let rank = Checkpoint {
            subdomain: Some(RankCheckpoint {
                rank: 2,
                ranks: 3,
                generation: 1,
                ranked,
            }),
            ..c
        };
        rank.write(&path).unwrap();
        assert_eq!(Checkpoint::read(&path).unwrap(), rank);
        std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
    }

    /// A format-1 file (one solid state per particle, in the saved GPU order) reads as format 2:
    /// the solid particles' states only, in id order.
    #[test]
    fn format_1_solid_sections_are_read_in_id_order() {
        let path = temp("format1");
        let mut c = sample();
        let n = c.solver.code.len() as u32;
        // GPU order: ids n−1 … 0; ids 1, 2 and 3 are solid (3 clamped), the rest fluid.
        let kind = |id: u32| match id {
            1 | 2 => Kind::Solid as u32,
            3 => Kind::SolidClamped as u32,
            _ => Kind::Fluid as u32,
        };
        c.solver.code = (0..n).rev().map(|id| kind(id) << KIND_SHIFT | id).collect();
        c.write(&path).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[8..12].copy_from_slice(&1u32.to_le_bytes());
        let body = bytes.len() - 8;
        let mut sum = Fnv::default();
        sum.update(&bytes[..body]);
        bytes[body..].copy_from_slice(&sum.finish().to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let read = Checkpoint::read(&path).unwrap();
        // The sample's state at GPU index i has body i; id k sits at index n − 1 − k.
        let bodies: Vec<u32> = read.solver.solid.unwrap().iter().map(|s| s.body).collect();
        assert_eq!(bodies, [n - 2, n - 3, n - 4]);
        std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
    }

    /// A format-2 file (the time-step state 48 bytes long, before the density monitor) reads
    /// with the monitor cleared and everything else as written.
    #[test]
    fn format_2_time_step_states_are_read_with_the_monitor_cleared() {
        let path = temp("format2");
        let mut c = sample();
        c.solver.sim.density_variation_peak = 0.5;
        c.write(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let json_len = u64::from_le_bytes(bytes[12..20].try_into().unwrap()) as usize;
        let mut header: serde_json::Value =
            serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
        header["format"] = 2.into();
        let sim = header["sections"][0].as_array_mut().unwrap();
        assert_eq!(sim[0], "sim");
        sim[1] = SIM_STATE_BYTES_V2.into();
        let json = serde_json::to_vec(&header).unwrap();
        let sections = &bytes[20 + json_len..bytes.len() - 8];
        let cut = std::mem::size_of::<SimState>() - SIM_STATE_BYTES_V2;
        let mut old = Vec::new();
        old.extend_from_slice(MAGIC);
        old.extend_from_slice(&2u32.to_le_bytes());
        old.extend_from_slice(&(json.len() as u64).to_le_bytes());
        old.extend_from_slice(&json);
        old.extend_from_slice(&sections[..SIM_STATE_BYTES_V2]);
        old.extend_from_slice(&sections[SIM_STATE_BYTES_V2 + cut..]);
        let mut sum = Fnv::default();
        sum.update(&old);
        old.extend_from_slice(&sum.finish().to_le_bytes());
        std::fs::write(&path, &old).unwrap();
        let read = Checkpoint::read(&path).unwrap();
        c.solver.sim.density_variation_peak = 0.0;
        assert_eq!(read, c);
        std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
    }

    #[test]
    fn truncated_or_damaged_files_are_refused() {
        let path = temp("damaged");
        sample().write(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        for cut in [0, 7, 20, bytes.len() / 2, bytes.len() - 1] {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            let e = format!("{:#}", Checkpoint::read(&path).unwrap_err());
            assert!(e.contains("checkpoint"), "{e}");
        }
        let mut flipped = bytes.clone();
        let k = flipped.len() - 20;
        flipped[k] ^= 1;
        std::fs::write(&path, &flipped).unwrap();
        let e = format!("{:#}", Checkpoint::read(&path).unwrap_err());
        assert!(e.contains("checksum"), "{e}");
        std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
    }

    /// Damage behind a checksum that still matches (re-signed: a hostile edit, or the one
    /// collision in 2^64) reaches the decoder itself: no damaged copy may panic it.
    #[test]
    fn damage_behind_a_matching_checksum_is_an_error_not_a_panic() {
        let path = temp("resigned");
        sample().write(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let body = &bytes[..bytes.len() - 8];
        let signed = |b: &[u8]| {
            let mut sum = Fnv::default();
            sum.update(b);
            let mut signed = b.to_vec();
            signed.extend_from_slice(&sum.finish().to_le_bytes());
            Checkpoint::decode(&signed)
        };
        assert_eq!(signed(body).unwrap(), sample());
        crate::output::test_util::survives_damage("a checkpoint", body, 1, signed);
        std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
    }

    #[test]
    fn checkpoint_policy_parses_simulated_and_wall_intervals() {
        let p = |s: &str| s.parse::<CheckpointPolicy>();
        assert_eq!(p("0.5").unwrap().every_sim_s, Some(0.5));
        assert_eq!(p("0.25s").unwrap().every_sim_s, Some(0.25));
        let wall = p("10min").unwrap();
        assert_eq!((wall.every_sim_s, wall.every_wall_s), (None, Some(600.0)));
        assert_eq!(p("never").unwrap(), CheckpointPolicy::default());
        for bad in ["", "0", "-1s", "nan", "tenmin", "1h"] {
            let e = p(bad).unwrap_err().to_string();
            assert!(e.contains("--checkpoint-every"), "{bad}: {e}");
        }
    }
}
