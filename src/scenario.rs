//! The built, validated description of a run: what the solver consumes.
//!
//! A case file (`cases/*.toml`, parsed in [`crate::case`]) is turned into a [`Scenario`]; the
//! solver never sees TOML. All quantities are SI. Coordinates are always 3-component: in 2D the
//! third component is zero, `y` is up in 2D and `z` is up in 3D (the "vertical axis" is
//! `dimension - 1`).

use crate::hydrograph::Hydrograph;

/// The edge of the neighbour grid's cells (`[particles] cell` of a case).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellEdge {
    /// The kernel support 2h: a particle's neighbours are in the 3^d cells around its own.
    Support,
    /// h: the 5^d cells around, whose union hugs the support's sphere closer. A particle tests
    /// the particles of 125 h³ for a sphere of 33.5 h³ in 3D, against 216 h³ with cells of 2h
    /// (25 h² against 36 h² for a disc of 12.6 h² in 2D).
    Half,
}

impl CellEdge {
    /// The name a case file gives it.
    pub fn name(self) -> &'static str {
        match self {
            CellEdge::Support => "2h",
            CellEdge::Half => "h",
        }
    }
}

/// What a particle is. Stored in the top bits of the GPU `code` word (see `shaders/lib/common.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Kind {
    Fluid = 0,
    /// Fixed wall particle, dynamic boundary condition (Crespo et al. 2007).
    Wall = 1,
    /// Fixed ghost particle (the seed's improved interface), no-slip: pressure and velocity
    /// interpolated from the fluid every step, v_g = 2 v_wall − Σ v_j W^I_gj V_j.
    GhostNoSlip = 2,
    /// Fixed ghost particle, free-slip: the interpolated fluid velocity itself in the viscous
    /// terms (the wall's own in continuity).
    GhostFreeSlip = 3,
    /// Repulsive-force boundary particle (Monaghan 1994, Lennard-Jones form).
    Repulsive = 4,
    /// Hypoelastic solid particle (Gray, Monaghan & Swift 2001): moves with its stress.
    Solid = 5,
    /// Clamped solid particle: part of its body's stress sums, but held fixed in place.
    SolidClamped = 6,
    /// Particle of an inlet's buffer (`[[inlet]]`): moves at the inflow velocity with the
    /// reference density and becomes fluid where it crosses the inlet plane.
    Inlet = 7,
}

impl Kind {
    /// Every kind, in code order.
    pub const ALL: [Kind; 8] = [
        Kind::Fluid,
        Kind::Wall,
        Kind::GhostNoSlip,
        Kind::GhostFreeSlip,
        Kind::Repulsive,
        Kind::Solid,
        Kind::SolidClamped,
        Kind::Inlet,
    ];

    pub fn is_fluid(self) -> bool {
        self == Kind::Fluid
    }

    pub fn is_solid(self) -> bool {
        matches!(self, Kind::Solid | Kind::SolidClamped)
    }

    /// A boundary particle of a wall, obstacle or body (of any wall treatment).
    pub fn is_boundary(self) -> bool {
        !self.is_fluid() && !self.is_solid() && self != Kind::Inlet
    }

    /// Whether a code word's kind field is an elastic solid's (free or clamped).
    pub fn code_is_solid(kind: u32) -> bool {
        Kind::from_code(kind).is_some_and(Kind::is_solid)
    }

