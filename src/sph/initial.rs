//! The initial particle arrays of a run, packed as the GPU stores them, and what the case holds
//! (`Present`, the body and solid id ranges): pure functions of the scenario.

use std::ops::Range;

use anyhow::{bail, Result};

use super::buffers::ParticleBuffers;
use crate::gpu::GpuContext;
use crate::grid::Grid;
use crate::layout::{pack_block, IdSplit, Packed, Pos, SolidState, KIND_EXCLUDED};
use crate::scenario::{Kind, Scenario};

/// What a case holds, for the branches of the pair sums: the kernels leave out the terms of the
/// kinds it lacks. With every kind's branches compiled in, the interaction pass ran 15–40 %
/// slower on lavapipe (docs/performance.md, "Only the kinds a case has"), most likely from the
/// larger kernel's code and registers: lanes already skip a branch that none of them takes.
/// Every flag on is always correct, only slower.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Present {
    /// Elastic solid particles (`Kind::Solid`, `Kind::SolidClamped`).
    pub solids: bool,
    /// Fixed ghost particles, of walls or of bodies.
    pub fixed_ghosts: bool,
    /// Repulsive boundary particles.
    pub repulsive: bool,
    /// Particles of moving bodies (ids from `params.body_id_base` on).
    pub bodies: bool,
    /// Mirror planes.
    pub mirrors: bool,
    /// Every particle is of one elastic body: no fluid, boundary particle or other solid can
    /// load it, and interaction.wgsl gives its particles zero (rather than searching their
    /// neighbours for nothing: 23 % of the step of the total-Lagrangian plate on lavapipe).
    pub lone_solid: bool,
}

impl Present {
    pub const ALL: Present = Present {
        solids: true,
        fixed_ghosts: true,
        repulsive: true,
        bodies: true,
        mirrors: true,
        lone_solid: false,
    };
    /// A fluid with dynamic boundary particles only.
    pub const NONE: Present = Present {
        solids: false,
        fixed_ghosts: false,
        repulsive: false,
        bodies: false,
        mirrors: false,
        lone_solid: false,
    };

    /// Which kinds of particle and wall `sc` has: kinds do not appear during a run (inlet
    /// particles become fluid, any particle may become excluded).
    pub fn of(sc: &Scenario) -> Result<Present> {
        let has = |kinds: &[Kind]| sc.particles.iter().any(|p| kinds.contains(&p.kind));
        Ok(Present {
            solids: has(&[Kind::Solid, Kind::SolidClamped]),
            fixed_ghosts: has(&[Kind::GhostNoSlip, Kind::GhostFreeSlip]),
            repulsive: has(&[Kind::Repulsive]),
            bodies: (body_id_base(sc)? as usize) < sc.particles.len(),
            mirrors: !sc.walls.mirror_planes.is_empty(),
            lone_solid: sc.solids.as_ref().is_some_and(|s| s.materials.len() == 1)
                && sc.particles.iter().all(|p| p.kind.is_solid()),
        })
    }
}

/// How `sc`'s particle ids are stored: wide where `particles.id_low_bits` asks for it or
/// where the run has too many particles for narrow ids.
pub fn id_split(sc: &Scenario) -> IdSplit {
    IdSplit::for_run(sc.particles.len() as u64, sc.physics.id_low_bits)
}

/// `sc`'s particles on `grid`: positions as block offsets, and inlet particles behind their
/// buffers excluded (in no cell) until they join.
pub fn pack(sc: &Scenario, grid: &Grid) -> Packed {
    pack_range(sc, grid, 0..sc.particles.len())
}

/// The particles `ids` of `sc` packed as [`pack`] packs them all (entry k is particle
/// `ids.start + k`).
pub fn pack_range(sc: &Scenario, grid: &Grid, ids: Range<usize>) -> Packed {
    let split = id_split(sc);
    let mut out = Packed {
        pos: Vec::with_capacity(ids.len()),
        velrho: Vec::with_capacity(ids.len()),
        code: Vec::with_capacity(ids.len()),
        id: (ids.start as u32..ids.end as u32).collect(),
        ids: split,
    };
    for (id, p) in sc.particles[ids.clone()].iter().enumerate() {
        let (off, b) = grid.to_block(p.pos);
        out.pos.push(Pos {
            off,
            block: pack_block(b),
        });
        let v = p.vel.map(|x| x as f32);
        out.velrho.push([v[0], v[1], v[2], p.rho as f32]);
        out.code
            .push(split.code_word(p.kind as u32, (ids.start + id) as u32));
    }
    for inlet in &sc.inlets {
        for (k, id) in inlet.particles.clone().enumerate() {
            if inlet.dormant(k) && ids.contains(&id) {
                out.code[id - ids.start] = split.code_word(KIND_EXCLUDED, id as u32);
            }
        }
    }
    out
}

