//! An estimate of the bytes each stage of the step reads and writes per particle-step, from the
//! arrays its WGSL binds and what each invocation touches (`wgsph bench`). Divided into a
//! GPU's memory bandwidth it bounds the step's speed from above: the step cannot be faster than
//! moving these bytes.
//!
//! What it counts: every load and store of a per-particle array, each counted once per
//! invocation that makes it, at the size of the element (or component) the shader names; the
//! neighbour loops' loads per candidate tested and per neighbour found, with the counts
//! measured on the particles; and the slot table (cell starts, the prefix scan) per slot. What
//! it leaves out: caches (a neighbour's position is loaded by every particle around it, and on a
//! GPU mostly hits L1/L2, so the neighbour loops' bytes are DRAM bytes only without a cache),
//! memory transactions (a 4-byte load moves a 32-byte sector), uniforms and the small case
//! tables, the per-step single-invocation kernels, the clear of the slot histogram, and the
//! stages it does not model (named as such).

use std::mem::size_of;

use crate::layout::Pos;

/// A particle's position: block offset and packed block (src/layout.rs, checked against naga).
const POS: f64 = size_of::<Pos>() as f64;
/// A `vec4<f32>`: velrho (v, ρ), rate (dv/dt, dρ/dt), rate_old, the filtered density.
const VEC4: f64 = size_of::<[f32; 4]>() as f64;
/// A `u32` or `f32`: code (kind + id), ranks, permutation, a slot's start, one component.
const WORD: f64 = size_of::<u32>() as f64;
/// (e, de/dt), with `physics.energy`.
const ENERGY: f64 = size_of::<[f32; 2]>() as f64;

/// Bytes read and written.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bytes {
    pub read: f64,
    pub written: f64,
}

impl Bytes {
    const fn new(read: f64, written: f64) -> Bytes {
        Bytes { read, written }
    }

    pub fn total(&self) -> f64 {
        self.read + self.written
    }

    fn scaled(self, k: f64) -> Bytes {
        Bytes::new(k * self.read, k * self.written)
    }
}

impl std::ops::Add for Bytes {
    type Output = Bytes;
    fn add(self, o: Bytes) -> Bytes {
        Bytes::new(self.read + o.read, self.written + o.written)
    }
}

/// What the model needs of a case's particles and grid, per live particle in one state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepCounts {
    pub dim: u32,
    /// Rows of cells take one range each (`Grid::contiguous_rows`).
    pub contiguous_rows: bool,
    /// Cells per support (`Grid::reach`): a neighbourhood is (2 reach + 1)^d cells.
    pub reach: u32,
    /// Entries of the slot table (slots + 3) per particle.
    pub slots_per_particle: f64,
    pub fluid_fraction: f64,
    /// Fixed ghost particles, which `ghost` interpolates.
    pub ghost_fraction: f64,
    pub energy: bool,
    /// The density filter's period in steps, if the case has one.
    pub density_filter_every: Option<u32>,
    /// Candidates and neighbours per particle (all live, and fluid).
    pub work: super::NeighbourWork,
}

impl StepCounts {
    /// Cells along an axis of a neighbourhood: 2 reach + 1.
    fn side(&self) -> f64 {
        (2 * self.reach + 1) as f64
    }

    /// The particles of a slot, seen from one of them: the candidates come from the
    /// side^d cells around a particle, so a cell holds about candidates / side^d.
    fn slot_mates(&self) -> f64 {
        self.work.candidates / self.side().powi(self.dim as i32)
    }

    /// The slot table entries `neighbour_ranges` loads: two per row of cells where rows are
    /// contiguous (side^(d-1) rows), two per slot of the side^d cells otherwise.
    fn range_bytes(&self) -> f64 {
        let cells = self.side().powi(self.dim as i32);
        let ranges = if self.contiguous_rows {
            cells / self.side()
        } else {
            cells
        };
        2.0 * WORD * ranges
    }

    fn energy_bytes(&self, bytes: f64) -> f64 {
        if self.energy {
            bytes
        } else {
            0.0
        }
    }
}