    /// The kind of a code word's kind field (None: excluded, or not a kind).
    pub fn from_code(kind: u32) -> Option<Kind> {
        Kind::ALL.into_iter().find(|k| *k as u32 == kind)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle {
    pub pos: [f64; 3],
    pub vel: [f64; 3],
    pub rho: f64,
    pub kind: Kind,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelKind {
    /// Monaghan & Lattanzio (1985) cubic B-spline, support 2h.
    CubicSpline,
    /// Wendland (1995) C2, support 2h.
    WendlandC2,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Viscosity {
    /// Monaghan (1992) artificial viscosity with coefficient alpha.
    Artificial { alpha: f64 },
    /// Laminar viscosity (Morris et al. 1997, in the form of Lo & Shao 2002), kinematic nu [m²/s].
    Laminar { nu: f64 },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Physics {
    /// 2 or 3.
    pub dim: u32,
    /// Initial particle spacing [m].
    pub dx: f64,
    /// Smoothing length [m]; kernel support is 2h.
    pub h: f64,
    pub kernel: KernelKind,
    /// The neighbour grid's cell edge; by default h where the grid allows (`Grid::new`).
    pub cell: Option<CellEdge>,
    /// `particles.id_low_bits`: wide particle ids forced, with this many bits of an id in its
    /// code word (`layout::IdSplit`); None: wide only where the run needs them.
    pub id_low_bits: Option<u32>,
    /// Reference density [kg/m³].
    pub rho0: f64,
    /// Numerical speed of sound [m/s].
    pub c0: f64,
    /// Tait exponent (7 for water).
    pub gamma: f64,
    /// Gravity [m/s²], 3 components (z = 0 in 2D).
    pub gravity: [f64; 3],
    pub viscosity: Viscosity,
    /// δ-SPH density diffusion coefficient (Molteni & Colagrossi 2009); 0 disables it.
    pub delta_sph: f64,
    /// What δ-SPH diffuses.
    pub delta_sph_form: DeltaSphForm,
    /// Mass of every particle [kg] (ρ0·dx^dim).
    pub particle_mass: f64,
    /// Periodic density re-initialisation of the fluid (Shepard or MLS filter).
    pub density_filter: DensityFilter,
    /// Integrate the specific internal energy (the seed's energy equation); off by default.
    pub energy: bool,
}

/// The density difference that δ-SPH diffuses between two fluid particles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DeltaSphForm {
    /// The whole ρ_j − ρ_i (Molteni & Colagrossi 2009): the fluid next to a floor loses density
    /// to the lighter fluid above it, and a tank at rest sinks steadily (docs/validation.md,
    /// "δ-SPH and water at rest").
    MolteniColagrossi,
    /// ρ_j − ρ_i less its hydrostatic part ρ0((1 + ρ0 g·x_ji/B)^(1/γ) − 1) (Fourtakas et al.
    /// 2019): a fluid at rest stays at rest. The default (issue 36): a still 3D tank's bottom
    /// pressure holds within 1 % where the whole difference drains it by 9–12 % in 2 s.
    #[default]
    Fourtakas,
}

/// Density re-initialisation every `every` steps (Colagrossi & Landrini 2003): the fluid
/// densities are replaced by a kernel interpolation of the densities around each particle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DensityFilter {
    #[default]
    None,
    /// Zeroth order: ρ_i = Σ_j m_j W_ij / Σ_j W_ij m_j/ρ_j.
    Shepard { every: u32 },
    /// First-order moving least squares: ρ_i = Σ_j m_j W^MLS_ij (Shepard where ill-conditioned).
    Mls { every: u32 },
}

impl Physics {
    /// Tait stiffness B = c0² ρ0 / γ [Pa].
    pub fn tait_b(&self) -> f64 {
        self.c0 * self.c0 * self.rho0 / self.gamma
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct TimeControl {
    pub end_s: f64,
    /// Interval between particle outputs (VTU) [s].
    pub output_every_s: f64,
    /// Interval between probe samples [s].
    pub probe_every_s: f64,
    /// Courant number for the time step.
    pub cfl: f64,
    /// Which particle outputs hold the boundary particles that have not moved.
    pub output_boundary: OutputBoundary,
    /// Whether a run over ranks overlaps the exchange with the sums that need nothing from
    /// it (`sph::overlap`); the results are the same.
    pub overlap_exchange: OverlapExchange,
    /// The run warns when the fluid's density varies from ρ0 by more than this fraction (the
    /// weakly-compressible limit), and keeps only outputs within it when it stops unstable.
    pub density_variation_warn: f64,
    /// The run stops when the fluid's density varies from ρ0 by more than this fraction.
    pub density_variation_stop: f64,
}

impl TimeControl {
    /// `time.density_variation_warn`'s default: ±3 %, WCSPH's usual bound on |ρ/ρ0 − 1| (the
    /// sound speed is chosen ≥ 10 times the largest flow speed so that it holds, Monaghan 1994).
    pub const DENSITY_VARIATION_WARN: f64 = 0.03;
    /// `time.density_variation_stop`'s default (or twice `density_variation_warn` when that is
    /// above 5 %).
    pub const DENSITY_VARIATION_STOP: f64 = 0.1;
}

/// Whether a subdomain's steps overlap the exchange with its interior's sums
/// (`time.overlap_exchange`, docs/scaling.md "Overlapping the exchange").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OverlapExchange {
    /// Each rank times its steps both ways now and then and takes the faster
    /// (`sph::overlap::Choice`).
    #[default]
    Auto,
    Always,
    Never,
}

/// Which particle outputs hold the boundary particles still where they started (fixed walls,
/// obstacles and bodies; a moving tank's or body's particles are in every output anyway).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OutputBoundary {
    /// Every output holds every particle.
    #[default]
    Every,
    /// Only the first output (`particles_000000.vtu`) holds them: the later files are about
    /// the fluid's size in a 3D case of many walls. Their density and pressure are then only
    /// in the first file; `wgsph plot --snapshots` takes them from it.
    First,
}

/// Axis-aligned box; particles leaving it are excluded from the run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Domain {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

/// Where a gauge finds the water's surface (`ProbeKind::Height`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GaugeSurface {
    /// Where the fluid fills half the kernel, Σ W V = ½: a wave gauge (`kind = "height"`).
    FluidHalf,
    /// Where the water fills half of what the walls leave of the kernel, ψ = ½ (docs/equations.md
    /// eq. 34, the flood maps' criterion): a depth gauge (`kind = "depth"`), which reads a sheet
    /// one particle deep and the surface beside a wall.
    WaterFraction,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ProbeKind {
    /// Pressure at a point, kernel-interpolated (Shepard-normalised) from fluid particles.
    Pressure { point: [f64; 3] },
    /// Water height along the vertical line through `base`, measured from `base`'s vertical
    /// coordinate: the highest point where `surface` reaches ½.
    Height {
        base: [f64; 3],
        surface: GaugeSurface,
    },
    /// Surge front: largest (x − origin)·axis over fluid particles, or with `continuous` over
    /// the water that reaches along the axis from the origin without a gap: fluid projected
    /// onto the axis in bins of the kernel support 2h, the front ends at the first empty bin
    /// past the first wet one, so a droplet more than 2h–4h ahead of the tongue does not count.
    Front {
        origin: [f64; 3],
        axis: [f64; 3],
        continuous: bool,
    },
    /// Pressure on a patch of wall, as a transducer reads it: the fluid's force on the wall's
    /// boundary particles whose columns lie within `radius` of `point` (measured across
    /// `normal`, from 3h behind the face to h in front of it), along −`normal`, divided by the
    /// columns' area.
    /// Needs [`WallParams::reactions`], which gives fixed boundary particles that force.
    WallPressure(WallPatch),
    /// The fluid's discharge through a section (m³/s; 2D m²/s per metre of width): in 2D the
    /// segment from `from` to `to`, in 3D the vertical plane through their line in plan,
    /// bounded by the two points along it and by nothing vertically. Positive towards the
    /// right of `from` → `to` (the side of [`ProbeKind::section_normal`]). Σ_j V_j (u_j·n)
    /// w(d_j) over the fluid, w the kernel's 1D form of the distance d_j to the section
    /// (docs/equations.md eq. 33).
    Discharge { from: [f64; 3], to: [f64; 3] },
}

impl ProbeKind {
    /// A discharge section's unit normal n (horizontal in 3D: the plan tangent t = (tx, ty)
    /// turned clockwise, n = (ty, −tx)) and its length along t.
    pub fn section_normal(from: [f64; 3], to: [f64; 3]) -> ([f64; 3], f64) {
        let (tx, ty) = (to[0] - from[0], to[1] - from[1]);
        let length = (tx * tx + ty * ty).sqrt();
        ([ty / length, -tx / length, 0.0], length)
    }
}

/// The boundary particles a wall-pressure probe sums over ([`WallPatch::resolve`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallPatch {
    /// A point on the wall's face.
    pub point: [f64; 3],
    /// Unit normal of the face, into the fluid.
    pub normal: [f64; 3],
    /// Radius across the normal within which a column's centre is taken; set halfway between
    /// the farthest column taken and the nearest column left out, so that f32 positions on the
    /// GPU select the same particles.
    pub radius: f64,
    /// Area of the columns taken [m² in 3D, m in 2D]: their number times dx^(dim − 1).
    pub area: f64,
    /// (x − point)·normal of the wall's face, half a spacing in front of the columns' first
    /// layer of particles. On a fixed wall the patch's particles take the force only of the
    /// fluid in front of it ([`WallParams::sensors`]): at a convex edge the fluid beside the
    /// other face does not load the sensor.
    pub face: f64,
    /// The face's extent around the sensor along the lattice axes across an axis-aligned
    /// normal, where an edge lies within 2h + `radius` of it (±[`FACE_UNBOUNDED`] otherwise,
    /// and along the normal): only fluid over the face, within [`Self::over_lo`,
    /// `Self::over_hi`], loads the patch, not the water beyond the edge.
    pub over_lo: [f64; 3],
    pub over_hi: [f64; 3],
}

/// A face's extent where no edge limits it (finite, so that f32 comparisons stay ordinary).
pub const FACE_UNBOUNDED: f64 = 1e30;

/// A tracked material point (`[[probe]] kind = "point"`): the particle of an elastic solid or
/// a rigid body nearest to the given point at t = 0. Its position and displacement are written
/// to `probes/point_<name>.csv`.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackedPoint {
    pub name: String,
    /// The particle followed: an index into `Scenario::particles` (its stable id).
    pub particle: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    pub name: String,
    pub kind: ProbeKind,
    /// The body (index into `Scenario::bodies`) the probe moves with, e.g. a pressure
    /// transducer on a moving tank's wall; its coordinates are given at t = 0.
    pub body: Option<usize>,
}

/// How ghost particles interpolate pressure and velocity from the fluid (the kernel W^I).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GhostCorrection {
    /// W_gj / Σ_k W_gk V_k (zeroth order).
    Shepard,
    /// First-order moving least squares (falls back to Shepard where ill-conditioned).
    Mls,
}