/// Particles packed and written at a time by [`write_in_pieces`]: 2.5 MiB of packed arrays,
/// small beside any case that needs pieces, and a wait for the GPU every 65 536 particles.
pub const UPLOAD_PIECE: usize = 1 << 16;

/// Packs `sc`'s particles on `grid` and writes them into `buffers` [`UPLOAD_PIECE`] at a time,
/// waiting for the GPU after each piece: beside the case's particles the host holds one
/// piece's packed arrays and the queue's staging copy of them (issue 64: it held the whole
/// case's packed arrays, their code words again, a zeroed rate array and staging copies of
/// them all, about 110 bytes a particle).
pub fn write_in_pieces(
    sc: &Scenario,
    grid: &Grid,
    buffers: &ParticleBuffers,
    ctx: &GpuContext,
) -> Result<()> {
    let n = sc.particles.len();
    for first in (0..n).step_by(UPLOAD_PIECE) {
        let piece = pack_range(sc, grid, first..(first + UPLOAD_PIECE).min(n));
        buffers.write_particles(&ctx.queue, first as u32, &piece);
        ctx.queue.submit([]);
        (ctx.device.poll(wgpu::PollType::wait_indefinitely()))
            .map_err(|e| anyhow::anyhow!("GPU wait failed writing the particles: {e}"))?;
    }
    Ok(())
}

/// The id of the first body particle: bodies' particles must come last, body after body, in
/// the scenario's order (the case builder puts them there). Without bodies, the particle count.
pub fn body_id_base(sc: &Scenario) -> Result<u32> {
    let n = sc.particles.len();
    let base = sc.bodies.first().map_or(n, |b| b.particles.start);
    let mut next = base;
    for b in &sc.bodies {
        if b.particles.start != next || b.particles.is_empty() {
            bail!(
                "body '{}' has particles {:?}: bodies need non-empty ranges that follow each \
                 other up to the last particle",
                b.name,
                b.particles
            );
        }
        next = b.particles.end;
    }
    if next != n {
        bail!("the bodies' particles must be the last ones of the scenario");
    }
    Ok(base as u32)
}

/// The solid particles' ids; they must be consecutive (the case loader builds them so), which
/// lets the solid arrays be indexed by id − first id.
pub(crate) fn solid_range(sc: &Scenario) -> Result<std::ops::Range<usize>> {
    let ids: Vec<usize> = (0..sc.particles.len())
        .filter(|&i| sc.particles[i].kind.is_solid())
        .collect();
    consecutive(&ids, "the elastic solids")
}

/// The range that sorted `ids` fill, when they are consecutive (the particles of `what`).
pub(crate) fn consecutive(ids: &[usize], what: &str) -> Result<std::ops::Range<usize>> {
    let (Some(&first), Some(&last)) = (ids.first(), ids.last()) else {
        bail!("{what} have no particles");
    };
    if last - first + 1 != ids.len() {
        bail!("{what}' particles must have consecutive ids");
    }
    Ok(first..last + 1)
}

