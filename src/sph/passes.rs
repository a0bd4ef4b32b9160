//! Every pass of the step, built for one case, and `record_step`: the one list of named passes
//! in their order. A new pass is added here (its module, its `SHADER` in [`SHADERS`], its place
//! in the step) and nowhere else.

use anyhow::Result;

use super::bodies::{self, Bodies};
use super::buffers::ParticleBuffers;
use super::cell_list::{self, CellList};
use super::density_filter::{self, DensityFilter};
use super::elastic::{self, Elastic};
use super::flood_maps::{self, FloodMapPass};
use super::ghost::{self, Ghost};
use super::halo::{self, Halo};
use super::integrate::{self, Integrate};
use super::interaction::{self, Interaction};
use super::open_boundaries::{self, OpenBoundaries};
use super::overlap::{self, Overlap};
use super::probes::{self, PointTracker, Probes};
use super::profile::Recorder;
use super::shader::{module, ShaderConfig};
use super::total_lagrangian::{self, TotalLagrangian};
use crate::gpu::shader::Shader;
use crate::grid::Grid;
use crate::layout::{BodyMotion, HaloCtl, ProbeDef};
use crate::scenario::{Kind, OverlapExchange, Scenario, SolidFormulation};

/// Every pass's shader, for the checks that compose them all.
pub const SHADERS: [&Shader; 14] = [
    &cell_list::SHADER,
    &cell_list::SCAN_SHADER,
    &interaction::SHADER,
    &integrate::SHADER,
    &probes::SHADER,
    &ghost::SHADER,
    &density_filter::SHADER,
    &bodies::SHADER,
    &elastic::SHADER,
    &total_lagrangian::SHADER,
    &open_boundaries::SHADER,
    &halo::SHADER,
    &overlap::SHADER,
    &flood_maps::SHADER,
];

/// The passes of a run; those of what the case lacks are `None`.
pub struct Passes {
    pub cell_list: CellList,
    pub interaction: Interaction,
    pub ghost: Ghost,
    pub integrate: Integrate,
    /// Shepard/MLS density re-initialisation, if the case asks for one.
    pub density_filter: Option<DensityFilter>,
    /// Updated-Lagrangian elastic solids.
    pub elastic: Option<Elastic>,
    /// Total-Lagrangian elastic solids.
    pub total_lagrangian: Option<TotalLagrangian>,
    /// Velocity inlets and outlets.
    pub open_boundaries: Option<OpenBoundaries>,
    /// Moving bodies' GPU part (the host dynamics are the solver's).
    pub bodies: Option<Bodies>,
    pub probes: Probes,
    /// Tracked points of bodies.
    pub points: Option<PointTracker>,
    /// Flood maps (`[maps]`).
    pub flood_maps: Option<FloodMapPass>,
    /// A subdomain's halo and migrants (`Solver::subdomain`); None in a whole run.
    pub halo: Option<Halo>,
    /// A subdomain whose steps may overlap the exchange (`time.overlap_exchange`): its
    /// choice, and its second sort's rates.
    pub overlap: Option<Overlap>,
}

impl Passes {
    /// A subdomain's halo pass.
    pub fn halo(&self) -> &Halo {
        self.halo.as_ref().expect("a subdomain has a halo pass")
    }

    /// [`Passes::halo`], to grow its buffers or change how it packs.
    pub fn halo_mut(&mut self) -> &mut Halo {
        self.halo.as_mut().expect("a subdomain has a halo pass")
    }