/// A straight wall treated with mirrored ghosts: every fluid particle within 2h of the plane
/// has a mirror image x_g = 2 x_w − x_i with p_g = p_i, ρ_g = ρ_i.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MirrorPlane {
    /// A point of the plane.
    pub point: [f64; 3],
    /// Unit normal pointing into the fluid.
    pub normal: [f64; 3],
    /// No-slip: v_g = −v_i (wall at rest); free-slip: only the normal component reversed.
    pub no_slip: bool,
}

/// Parameters of the wall treatments other than dynamic boundary particles.
#[derive(Clone, Debug, PartialEq)]
pub struct WallParams {
    pub ghost_correction: GhostCorrection,
    /// Lennard-Jones strength D [m²/s²] of repulsive walls (Monaghan 1994: about 5 g H).
    pub repulsive_d: f64,
    /// Lennard-Jones cut-off r0 [m] (the initial particle spacing).
    pub repulsive_r0: f64,
    pub repulsive_form: RepulsiveForm,
    /// Monaghan & Kajtar strength K [m²/s²] (their static tank: g·D, D the water depth).
    pub repulsive_k: f64,
    /// Monaghan & Kajtar β: fluid spacing over boundary-particle spacing.
    pub repulsive_beta: f64,
    /// Coulomb friction coefficient μ of contact (bodies and solids against walls, bodies and
    /// solids); 0: frictionless.
    pub friction: f64,
    /// Regularisation speed ε [m/s] of the friction: the tangential force is
    /// μ|F_n| v_t/sqrt(|v_t|² + ε²).
    pub friction_slip: f64,
    /// Pairs in contact with a μ of their own (`[[friction]]`); every other pair has `friction`.
    pub friction_pairs: Vec<FrictionPair>,
    pub mirror_planes: Vec<MirrorPlane>,
    /// Whether the boundary particles of fixed walls also get the fluid's force on them (as
    /// moving bodies' always do): wall-pressure probes read it. Off otherwise: fixed ghosts and
    /// repulsive particles would pay a neighbour sum they otherwise skip (dynamic walls sum
    /// over their neighbours for dρ/dt anyway).
    pub reactions: bool,
    /// The patches of the wall-pressure probes on fixed walls (those without a body), in
    /// probe order. With `reactions`, a fixed wall's particle in one of them (its sensor,
    /// [`Self::sensor_of`]) takes the force only of the fluid that [`WallPatch::faces`] it, as
    /// a transducer feels only the water on its face: near a convex edge the particles under
    /// the sensor also carry the load of the water against the other face. Its dρ/dt still
    /// sums every fluid neighbour. Bodies' particles always take the whole force (it moves the
    /// body).
    pub sensors: Vec<WallPatch>,
}

/// What takes part in contact, for friction by pair: the fixed walls (tank, obstacles), a rigid
/// body or an elastic solid (by their index in `Scenario::bodies` and in the solids' bodies).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactGroup {
    Walls,
    Body(usize),
    Solid(usize),
}

/// A pair of contact groups with a Coulomb friction coefficient of its own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionPair {
    pub between: [ContactGroup; 2],
    pub coefficient: f64,
}

impl WallParams {
    /// The sensor (index into `sensors`) a fixed wall's boundary particle at `x` belongs to: of
    /// those whose patch holds it, the one whose face it lies least deep behind (the first of
    /// those within h/100 of that: f32 rounding on the GPU then agrees on ties). At an edge a
    /// particle near one face and deep behind the other counts for the first only
    /// (`sensor_faces`).
    pub fn sensor_of(&self, x: [f64; 3], h: f64) -> Option<usize> {
        let mut best: Option<(usize, f64)> = None;
        for (k, s) in self.sensors.iter().enumerate() {
            let depth = s.depth_behind_face(x);
            if s.holds(x, h) && best.is_none_or(|(_, d)| depth < d - 0.01 * h) {
                best = Some((k, depth));
            }
        }
        best.map(|(k, _)| k)
    }

    /// Each sensor's face: the index of the first sensor on the same face. A sensor sums only
    /// the particles that belong to a sensor of its own face ([`Self::sensor_of`]).
    pub fn sensor_faces(&self) -> Vec<u32> {
        (0..self.sensors.len())
            .map(|k| {
                (0..=k)
                    .find(|&j| self.sensors[j].same_face(&self.sensors[k]))
                    .unwrap_or(k) as u32
            })
            .collect()
    }

    /// The Coulomb μ between two contact groups: their pair's, in either order, else the
    /// walls' `friction`.
    pub fn friction_between(&self, a: ContactGroup, b: ContactGroup) -> f64 {
        self.friction_pairs
            .iter()
            .find(|p| p.between == [a, b] || p.between == [b, a])
            .map_or(self.friction, |p| p.coefficient)
    }
}

/// The default regularisation speed of contact friction [m/s].
pub const DEFAULT_FRICTION_SLIP: f64 = 1e-3;