/// A neighbour loop of one stage: the particles that run it and what each loads per candidate
/// (before the distance test) and per neighbour within the support.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeighbourLoop {
    /// Fraction of the particles that run the loop.
    pub runners: f64,
    /// Per runner.
    pub candidates: f64,
    /// Per runner, those the loop goes on with (the particle itself excluded where it skips it).
    pub neighbours: f64,
    pub bytes_per_candidate: f64,
    pub bytes_per_neighbour: f64,
    /// The slot table entries that give the loop its ranges.
    pub range_bytes: f64,
}

impl NeighbourLoop {
    fn read(&self) -> f64 {
        self.runners
            * (self.range_bytes
                + self.candidates * self.bytes_per_candidate
                + self.neighbours * self.bytes_per_neighbour)
    }
}

/// One stage's traffic, per particle of the step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageCost {
    /// The per-particle arrays, averaged over the particles' kinds.
    pub per_particle: Bytes,
    /// Per entry of the slot table.
    pub per_slot: Bytes,
    pub neighbour_loop: Option<NeighbourLoop>,
    /// Steps per run of the stage (the density filter's period), 1 otherwise.
    pub every: u32,
}

impl StageCost {
    fn particles(per_particle: Bytes) -> StageCost {
        StageCost {
            per_particle,
            every: 1,
            ..Default::default()
        }
    }

    /// Bytes per particle-step.
    pub fn bytes(&self, c: &StepCounts) -> Bytes {
        let streamed = self.per_particle + self.per_slot.scaled(c.slots_per_particle);
        streamed.scaled(1.0 / self.every as f64) + Bytes::new(self.neighbour_loop_read(), 0.0)
    }

    /// Bytes per particle-step the neighbour loop reads: the other particles' arrays, which a
    /// GPU's caches serve mostly (each particle is the neighbour of the ~100 around it).
    pub fn neighbour_loop_read(&self) -> f64 {
        self.neighbour_loop.map_or(0.0, |l| l.read()) / self.every as f64
    }
}