/// The initial state (τ0, body, material) of every solid particle, in id order, or nothing
/// without solids.
pub fn solid_states(sc: &Scenario) -> Result<Vec<SolidState>> {
    let Some(solids) = &sc.solids else {
        return Ok(Vec::new());
    };
    let n = sc.particles.len();
    if solids.body.len() != n || solids.tau0.len() != n {
        bail!(
            "the solids have {} bodies and {} stresses for {n} particles",
            solids.body.len(),
            solids.tau0.len()
        );
    }
    let (_, material) = solids.distinct_materials();
    solid_range(sc)?
        .map(|i| {
            let t = solids.tau0[i].map(|x| x as f32);
            let body = solids.body[i];
            Ok(SolidState {
                tau_a: [t[0], t[1], t[2], t[3]],
                tau_b: [t[4], t[5], 0.0],
                body,
                material: *material.get(body as usize).ok_or_else(|| {
                    anyhow::anyhow!(
                        "solid particle {i} is of body {body}, which has no material ({} given)",
                        solids.materials.len()
                    )
                })?,
                ..Default::default()
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::KIND_SHIFT;

    fn present_in(case: &str) -> Present {
        let sc = crate::case::load(std::path::Path::new(case), &[]).unwrap();
        Present::of(&sc).unwrap()
    }

    /// Only a case of one elastic body and nothing else skips its solids' neighbour search:
    /// with water, walls or a second solid, the solid must be loaded.
    #[test]
    fn a_lone_solid_is_a_case_of_one_elastic_body_alone() {
        assert!(present_in("cases/oscillating_plate_2d.toml").lone_solid);
        assert!(present_in("cases/oscillating_plate_tl_2d.toml").lone_solid);
        assert!(!present_in("cases/elastic_gate_2d.toml").lone_solid);
        assert!(!present_in("cases/dam_break_2d.toml").lone_solid);
        let text = std::fs::read_to_string("cases/oscillating_plate_2d.toml")
            .unwrap()
            .replace("[[solid]]", "[walls]\nrepulsive_d_m2_s2 = 1.0\n[[solid]]")
            + "\n[[solid]]\nname = \"second\"\nmin_m = [0.0, 0.1]\nmax_m = [0.2, 0.12]\n\
               density_kg_m3 = 1000.0\nyoungs_modulus_pa = 2.0e6\npoisson_ratio = 0.3975\n";
        let two = crate::case::load_str(&text, "two.toml", &[]).unwrap();
        assert!(!Present::of(&two).unwrap().lone_solid);
    }

    /// Packing keeps every particle's kind and id in its code word and its world position within
    /// f32 rounding of the block offset.
    #[test]
    fn packed_particles_keep_kind_id_and_position() {
        let sc = crate::case::load(std::path::Path::new("cases/dam_break_2d.toml"), &[]).unwrap();
        let grid = Grid::of(&sc).unwrap();
        let packed = pack(&sc, &grid);
        assert!(!packed.ids.wide);
        assert!(packed.high_words().is_empty());
        for (id, p) in sc.particles.iter().enumerate() {
            assert_eq!(packed.code[id] & crate::layout::ID_MASK, id as u32);
            assert_eq!(packed.code[id] >> KIND_SHIFT, p.kind as u32);
            let x = grid.to_world(
                packed.pos[id].off,
                crate::layout::unpack_block(packed.pos[id].block),
            );
            for (a, (x, x0)) in x.iter().zip(p.pos).enumerate() {
                assert!((x - x0).abs() < 1e-6, "particle {id} axis {a}");
            }
            assert_eq!(packed.velrho[id][3], p.rho as f32);
        }
    }

    /// Packed in pieces, the water injection's particles are the whole packing's: positions,
    /// velocities and densities, ids, and the inlet particles waiting behind their buffers
    /// excluded in whichever piece holds them.
    #[test]
    fn pieces_pack_as_the_whole() {
        let path = std::path::Path::new("cases/water_injection_2d.toml");
        let sc = crate::case::load(path, &[]).unwrap();
        let grid = Grid::of(&sc).unwrap();
        let whole = pack(&sc, &grid);
        let n = sc.particles.len();
        let excluded = |code: &[u32]| {
            code.iter()
                .filter(|&&c| c >> KIND_SHIFT == KIND_EXCLUDED)
                .count()
        };
        assert!(excluded(&whole.code) > 0);
        let (first, last) = (sc.inlets[0].particles.start, sc.inlets[0].particles.end);
        let cuts = [0, 1, first + 1, (first + last) / 2, last, n - 1, n];
        for w in cuts.windows(2) {
            let piece = pack_range(&sc, &grid, w[0]..w[1]);
            let bytes = |x: &[Pos]| bytemuck::cast_slice::<Pos, u8>(x).to_vec();
            assert_eq!(bytes(&piece.pos), bytes(&whole.pos[w[0]..w[1]]), "{w:?}");
            assert_eq!(piece.velrho, whole.velrho[w[0]..w[1]], "{w:?}");
            assert_eq!(piece.code, whole.code[w[0]..w[1]], "{w:?}");
            assert_eq!(piece.id, whole.id[w[0]..w[1]], "{w:?}");
        }
    }

    /// With wide ids (forced with 4 low bits) a code word keeps an id's low bits and its kind,
    /// and the words after the n code words the rest: every id comes back from the two.
    #[test]
    fn wide_ids_split_between_the_code_word_and_a_second_word() {
        let set = ["particles.id_low_bits=4".to_string()];
        let path = std::path::Path::new("cases/dam_break_2d.toml");
        let sc = crate::case::load(path, &set).unwrap();
        let packed = pack(&sc, &Grid::of(&sc).unwrap());
        let n = sc.particles.len();
        assert!(packed.ids.wide && n > 1000);
        let words = [packed.code.clone(), packed.high_words()].concat();
        assert_eq!(words.len(), 2 * n);
        for (id, p) in sc.particles.iter().enumerate() {
            assert_eq!(packed.code[id] & crate::layout::ID_MASK, id as u32 & 15);
            assert_eq!(packed.code[id] >> KIND_SHIFT, p.kind as u32);
            assert_eq!(words[n + id], id as u32 >> 4);
            assert_eq!(packed.ids.id_at(&words, n, id), id as u32);
        }
        assert!(packed.ids.free_id() > n as u32);
    }
}