/// The force law of repulsive boundary particles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RepulsiveForm {
    /// Monaghan (1994): D((r0/r)^12 − (r0/r)^4) x/r² for r < r0.
    LennardJones,
    /// Monaghan & Kajtar (2009): (K/β) x/r² Φ(r/h) 2m_b/(m_a+m_b), Φ the Wendland C4 shape
    /// with Φ(0) = 1.77; smooth along the wall.
    MonaghanKajtar,
}

impl WallPatch {
    /// The extent of the patch along its normal, from the face: boundary particles up to 3h
    /// behind it (every one the fluid reaches, 2h from the nearest fluid, whatever the wall's
    /// spacing) and h in front of it (a face given half a spacing off).
    pub fn depth(h: f64) -> (f64, f64) {
        (-3.0 * h, h)
    }

    /// Whether a boundary particle at `x` belongs to the patch: (x − point)·normal within
    /// [`Self::depth`] and closer than `radius` to the normal line (`in_wall_patch` in
    /// shaders/lib/wall_patch.wgsl).
    pub fn holds(&self, x: [f64; 3], h: f64) -> bool {
        let (behind, front) = Self::depth(h);
        let (d, t2) = Self::coordinates(self.point, self.normal, x);
        d >= behind && d <= front && t2 < self.radius * self.radius
    }

    /// How deep `x` lies behind the face, `face` − (x − point)·normal.
    pub fn depth_behind_face(&self, x: [f64; 3]) -> f64 {
        self.face - Self::coordinates(self.point, self.normal, x).0
    }

    /// Whether `other` lies on the same face (the same plane, to 1e-9 m).
    pub fn same_face(&self, other: &WallPatch) -> bool {
        let n_dot = (0..3)
            .map(|a| self.normal[a] * other.normal[a])
            .sum::<f64>();
        n_dot > 1.0 - 1e-9 && (self.depth_behind_face(other.point) + other.face).abs() < 1e-9
    }

    /// Whether fluid at `x` loads the patch's particles: it lies in front of the wall's face,
    /// (x − point)·normal > `face`, and over it (within `over_lo`, `over_hi`).
    pub fn faces(&self, x: [f64; 3]) -> bool {
        Self::coordinates(self.point, self.normal, x).0 > self.face
            && (0..3).all(|a| x[a] >= self.over_lo[a] && x[a] <= self.over_hi[a])
    }

    /// The extent of the face whose first layer of boundary particles lies at
    /// (x − point)·normal = `layer`, from the particle of that layer nearest to `point`, along
    /// each lattice axis across an axis-aligned `normal`: a march of dx steps through that
    /// layer, up to `reach` m; the edge is half a spacing beyond the last particle. Unbounded
    /// where the march reaches `reach`, and everywhere for a normal off the lattice axes.
    fn face_extent(
        particles: &[Particle],
        point: [f64; 3],
        normal: [f64; 3],
        layer: f64,
        dim: usize,
        dx: f64,
        reach: f64,
    ) -> ([f64; 3], [f64; 3]) {
        let mut lo = [-FACE_UNBOUNDED; 3];
        let mut hi = [FACE_UNBOUNDED; 3];
        let Some(axis) = (0..dim).find(|&a| (normal[a].abs() - 1.0).abs() < 1e-9) else {
            return (lo, hi);
        };
        let window = reach + 2.0 * dx;
        let first: Vec<[f64; 3]> = particles
            .iter()
            .filter(|p| p.kind.is_boundary())
            .filter(|p| {
                let (d, t2) = Self::coordinates(point, normal, p.pos);
                (d - layer).abs() < 0.25 * dx && t2 < window * window
            })
            .map(|p| p.pos)
            .collect();
        let across = |q: &[f64; 3]| Self::coordinates(point, normal, *q).1;
        let Some(start) = first
            .iter()
            .min_by(|a, b| across(a).total_cmp(&across(b)))
            .copied()
        else {
            return (lo, hi);
        };
        let steps = (reach / dx).ceil() as usize;
        for a in (0..dim).filter(|&a| a != axis) {
            for sign in [-1.0, 1.0] {
                let at = |k: usize| {
                    let mut x = start;
                    x[a] += sign * k as f64 * dx;
                    x
                };
                let held = |x: [f64; 3]| {
                    first
                        .iter()
                        .any(|q| (0..dim).all(|b| (q[b] - x[b]).abs() < 0.25 * dx))
                };
                let Some(last) = (1..=steps).find(|&k| !held(at(k))).map(|k| k - 1) else {
                    continue;
                };
                let edge = start[a] + sign * (last as f64 + 0.5) * dx;
                if sign < 0.0 {
                    lo[a] = edge;
                } else {
                    hi[a] = edge;
                }
            }
        }
        (lo, hi)
    }

    /// The normal coordinate d = (x − point)·normal of `x` and its squared distance from the
    /// normal line through `point`.
    pub fn coordinates(point: [f64; 3], normal: [f64; 3], x: [f64; 3]) -> (f64, f64) {
        let r: [f64; 3] = [0, 1, 2].map(|a| x[a] - point[a]);
        let d = (0..3).map(|a| r[a] * normal[a]).sum::<f64>();
        let r2 = (0..3).map(|a| r[a] * r[a]).sum::<f64>();
        (d, (r2 - d * d).max(0.0))
    }