    /// The passes `sc` needs, compiled for `cfg`, over `b`; `defs` are the probes' GPU
    /// definitions and `motions` the bodies' table the buffers were made with; with
    /// `subdomain`, those of one rank's subdomain (its halo pass).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        device: &wgpu::Device,
        sc: &Scenario,
        cfg: ShaderConfig,
        grid: &Grid,
        b: &ParticleBuffers,
        defs: &[ProbeDef],
        motions: Vec<BodyMotion>,
        subdomain: Option<HaloCtl>,
    ) -> Result<Self> {
        let ph = &sc.physics;
        let shader = |s: &Shader| module(device, s, cfg);
        let has_kind = |k: &[Kind]| sc.particles.iter().any(|p| k.contains(&p.kind));
        let has_formulation = |f| sc.solids.as_ref().is_some_and(|s| s.has(f));
        let probe_module = shader(&probes::SHADER)?;
        let halo = subdomain
            .map(|ctl| {
                let layers = grid.cells[ctl.axis as usize];
                let records = halo::records_per_particle(sc);
                let module = shader(&halo::SHADER)?;
                Halo::new(device, &module, b, ctl, layers, records, cfg.ids.wide)
            })
            .transpose()?;
        let policy = sc.time.overlap_exchange;
        let overlapped = halo.as_ref().filter(|_| policy != OverlapExchange::Never);
        Ok(Self {
            cell_list: CellList::new(
                device,
                &shader(&cell_list::SHADER)?,
                &shader(&cell_list::SCAN_SHADER)?,
                b,
                ph.energy,
            )?,
            interaction: Interaction::new(
                device,
                &shader(&interaction::SHADER)?,
                b,
                overlapped.map(Halo::slab),
            )?,
            overlap: overlapped
                .map(|_| Overlap::new(device, &shader(&overlap::SHADER)?, b, policy))
                .transpose()?,
            ghost: Ghost::new(
                device,
                &shader(&ghost::SHADER)?,
                b,
                has_kind(&[Kind::GhostNoSlip, Kind::GhostFreeSlip]),
                has_kind(&[Kind::Fluid]) && has_kind(&[Kind::Solid, Kind::SolidClamped]),
            )?,
            density_filter: match ph.density_filter {
                crate::scenario::DensityFilter::None => None,
                mode => DensityFilter::new(device, &shader(&density_filter::SHADER)?, b, mode)?,
            },
            integrate: Integrate::new(device, &shader(&integrate::SHADER)?, b)?,
            elastic: has_formulation(SolidFormulation::UpdatedLagrangian)
                .then(|| Elastic::new(device, &shader(&elastic::SHADER)?, b))
                .transpose()?,
            total_lagrangian: has_formulation(SolidFormulation::TotalLagrangian)
                .then(|| TotalLagrangian::new(device, &shader(&total_lagrangian::SHADER)?, b, sc))
                .transpose()?,
            open_boundaries: (!sc.inlets.is_empty() || !sc.outlets.is_empty())
                .then(|| {
                    OpenBoundaries::new(device, &shader(&open_boundaries::SHADER)?, b, sc, grid)
                })
                .transpose()?,
            bodies: (!sc.bodies.is_empty())
                .then(|| {
                    Bodies::new(
                        device,
                        &shader(&bodies::SHADER)?,
                        b,
                        motions,
                        subdomain.is_some(),
                    )
                })
                .transpose()?,
            probes: Probes::new(
                device,
                &probe_module,
                b,
                &sc.probes,
                defs,
                ph.particle_mass,
                (crate::probe_reach::unmeasurable(sc).iter())
                    .map(Option::is_some)
                    .collect(),
            )?,
            points: PointTracker::new(device, &probe_module, b, &sc.points)?,
            flood_maps: (sc.maps.as_ref())
                .map(|m| {
                    FloodMapPass::new(device, &shader(&flood_maps::SHADER)?, b, m, grid.origin)
                })
                .transpose()?,
            halo,
        })
    }

    /// GPU memory of the passes' own buffers, in bytes.
    pub fn bytes(&self) -> u64 {
        self.total_lagrangian.as_ref().map_or(0, |t| t.bytes())
            + self.elastic.as_ref().map_or(0, |e| e.bytes())
            + self.halo.as_ref().map_or(0, |h| h.bytes())
            + self.overlap.as_ref().map_or(0, |o| o.bytes())
            + self.flood_maps.as_ref().map_or(0, |m| m.bytes())
    }

    /// The stages of one step on the arrays of parity `p`, in order (the sort moves them to
    /// parity `1 - p`, where the rest of the step works). A subdomain swaps its halo and
    /// migrants with its neighbours between the two halves.
    pub(super) fn record_step(&self, mut r: Recorder<'_>, p: usize) {
        self.record_to_exchange(&mut r, p);
        self.record_from_exchange(&mut r, p, false);
    }

    /// The step up to the exchange: the predictors, and a subdomain's packing.
    pub(super) fn record_to_exchange(&self, r: &mut Recorder<'_>, p: usize) {
        r.stage("predict", |pass| self.integrate.encode_predict(pass, p));
        if let Some(e) = &self.elastic {
            r.stage("elastic_predict", |pass| e.encode_predict(pass, p));
        }
        if let Some(b) = &self.bodies {
            r.stage("body_move", |pass| b.encode_move(pass, p));
        }
        if let Some(o) = &self.open_boundaries {
            r.stage("open_boundaries", |pass| o.encode(pass, p));
        }
        if let Some(h) = &self.halo {
            // The predicted positions of the TL particles this rank holds, which the ranks
            // share before the sums (`Solver::share_tl_positions`).
            if let Some(t) = &self.total_lagrangian {
                r.stage("total_lagrangian_index", |pass| t.encode_index(pass, p));
            }
            r.stage("halo_pack", |pass| h.encode_pack(pass, p));
        }
    }

    /// An overlapped subdomain's step before what the exchange brings arrives (the host
    /// swaps it meanwhile): the arrays of parity `p` sorted, and the sums of the particles
    /// that need nothing from it; the rest of the step starts again from the other parity
    /// (`record_from_exchange(r, 1 - p, true)`), whose sort takes the arrivals in.
    pub(super) fn record_before_arrival(&self, r: &mut Recorder<'_>, p: usize) {
        let q = 1 - p;
        self.record_sort(r, p, None);
        // The fixed ghosts' and solids' values and the inlet buffers' pressure, which those sums
        // read (again after the second sort).
        r.stage("ghost", |pass| self.ghost.encode(pass, q));
        if let Some(o) = &self.open_boundaries {
            r.stage("inlet_pressure", |pass| o.encode_pressure(pass, q));
        }
        let halo = self.halo();
        r.stage("halo_tail", |pass| halo.encode_tail(pass, q));
    }

    /// The sums of [`Passes::record_before_arrival`]'s particles, on its sorted arrays.
    pub(super) fn record_interior(&self, r: &mut Recorder<'_>, q: usize) {
        r.stage("interaction_interior", |pass| {
            self.interaction.encode_interior(pass, q)
        });
    }

    /// The sort of the arrays of parity `p` into the other; with `rates`, carrying this
    /// step's rates the interior's sums wrote beside the last ones.
    fn record_sort(&self, r: &mut Recorder<'_>, p: usize, rates: Option<&Overlap>) {
        let cells = &self.cell_list;
        r.stage("sort_key", |pass| cells.encode_key(pass, p));
        r.stage("sort_scan", |pass| cells.encode_scan(pass));
        r.stage("sort_scatter", |pass| cells.encode_scatter(pass, p));
        if let Some(o) = rates {
            r.stage("hold_old_rates", |pass| o.encode_hold(pass));
        }
        r.stage("sort_reorder", |pass| cells.encode_reorder(pass, p));
        if let Some(o) = rates {
            r.stage("settle_rates", |pass| o.encode_settle(pass));
        }
    }

    /// The step from the exchange on: a subdomain's arrivals, the sort, the sums and the
    /// correctors. An `overlapped` subdomain's sort carries the interior's rates, and its sums
    /// are the rest's.
    pub(super) fn record_from_exchange(&self, r: &mut Recorder<'_>, p: usize, overlapped: bool) {
        let q = 1 - p;
        let bodies = self.bodies.as_ref();
        let overlap = self.overlap.as_ref().filter(|_| overlapped);
        // A subdomain's arrivals, after its free tail (`Solver::place_arrivals`).
        if let Some(h) = &self.halo {
            r.stage("halo_unpack", |pass| h.encode_unpack(pass, p, overlapped));
        }
        self.record_sort(r, p, overlap);
        if let Some(t) = &self.total_lagrangian {
            r.stage("total_lagrangian_index", |pass| t.encode_index(pass, q));
        }
        if let Some(b) = bodies {
            r.stage("body_index", |pass| b.encode_index(pass, q));
        }
        r.stage("ghost", |pass| self.ghost.encode(pass, q));
        if let Some(o) = &self.open_boundaries {
            r.stage("inlet_pressure", |pass| o.encode_pressure(pass, q));
        }
        match overlap {
            Some(_) => r.stage("interaction_boundary", |pass| {
                self.interaction.encode_boundary(pass, q)
            }),
            None => r.stage("interaction", |pass| self.interaction.encode(pass, q)),
        }
        if let Some(e) = &self.elastic {
            r.stage("elastic_rates", |pass| e.encode_rates(pass, q));
            r.stage("elastic_correct", |pass| e.encode_correct(pass, q));
        }
        if let Some(t) = &self.total_lagrangian {
            r.stage("total_lagrangian_rates", |pass| t.encode_rates(pass, q));
        }
        // A subdomain drops its halo copies first: a body's load is its own particles'.
        if let Some(h) = &self.halo {
            r.stage("halo_drop", |pass| h.encode_drop(pass, q));
        }
        if let Some(b) = bodies {
            r.stage("body_force", |pass| b.encode_force(pass, q));
        }
        r.stage("correct", |pass| self.integrate.encode_correct(pass, q));
        // A subdomain filters after a second exchange (`Solver::filter_over_ranks`).
        if let (Some(f), None) = (&self.density_filter, &self.halo) {
            r.stage("density_filter", |pass| f.encode(pass, q));
        }
    }
}