/// The cost of stage `name` of `Passes::record_step`, None for a stage the model leaves out.
pub fn stage_cost(name: &str, c: &StepCounts) -> Option<StageCost> {
    let fluid = c.fluid_fraction;
    let boundary = 1.0 - fluid;
    Some(match name {
        // integrate.wgsl `predict`: code, velrho, rate of all; a fluid particle also its pos
        // (read, moved, written) and its velrho, a wall only its density (velrho.w); with
        // energy a fluid particle's (e, de/dt) read and e written.
        "predict" => StageCost::particles(Bytes::new(
            WORD + 2.0 * VEC4 + fluid * (POS + c.energy_bytes(ENERGY)),
            fluid * (POS + VEC4 + c.energy_bytes(WORD)) + boundary * WORD,
        )),
        // cell_list.wgsl `cell_key`: code, pos (`sort_slot`); the provisional rank written, the
        // slot's count read and written by the atomic.
        "sort_key" => StageCost::particles(Bytes::new(WORD + POS + WORD, 2.0 * WORD)),
        // prefix_scan.wgsl: `scan_blocks` reads and writes each slot's count, `scan_add` reads
        // it and its block's sum and writes it back (the block sums' levels are 1/512 of that).
        "sort_scan" => StageCost {
            per_slot: Bytes::new(3.0 * WORD, 2.0 * WORD),
            ..StageCost::particles(Bytes::default())
        },
        // `scatter`: code and pos (`sort_slot`), the slot's start and the rank read,
        // `provisional` written; `rank_in_cell`: provisional, code and pos (`sort_slot`), the
        // slot's start and end, and per slot-mate its index and code word (ordering by id);
        // `perm` written.
        "sort_scatter" => StageCost::particles(Bytes::new(
            (POS + 3.0 * WORD) + (POS + 4.0 * WORD) + 2.0 * WORD * c.slot_mates(),
            2.0 * WORD,
        )),
        // `reorder` and `reorder_motion` (and `reorder_energy`): the permutation read by each,
        // pos, code, velrho, rate (and energy) gathered and written into the other parity.
        "sort_reorder" => {
            let moved = POS + WORD + 2.0 * VEC4 + c.energy_bytes(ENERGY);
            let perm = WORD * if c.energy { 3.0 } else { 2.0 };
            StageCost::particles(Bytes::new(perm + moved, moved))
        }
        // ghost.wgsl `ghost_interpolate` (dispatched only when the case has fixed ghosts):
        // every particle's code; a ghost's pos, then `fluid_at` loads each candidate's code and
        // a fluid candidate's pos, a fluid neighbour's velrho; the ghost's velrho written.
        "ghost" if c.ghost_fraction == 0.0 => StageCost::particles(Bytes::default()),
        "ghost" => StageCost {
            per_particle: Bytes::new(WORD + c.ghost_fraction * POS, c.ghost_fraction * VEC4),
            neighbour_loop: Some(NeighbourLoop {
                runners: c.ghost_fraction,
                candidates: c.work.candidates,
                neighbours: c.work.neighbours,
                bytes_per_candidate: WORD + fluid * POS,
                bytes_per_neighbour: fluid * VEC4,
                range_bytes: c.range_bytes(),
            }),
            every: 1,
            ..Default::default()
        },
        // interaction.wgsl: code, pos, velrho of i, its rate (and de/dt) written; the loop
        // loads each candidate's pos before the distance test, and a neighbour's code and
        // velrho (a fluid particle's loop; a fixed dynamic wall's, `wall_continuity`, tests
        // only the fluid of each slot, loading a candidate's code before its pos and a
        // neighbour's velrho: 4 B more a candidate and 4 B less a neighbour, and a code word
        // a slot, left out here). Ghosts (and inlets) write a zero rate only; they are counted
        // with the rest for their code and pos.
        "interaction" => StageCost {
            per_particle: Bytes::new(WORD + POS + VEC4, VEC4 + c.energy_bytes(WORD)),
            neighbour_loop: Some(NeighbourLoop {
                runners: 1.0 - c.ghost_fraction,
                candidates: c.work.candidates,
                neighbours: (c.work.neighbours - 1.0).max(0.0),
                bytes_per_candidate: POS,
                bytes_per_neighbour: WORD + VEC4,
                range_bytes: c.range_bytes(),
            }),
            every: 1,
            ..Default::default()
        },
        // integrate.wgsl `correct`: code, rate, velrho, rate_old read; a fluid particle's velrho
        // written (and energy: e, de/dt, the new de/dt read, both written), a wall's density.
        "correct" => StageCost::particles(Bytes::new(
            WORD + 3.0 * VEC4 + fluid * c.energy_bytes(ENERGY + WORD),
            fluid * (VEC4 + c.energy_bytes(ENERGY)) + boundary * WORD,
        )),
        // density_filter.wgsl, on the steps the gate opens: the filter reads code of all, a
        // fluid particle's pos and velrho, its ranges, each candidate's code then pos, a
        // neighbour's density (velrho.w, itself included), and writes `filtered`;
        // `apply_density` reads code and a fluid particle's filtered density, writes its ρ.
        "density_filter" => StageCost {
            per_particle: Bytes::new(
                2.0 * WORD + fluid * (POS + VEC4 + VEC4),
                fluid * (VEC4 + WORD),
            ),
            neighbour_loop: Some(NeighbourLoop {
                runners: fluid,
                candidates: c.work.fluid_candidates,
                neighbours: c.work.fluid_neighbours,
                bytes_per_candidate: WORD + POS,
                bytes_per_neighbour: WORD,
                range_bytes: c.range_bytes(),
            }),
            every: c.density_filter_every.unwrap_or(1),
            ..Default::default()
        },
        _ => return None,
    })
}

/// One stage's estimate, per particle-step (None: not modelled).
#[derive(Clone, Debug, PartialEq)]
pub struct StageTraffic {
    pub name: &'static str,
    pub bytes: Option<Bytes>,
    /// The part of `bytes.read` in the stage's neighbour loop.
    pub neighbour_loop_read: f64,
}

/// The estimate of a whole step, stage by stage.
#[derive(Clone, Debug, PartialEq)]
pub struct Traffic {
    pub stages: Vec<StageTraffic>,
}