    /// The patch of the boundary particles among `particles` that lie within `radius` of
    /// `point` across the unit `normal` (from 3h behind the face to h in front of it; a column
    /// on the circle is left out); a sensor narrower than the spacing takes the nearest column
    /// (all of them, between several). Its radius is moved halfway to the next column left
    /// out, and its area is the number of distinct columns (tangential positions to dx/4) times
    /// dx^(dim − 1). `None` when no boundary particle lies within max(radius, dx) of `point`
    /// across the normal, or the nearest lie more than dx behind it, or every column of them
    /// runs on along the normal past the slab (`point` is not on a face with this normal).
    pub fn resolve(
        particles: &[Particle],
        point: [f64; 3],
        normal: [f64; 3],
        radius: f64,
        dim: usize,
        dx: f64,
        h: f64,
    ) -> Option<WallPatch> {
        let (behind, front) = Self::depth(h);
        // Every boundary particle in the slab.
        struct Candidate {
            /// Distance across the normal.
            across: f64,
            /// Tangential position in quarters of dx.
            column: [i64; 3],
            /// (x − point)·normal.
            d: f64,
            pos: [f64; 3],
        }
        let candidates: Vec<Candidate> = particles
            .iter()
            .filter(|p| p.kind.is_boundary())
            .filter_map(|p| {
                let (d, t2) = Self::coordinates(point, normal, p.pos);
                let column = [0, 1, 2]
                    .map(|a| ((p.pos[a] - point[a] - d * normal[a]) / (0.25 * dx)).round() as i64);
                (d >= behind && d <= front).then_some(Candidate {
                    across: t2.sqrt(),
                    column,
                    d,
                    pos: p.pos,
                })
            })
            .collect();
        // A column within a millionth of dx of the circle is on it, and left out: f32 positions
        // on the GPU could not tell which side it is on.
        let tol = 1e-6 * dx;
        let nearest = candidates
            .iter()
            .map(|c| c.across)
            .fold(f64::INFINITY, f64::min);
        if nearest > radius.max(dx) + tol {
            return None;
        }
        // Within the radius, or as near as the nearest.
        let reach = if nearest < radius - tol {
            radius - tol
        } else {
            nearest + tol
        };
        let (taken, left_out): (Vec<&Candidate>, Vec<&Candidate>) =
            candidates.iter().partition(|c| c.across < reach);
        // The face must be within a spacing of the wall's first layer.
        if taken.iter().map(|c| c.d).fold(f64::NEG_INFINITY, f64::max) < -dx - tol {
            return None;
        }
        let farthest_taken = taken.iter().map(|c| c.across).fold(0.0, f64::max);
        let nearest_left_out = left_out
            .iter()
            .map(|c| c.across)
            .fold(f64::INFINITY, f64::min);
        // Each column's outermost particle, the first one the fluid meets.
        let mut tops: Vec<([i64; 3], f64)> = Vec::new();
        for c in &taken {
            match tops.iter_mut().find(|(column, _)| *column == c.column) {
                Some((_, top)) => *top = top.max(c.d),
                None => tops.push((c.column, c.d)),
            }
        }
        // The wall's first layer is the lowest of them: a column that runs into a concave
        // corner also holds the other wall's particles, in front of this wall's face.
        let first_layer = tops.iter().map(|t| t.1).fold(f64::INFINITY, f64::min);
        // No face across the normal where every column runs on, a boundary particle a spacing
        // in front of its outermost one in the slab: a wall along the normal (a sensor on a
        // building left out of the case finds the street's floor), not a face.
        let runs_on = |top: &Candidate| {
            let next: [f64; 3] = std::array::from_fn(|a| top.pos[a] + dx * normal[a]);
            (particles.iter().filter(|p| p.kind.is_boundary()))
                .any(|p| (0..3).all(|a| (p.pos[a] - next[a]).abs() < 0.25 * dx))
        };
        let mut outermost = tops.iter().filter_map(|(column, top)| {
            (taken.iter()).find(|c| c.column == *column && c.d == *top)
        });
        if outermost.all(|c| runs_on(c)) {
            return None;
        }
        let (over_lo, over_hi) = Self::face_extent(
            particles,
            point,
            normal,
            first_layer,
            dim,
            dx,
            2.0 * h + radius,
        );
        Some(WallPatch {
            point,
            normal,
            radius: if nearest_left_out.is_finite() {
                0.5 * (farthest_taken + nearest_left_out)
            } else {
                reach
            },
            area: tops.len() as f64 * dx.powi(dim as i32 - 1),
            face: first_layer + 0.5 * dx,
            over_lo,
            over_hi,
        })
    }
}

impl WallParams {
    /// Defaults for a case of spacing `dx` and highest water column `height` [m].
    pub fn defaults(dx: f64, height: f64, gravity: f64) -> Self {
        Self {
            ghost_correction: GhostCorrection::Mls,
            repulsive_d: 5.0 * gravity * height,
            repulsive_r0: dx,
            repulsive_form: RepulsiveForm::LennardJones,
            repulsive_k: gravity * height,
            repulsive_beta: 1.0,
            friction: 0.0,
            friction_slip: DEFAULT_FRICTION_SLIP,
            friction_pairs: Vec::new(),
            mirror_planes: Vec::new(),
            reactions: false,
            sensors: Vec::new(),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    pub name: String,
    pub physics: Physics,
    pub time: TimeControl,
    pub domain: Domain,
    pub particles: Vec<Particle>,
    pub probes: Vec<Probe>,
    /// Tracked points of bodies and solids (`[[probe]] kind = "point"`).
    pub points: Vec<TrackedPoint>,
    pub walls: WallParams,
    /// Periodic axes: a particle leaving the domain through one face re-enters through the
    /// opposite one, and neighbours are found across it (minimum image).
    pub periodic: [bool; 3],
    /// Moving solids (rigid bodies, moving tanks). Their particles come last in `particles`,
    /// body after body.
    pub bodies: Vec<Body>,
    /// Elastic bodies, when the case has solid particles.
    pub solids: Option<Solids>,
    /// Velocity inlets. Their particles come right after the fluid blocks', inlet after inlet.
    pub inlets: Vec<Inlet>,
    /// Outlets: boxes that remove the fluid entering them.
    pub outlets: Vec<Outlet>,
    /// Doubts about the case found while building it, each naming the part, the concern and a
    /// fix. The run goes on: `wgsph run` logs them and `DIR/run.json` lists them.
    pub warnings: Vec<String>,
    /// The world coordinates of the scenario's (0, 0, 0): `terrain.origin_m` (a terrain's
    /// positions are local, so that f32 keeps them to a fraction of dx), else zero. What the
    /// run writes is in the scenario's coordinates; `run.json` records this origin.
    pub world_origin_m: [f64; 3],
    /// Flood maps over a plan grid (`[maps]`; 3D cases only).
    pub maps: Option<FloodMaps>,
}

/// Flood maps (`[maps]`, docs/cases.md "Flood maps"): a plan grid of square cells over which
/// the water's depth and depth-averaged velocity are sampled at every probe time, and their
/// extremes over the run kept (shaders/flood_maps.wgsl).
#[derive(Clone, Debug, PartialEq)]
pub struct FloodMaps {
    /// The centre of the south-west cell, in the scenario's coordinates.
    pub first_centre: [f64; 2],
    /// The cells' size [m].
    pub cell: f64,
    pub nx: usize,
    pub ny: usize,
    /// The depth a cell must reach for its time of arrival [m].
    pub wet_depth: f64,
    /// The ground under each cell's centre (the scenario's vertical coordinate), row by row
    /// from the south: what the depth is measured from.
    pub ground: Vec<f64>,
}

impl FloodMaps {
    pub fn cells(&self) -> usize {
        self.nx * self.ny
    }

    /// The centre of cell `c` (row by row from the south).
    pub fn centre(&self, c: usize) -> [f64; 2] {
        [
            self.first_centre[0] + (c % self.nx) as f64 * self.cell,
            self.first_centre[1] + (c / self.nx) as f64 * self.cell,
        ]
    }
}

/// An outlet (`[[outlet]]`, docs/cases.md "Outlets"): a box that removes every fluid particle
/// entering it (a sink, counted apart from particles that escape the domain).
#[derive(Clone, Debug, PartialEq)]
pub struct Outlet {
    pub name: String,
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Outlet {
    /// Whether `x` lies in the box (faces included; 2D: z is not tested).
    pub fn contains(&self, x: [f64; 3], dim: usize) -> bool {
        (0..dim).all(|a| self.min[a] <= x[a] && x[a] <= self.max[a])
    }
}

/// A velocity inlet (`[[inlet]]`, docs/cases.md "Inlets"): a buffer of particles on the
/// fluid's lattice, `thickness` deep behind a plane, marching along `normal` at the speed of
/// its `inflow` (constant or a hydrograph) with
/// the pressure `pressure` gives it. A buffer particle that crosses the plane becomes
/// fluid; behind the buffer wait as many further layers (dormant, in no cell) as the inflow
/// takes until its stop time, each joining the buffer when it reaches the buffer's back.
/// A particle's place is a function of time alone (`distance`), so no state is integrated and
/// a restart is exact.
#[derive(Clone, Debug, PartialEq)]
pub struct Inlet {
    pub name: String,
    /// Unit normal of the plane, the direction of the inflow.
    pub normal: [f64; 3],
    /// The inflow speed [m/s] in time (≥ 0).
    pub inflow: Hydrograph,
    /// Buffer depth L behind the plane [m]: a whole number of layers, at least the kernel
    /// support 2h.
    pub thickness: f64,
    /// Distance between layers [m] (the particle spacing).
    pub spacing: f64,
    /// Each column's point on the plane [m].
    pub columns: Vec<[f64; 3]>,
    /// Its particles, layer after layer (column order within a layer): `particles[range]` of
    /// the scenario (ids are indices).
    pub particles: std::ops::Range<usize>,
    /// The buffer's pressure.
    pub pressure: InletPressure,
    /// The water level that wets its columns, where one is given (`level_file`).
    pub level: Option<InletLevel>,
}

/// The water level on a level-driven inlet's plane (`level_file`): a column flows while the
/// level is above its point on the plane, as DualSPHysics' inlets with a variable surface
/// (Tafuni et al. 2018) wet only the buffer below it; a column above stands still and its
/// particles wait, out of every cell.
#[derive(Clone, Debug, PartialEq)]
pub struct InletLevel {
    /// The level [m], the height along `up` of the water's surface in time, joined linearly
    /// (a stage hydrograph; its "speed" is the height).
    pub level: Hydrograph,
    /// The unit vector against gravity, the direction heights are measured along.
    pub up: [f64; 3],
    /// When each column flows, ordered by column, then time.
    pub windows: Vec<FlowWindow>,
}

/// A time a column of a level-driven inlet flows, [start, end), and how far its water has
/// come: D_c(t) = `before` + D(t) within it, D the inflow's distance (eq. 32), and `after` from
/// its end to the column's next window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlowWindow {
    pub column: usize,
    pub start: f64,
    /// Infinite where the level never falls below the column again.
    pub end: f64,
    pub before: f64,
    pub after: f64,
}

impl FlowWindow {
    /// Whether a column whose windows are `windows` (in time order) flows at time `t`, and how
    /// far `inflow` has carried its water.
    pub fn travel(windows: &[FlowWindow], inflow: &Hydrograph, t: f64) -> Travel {
        let k = windows.partition_point(|w| w.start <= t);
        match k.checked_sub(1).map(|k| windows[k]) {
            Some(w) if t < w.end => Travel {
                flows: true,
                distance: w.before + inflow.distance(t),
            },
            Some(w) => Travel {
                flows: false,
                distance: w.after,
            },
            None => Travel {
                flows: false,
                distance: 0.0,
            },
        }
    }

    /// The windows of column `column` at height `z` under `level`: the times the level is
    /// above it, each with the distance `inflow` carries the column's water before it and by
    /// its end (an open window's `after` is infinite).
    pub fn of_column(
        column: usize,
        z: f64,
        level: &Hydrograph,
        inflow: &Hydrograph,
    ) -> Vec<FlowWindow> {
        let mut carried = 0.0;
        (level.intervals_above(z).into_iter())
            .map(|(start, end)| {
                let before = carried - inflow.distance(start);
                carried = match end.is_finite() {
                    true => before + inflow.distance(end),
                    false => f64::INFINITY,
                };
                FlowWindow {
                    column,
                    start,
                    end,
                    before,
                    after: carried,
                }
            })
            .collect()
    }
}

/// Whether a column flows at a time, and how far its water has come.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Travel {
    pub flows: bool,
    pub distance: f64,
}

/// The pressure (through the density) of an inlet's buffer particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InletPressure {
    /// Zero, ρ0: a free jet, a nozzle in air.
    Zero,
    /// The hydrostatic pressure ρ0 g·(x − surface) below `surface`, the buffer's highest point:
    /// an open channel's inflow.
    Hydrostatic { surface: [f64; 3] },
    /// Taken from the fluid each step: the pressure interpolated at the buffer particle's mirror
    /// image across the plane, carried back hydrostatically (zero where no fluid is in reach):
    /// an inflow that meets water piled above it or a submerged one.
    Extrapolated,
}

impl Inlet {
    /// Whether column `column` flows at time `t`, and how far the inflow has carried its water:
    /// D(t) for every column of an inlet without a level; with one, D_c(t) = ∫₀ᵗ u 1[level >
    /// the column's height], from the column's windows.
    pub fn travel(&self, column: usize, t: f64) -> Travel {
        let Some(level) = &self.level else {
            return Travel {
                flows: true,
                distance: self.inflow.distance(t),
            };
        };
        let w = &level.windows;
        let (from, to) = (
            w.partition_point(|w| w.column < column),
            w.partition_point(|w| w.column <= column),
        );
        FlowWindow::travel(&w[from..to], &self.inflow, t)
    }