impl Traffic {
    /// The estimate of the stages `names` (`Solver::stage_names`) under `counts`.
    pub fn of_step(names: &[&'static str], counts: &StepCounts) -> Traffic {
        let stages = names
            .iter()
            .map(|&name| {
                let cost = stage_cost(name, counts);
                StageTraffic {
                    name,
                    bytes: cost.map(|s| s.bytes(counts)),
                    neighbour_loop_read: cost.map_or(0.0, |s| s.neighbour_loop_read()),
                }
            })
            .collect();
        Traffic { stages }
    }

    /// The modelled stages' sum, per particle-step.
    pub fn total(&self) -> Bytes {
        (self.stages.iter().filter_map(|s| s.bytes)).fold(Bytes::default(), |a, b| a + b)
    }

    /// The part of `total().read` in the neighbour loops.
    pub fn neighbour_loop_read(&self) -> f64 {
        self.stages.iter().map(|s| s.neighbour_loop_read).sum()
    }

    /// The stages the estimate leaves out.
    pub fn unmodelled(&self) -> Vec<&'static str> {
        (self.stages.iter().filter(|s| s.bytes.is_none()))
            .map(|s| s.name)
            .collect()
    }

    pub fn of_stage(&self, name: &str) -> Option<Bytes> {
        self.stages.iter().find(|s| s.name == name)?.bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::NeighbourWork;
    use crate::gpu::kernel::parse;
    use crate::gpu::shader::Shader;
    use crate::sph::shader::{compose, ShaderConfig};
    use crate::sph::{cell_list, integrate};
    use wgpu::naga;

    /// A 2D dam break's counts as `wgsph bench cases/dam_break_2d.toml` measures them
    /// (2026-12-05): 4 274 particles, 3/4 of them fluid, a dense grid of about a slot per
    /// particle.
    fn dam_break_2d() -> StepCounts {
        StepCounts {
            dim: 2,
            contiguous_rows: true,
            reach: 1,
            slots_per_particle: 1.0,
            fluid_fraction: 0.75,
            ghost_fraction: 0.0,
            energy: false,
            density_filter_every: None,
            work: NeighbourWork {
                candidates: 50.4,
                neighbours: 19.2,
                fluid_candidates: 57.8,
                fluid_neighbours: 20.6,
            },
        }
    }

    /// The stages of a case with fluid and dynamic walls only (`Passes::record_step`).
    const PLAIN_STEP: [&str; 8] = [
        "predict",
        "sort_key",
        "sort_scan",
        "sort_scatter",
        "sort_reorder",
        "ghost",
        "interaction",
        "correct",
    ];

    /// Bytes per element of the per-particle arrays (runtime-sized storage arrays but the slot
    /// table) that entry points `entries` of `shader` read and write, summed, as naga sees
    /// them: each array the kernels use counted once per kernel, whole elements.
    fn bound_bytes(shader: &Shader, entries: &[&str]) -> Bytes {
        let cfg = ShaderConfig {
            energy: true,
            ..Default::default()
        };
        let (module, info) = parse(&compose(shader, cfg), shader.name).unwrap();
        let mut total = Bytes::default();
        for entry in entries {
            let index = (module.entry_points.iter())
                .position(|e| e.name == *entry)
                .unwrap_or_else(|| panic!("{entry} in {}", shader.name));
            let uses = info.get_entry_point(index);
            for (handle, var) in module.global_variables.iter() {
                let naga::TypeInner::Array {
                    size: naga::ArraySize::Dynamic,
                    stride,
                    ..
                } = module.types[var.ty].inner
                else {
                    continue;
                };
                if var.name.as_deref() == Some("cell_start") {
                    continue;
                }
                let used = uses[handle];
                let bytes = |flag| {
                    if used.contains(flag) {
                        stride as f64
                    } else {
                        0.0
                    }
                };
                total = total
                    + Bytes::new(
                        bytes(naga::valid::GlobalUse::READ),
                        bytes(naga::valid::GlobalUse::WRITE),
                    );
            }
        }
        total
    }

    /// The stages that stream their arrays once per particle: the model's bytes for an all-fluid
    /// case with the energy equation (every branch's arrays) are what their kernels bind and
    /// use, per naga. The predictor and the corrector write a wall's density or a fluid's e
    /// alone (one component) and code only to exclude a particle, so their writes are below.
    #[test]
    fn the_streaming_stages_move_the_arrays_their_kernels_use() {
        let c = StepCounts {
            fluid_fraction: 1.0,
            energy: true,
            ..dam_break_2d()
        };
        let stages: [(&str, &Shader, &[&str], bool); 4] = [
            ("predict", &integrate::SHADER, &["predict"], false),
            ("correct", &integrate::SHADER, &["correct"], false),
            ("sort_key", &cell_list::SHADER, &["cell_key"], true),
            (
                "sort_reorder",
                &cell_list::SHADER,
                &["reorder", "reorder_motion", "reorder_energy"],
                true,
            ),
        ];
        for (name, shader, entries, whole_writes) in stages {
            let model = stage_cost(name, &c).unwrap().per_particle;
            let bound = bound_bytes(shader, entries);
            assert_eq!(model.read, bound.read, "{name} reads");
            match whole_writes {
                true => assert_eq!(model.written, bound.written, "{name} writes"),
                false => assert!(
                    model.written < bound.written && model.written > 0.5 * bound.written,
                    "{name} writes {} of {}",
                    model.written,
                    bound.written
                ),
            }
        }
    }

    /// The interaction loads a position per candidate and a code word and (v, ρ) per
    /// neighbour; one more candidate per particle costs that position and, in the sort, a
    /// ninth of a slot-mate's index and code word (2D: the candidates are 9 cells' particles).
    #[test]
    fn a_candidate_costs_a_position_in_the_interaction() {
        let c = dam_break_2d();
        let interaction = stage_cost("interaction", &c)
            .unwrap()
            .neighbour_loop
            .unwrap();
        assert_eq!(interaction.bytes_per_candidate, size_of::<Pos>() as f64);
        assert_eq!(interaction.bytes_per_neighbour, 4.0 + 16.0);
        let names = PLAIN_STEP;
        let total = |c: &StepCounts| Traffic::of_step(&names, c).total();
        let mut more = c;
        more.work.candidates += 1.0;
        let added = total(&more).read - total(&c).read;
        assert!((added - (16.0 + 8.0 / 9.0)).abs() < 1e-9, "{added}");
        assert_eq!(total(&more).written, total(&c).written);
        assert!(Traffic::of_step(&names, &c).unmodelled().is_empty());
    }

    /// The whole 2D dam break, against bounds from the array sizes alone: at least the
    /// interaction's position per candidate and (code, v, ρ) per other neighbour, and the sort
    /// moving pos, velrho, rate and code (52 B) in and out; at most every candidate's whole
    /// particle (pos, velrho, code: 36 B) and twelve passes of the 68 B of a particle's arrays
    /// (with rate_old) in and out.
    #[test]
    fn a_dam_break_moves_between_its_loops_and_its_arrays() {
        let c = dam_break_2d();
        let names = PLAIN_STEP;
        let step = Traffic::of_step(&names, &c);
        let total = step.total().total();
        let w = c.work;
        let lower = 16.0 * w.candidates + 20.0 * (w.neighbours - 1.0) + 2.0 * 52.0;
        let upper = 36.0 * w.candidates + 12.0 * 2.0 * 68.0;
        assert!(
            total > lower && total < upper,
            "{lower} < {total} < {upper}"
        );
        // The neighbour loop is most of it, and all of it is read.
        assert!(step.neighbour_loop_read() > 0.5 * total);
        assert!(step.neighbour_loop_read() < step.total().read);
        // A density filter every 10 steps adds a tenth of its pass.
        let filtered = StepCounts {
            density_filter_every: Some(10),
            ..c
        };
        let names = [&names[..], &["density_filter"]].concat();
        let filter = Traffic::of_step(&names, &filtered)
            .of_stage("density_filter")
            .unwrap();
        let every_step = stage_cost(
            "density_filter",
            &StepCounts {
                density_filter_every: Some(1),
                ..c
            },
        )
        .unwrap()
        .bytes(&c);
        assert!((filter.total() - 0.1 * every_step.total()).abs() < 1e-9);
    }
}