    /// Signed distance from the plane along the normal at time `t` of the inlet's particle
    /// `k` (index within the inlet): −(layer + ½) spacing + D_c(t), D_c the distance the
    /// inflow has carried its column's water ([`Inlet::travel`]).
    pub fn distance(&self, k: usize, t: f64) -> f64 {
        let layer = (k / self.columns.len()) as f64;
        -(layer + 0.5) * self.spacing + self.travel(k % self.columns.len(), t).distance
    }

    /// The density the inlet pass gives a buffer particle at `x` at time `t`: the Tait density
    /// of the hydrostatic pressure below the surface (the level's, where it has one), or ρ0
    /// (which an extrapolated buffer's pressure then replaces, after the sort).
    pub fn density(&self, x: [f64; 3], t: f64, ph: &Physics) -> f64 {
        match self.pressure {
            InletPressure::Zero | InletPressure::Extrapolated => ph.rho0,
            InletPressure::Hydrostatic { surface } => {
                let s = self.surface(surface, t);
                let head: f64 = (0..3).map(|a| ph.gravity[a] * (x[a] - s[a])).sum();
                let p = ph.rho0 * head.max(0.0);
                ph.rho0 * (1.0 + p / ph.tait_b()).powf(1.0 / ph.gamma)
            }
        }
    }

    /// A point of the water's surface at time `t`: `top`, the buffer's highest point, or a
    /// point at the level's height.
    pub fn surface(&self, top: [f64; 3], t: f64) -> [f64; 3] {
        match &self.level {
            None => top,
            Some(l) => l.up.map(|c| c * l.level.speed(t)),
        }
    }

    /// Whether particle `k` waits at t = 0: behind the buffer, or in a column the level does
    /// not reach.
    pub fn dormant(&self, k: usize) -> bool {
        !self.travel(k % self.columns.len(), 0.0).flows || self.distance(k, 0.0) < -self.thickness
    }

    /// Particle `k`'s place at the signed distance `s` from the plane.
    pub fn position_at(&self, k: usize, s: f64) -> [f64; 3] {
        let c = self.columns[k % self.columns.len()];
        [0, 1, 2].map(|a| c[a] + s * self.normal[a])
    }
}

/// A linear hypoelastic material (Gray, Monaghan & Swift 2001, section 2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElasticMaterial {
    /// Reference density ρs [kg/m³].
    pub density: f64,
    /// Young's modulus E [Pa].
    pub youngs_modulus: f64,
    /// Poisson ratio ν (below 0.5).
    pub poisson_ratio: f64,
    /// Monaghan artificial viscosity α between solid particles (with the solid sound speed).
    pub alpha: f64,
    /// Artificial stress ε (Monaghan 2000; Gray, Monaghan & Swift 2001 use 0.3); 0 disables it.
    pub artificial_stress: f64,
    /// How the solid is discretised (`formulation` in `[[solid]]`).
    pub formulation: SolidFormulation,
}

/// The discretisation of the elastic solids.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SolidFormulation {
    /// Updated-Lagrangian hypoelastic SPH (Gray, Monaghan & Swift 2001; shaders/elastic.wgsl):
    /// density and Jaumann stress rates, artificial viscosity and stress.
    #[default]
    UpdatedLagrangian,
    /// Total-Lagrangian St Venant–Kirchhoff SPH on the reference lattice with a fixed
    /// neighbour list (shaders/total_lagrangian.wgsl): quadratic least-squares gradients and the
    /// cell quadrature term; no artificial viscosity or stress.
    TotalLagrangian,
}

impl ElasticMaterial {
    /// Shear modulus μ = E / (2(1 + ν)) [Pa].
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// Lamé's first parameter λ = E ν / ((1 + ν)(1 − 2ν)) [Pa] (the 3D material; plane strain
    /// in 2D).
    pub fn lame_lambda(&self) -> f64 {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    }

    /// Bulk modulus K = E / (3(1 − 2ν)) [Pa].
    pub fn bulk_modulus(&self) -> f64 {
        self.youngs_modulus / (3.0 * (1.0 - 2.0 * self.poisson_ratio))
    }

    /// Solid sound speed c_s = sqrt(K / ρs) [m/s]; the solid's pressure is p = c_s² (ρ − ρs).
    pub fn sound_speed(&self) -> f64 {
        (self.bulk_modulus() / self.density).sqrt()
    }

    /// P-wave speed c_p = sqrt((K + 4μ/3)/ρs) [m/s], the solid's fastest wave.
    pub fn p_wave_speed(&self) -> f64 {
        ((self.bulk_modulus() + 4.0 / 3.0 * self.shear_modulus()) / self.density).sqrt()
    }

    /// Mass of a particle of this material at spacing `dx` in `dim` dimensions [kg].
    pub fn particle_mass(&self, dx: f64, dim: u32) -> f64 {
        self.density * dx.powi(dim as i32)
    }
}

/// The solid particles of a case: several bodies (solid particles interact only within their
/// body), each of its own material and formulation (the total-Lagrangian solids' particles in
/// one run of ids: the case loader builds those solids first).
#[derive(Clone, Debug, PartialEq)]
pub struct Solids {
    /// The material of every elastic body, indexed by body (`[[solid]]` order).
    pub materials: Vec<ElasticMaterial>,
    /// Elastic body of every particle, indexed like `Scenario::particles` (read for solid
    /// kinds only).
    pub body: Vec<u32>,
    /// Initial deviatoric stress τ (xx, yy, zz, xy, xz, yz) of every particle [Pa] (read for
    /// solid kinds only).
    pub tau0: Vec<[f64; 6]>,
}

/// The distinct materials of `materials`, in order of first appearance, and the index in that
/// list of each of `materials`.
pub fn distinct_materials(materials: &[ElasticMaterial]) -> (Vec<ElasticMaterial>, Vec<u32>) {
    let mut distinct: Vec<ElasticMaterial> = Vec::new();
    let index = materials
        .iter()
        .map(|m| match distinct.iter().position(|d| d == m) {
            Some(k) => k as u32,
            None => {
                distinct.push(*m);
                distinct.len() as u32 - 1
            }
        })
        .collect();
    (distinct, index)
}

impl Solids {
    /// Whether any solid of the case is of formulation `f`.
    pub fn has(&self, f: SolidFormulation) -> bool {
        self.materials.iter().any(|m| m.formulation == f)
    }

    /// The material of particle `i` (a solid particle).
    pub fn material_of(&self, i: usize) -> &ElasticMaterial {
        &self.materials[self.body[i] as usize]
    }

    /// The distinct materials, in order of first appearance, and the index in that list of
    /// every body's material (what the GPU stores: `Params::solid_materials`).
    pub fn distinct_materials(&self) -> (Vec<ElasticMaterial>, Vec<u32>) {
        distinct_materials(&self.materials)
    }

    /// The fastest P-wave speed c_p = sqrt((K + 4μ/3)/ρs) of the materials [m/s], which the
    /// time step uses for every solid particle.
    pub fn max_p_wave_speed(&self) -> f64 {
        self.materials
            .iter()
            .map(ElasticMaterial::p_wave_speed)
            .fold(0.0, f64::max)
    }
}

/// A rigid set of boundary particles that moves as one: a free body (floating box, falling
/// cylinder) or a prescribed one (a moving tank, a paddle).
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub name: String,
    /// Its particles: `particles[range]` of the scenario (ids are indices).
    pub particles: std::ops::Range<usize>,
    /// Mass [kg] (per metre of depth in 2D).
    pub mass: f64,
    /// Centre of mass at t = 0 [m].
    pub center: [f64; 3],
    /// Inertia tensor about the centre of mass at t = 0, world axes [kg m²] (2D: only zz is used).
    pub inertia: [[f64; 3]; 3],
    pub motion: Motion,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// Moves under the fluid's force and torque, gravity and contact, from this initial
    /// velocity of its centre of mass and angular velocity (world axes; 2D: only z); held at
    /// rest where it is until t = `release_s` (0: from the start; a held body has no initial
    /// velocity), while the water settles around it (DualSPHysics' FtPause).
    Free {
        velocity: [f64; 3],
        omega: [f64; 3],
        release_s: f64,
    },
    /// Follows a given law whatever the forces: x(t) = pivot + d(t) + R(θ(t) about `axis`)(x0 − pivot).
    Prescribed(Prescribed),
}

impl Motion {
    /// Whether the body never moves (`[body.motion] kind = "fixed"`).
    pub fn is_fixed(&self) -> bool {
        matches!(self, Motion::Prescribed(p) if p.law == MotionLaw::Fixed)
    }

    /// Whether the body moves as the case prescribes whatever its load (fixed, sine or series;
    /// the moving tank too), so that contact with the walls cannot move it.
    pub fn is_kinematic(&self) -> bool {
        matches!(self, Motion::Prescribed(_))
    }
}

/// A prescribed rigid motion: a displacement d(t) and a rotation θ(t) about a fixed axis
/// through `pivot` (the pivot moves with d).
#[derive(Clone, Debug, PartialEq)]
pub struct Prescribed {
    pub pivot: [f64; 3],
    /// Unit rotation axis (2D: z).
    pub axis: [f64; 3],
    pub law: MotionLaw,
}

#[derive(Clone, Debug, PartialEq)]
pub enum MotionLaw {
    /// d = 0, θ = 0: a body held where it is (a building in a flood), whose particles are
    /// walls and whose load is still summed and written.
    Fixed,
    /// d(t) = a_d sin(ωt + φ), θ(t) = a_θ sin(ωt + φ).
    Sine {
        translation: [f64; 3],
        angle: f64,
        omega: f64,
        phase: f64,
    },
    /// Samples (t, d, θ) of a time series, cubic Hermite between them (slopes by centred
    /// differences), held constant outside their span.
    Series {
        t: Vec<f64>,
        translation: Vec<[f64; 3]>,
        angle: Vec<f64>,
    },
}

impl Scenario {
    pub fn count(&self, kind: Kind) -> usize {
        self.particles.iter().filter(|p| p.kind == kind).count()
    }

    /// Particles of every boundary kind.
    pub fn boundary_count(&self) -> usize {
        self.particles
            .iter()
            .filter(|p| p.kind.is_boundary())
            .count()
    }

    /// Elastic solid particles, clamped ones included.
    pub fn solid_count(&self) -> usize {
        self.particles.iter().filter(|p| p.kind.is_solid()).count()
    }

    /// Inlet particles that wait behind their buffers at t = 0.
    pub fn dormant_count(&self) -> usize {
        self.inlets
            .iter()
            .map(|i| (0..i.particles.len()).filter(|&k| i.dormant(k)).count())
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2D pillar 4 dx wide and 6 dx high, lattice points at (i + ½) dx.
    fn pillar(dx: f64) -> Vec<Particle> {
        let mut out = Vec::new();
        for i in 0..4 {
            for j in 0..6 {
                out.push(Particle {
                    pos: [(i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx, 0.0],
                    vel: [0.0; 3],
                    rho: 1000.0,
                    kind: Kind::Wall,
                });
            }
        }
        out
    }

    /// On a pillar's top narrower than the reach both edges bound the face; on its side only
    /// the top's edge does within the reach (the bottom lies beyond it); a normal off the
    /// lattice axes gets no extent. The face sits half a spacing above the first layer.
    #[test]
    fn a_face_extends_to_the_edges_within_reach() {
        let (dx, h) = (0.01, 0.013);
        let parts = pillar(dx);
        let top = WallPatch::resolve(&parts, [0.02, 0.06, 0.0], [0.0, 1.0, 0.0], 0.004, 2, dx, h)
            .unwrap();
        assert!(top.face.abs() < 1e-12, "{top:?}");
        assert!((top.over_lo[0] - 0.0).abs() < 1e-12 && (top.over_hi[0] - 0.04).abs() < 1e-12);
        assert_eq!(
            (top.over_lo[1], top.over_hi[1]),
            (-FACE_UNBOUNDED, FACE_UNBOUNDED)
        );
        // Water over the top loads it, water beside the pillar above its top does not.
        assert!(top.faces([0.02, 0.065, 0.0]) && !top.faces([0.045, 0.065, 0.0]));
        assert!(!top.faces([0.02, 0.059, 0.0]));
        let side = WallPatch::resolve(&parts, [0.04, 0.05, 0.0], [1.0, 0.0, 0.0], 0.004, 2, dx, h)
            .unwrap();
        assert!((side.over_hi[1] - 0.06).abs() < 1e-12, "{side:?}");
        assert_eq!(side.over_lo[1], -FACE_UNBOUNDED);
        let n = std::f64::consts::FRAC_1_SQRT_2;
        let slanted =
            WallPatch::resolve(&parts, [0.04, 0.06, 0.0], [n, n, 0.0], 0.004, 2, dx, h).unwrap();
        assert_eq!(slanted.over_lo, [-FACE_UNBOUNDED; 3]);
        assert_eq!(slanted.over_hi, [FACE_UNBOUNDED; 3]);
    }
}
