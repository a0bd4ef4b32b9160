//! Which probes can never measure: a pressure probe whose point no fluid can come within h of
//! (inside a wall, an obstacle or a fixed body, or in a closed-off pocket), or a wave gauge
//! whose whole line is so. Such a probe would read 0 for the whole run (no fluid in its kernel)
//! and look like a dry sensor; instead the case loader warns at set-up (`case::build`) and the
//! solver writes NaN for it (`sph::probes::Probes`), the marker a front probe already uses when
//! there is no fluid at all. Points outside the domain are refused by the loader before this
//! runs (`case::domain`).
//!
//! Where fluid can ever be: the cells of edge dx of the domain reachable from the fluid's and
//! the inlets' particles at t = 0 through cells that hold no particle of a fixed wall, obstacle
//! or fixed body and lie in front of every mirror wall (a flood fill; moving bodies and elastic
//! solids may leave their place, so they block nothing). A cell that a gap in a solid lets the
//! fill through only makes the check more lenient. Within h of no reachable cell, fluid fills
//! at most the kernel's outer rim (the support is 2h): well under the tenth a pressure probe
//! needs and the half a gauge needs (shaders/probes.wgsl), so the verdict is "cannot", not
//! "might not". A probe that moves with a body is not judged (its surroundings change).

use std::collections::VecDeque;

use crate::scenario::{Kind, ProbeKind, Scenario};

/// Domains of more cells than this are not judged (the fill's memory, one byte a cell).
const MAX_CELLS: u64 = 1 << 28;

/// For every probe of `sc`, in order: `None` where it can measure, else why it cannot (a
/// phrase naming the place, for a warning).
pub fn unmeasurable(sc: &Scenario) -> Vec<Option<String>> {
    let judged = |p: &crate::scenario::Probe| {
        p.body.is_none()
            && matches!(
                p.kind,
                ProbeKind::Pressure { .. } | ProbeKind::Height { .. }
            )
    };
    if !sc.probes.iter().any(judged) {
        return vec![None; sc.probes.len()];
    }
    let Some(reach) = Reach::new(sc) else {
        return vec![None; sc.probes.len()];
    };
    let (dim, h) = (sc.physics.dim, sc.physics.h);
    sc.probes
        .iter()
        .map(|p| match &p.kind {
            _ if !judged(p) => None,
            ProbeKind::Pressure { point } => (!reach.near(*point, *point)).then(|| {
                format!(
                    "no fluid can ever come within h = {} m of its point {} (it lies inside a \
                     wall, an obstacle or a fixed body, or in a pocket closed to the fluid)",
                    sig(h),
                    fmt_point(point, dim)
                )
            }),
            ProbeKind::Height { base, .. } => {
                let up = dim as usize - 1;
                let mut top = *base;
                top[up] = sc.domain.max[up];
                (!reach.near(*base, top)).then(|| {
                    format!(
                        "no fluid can ever come within h = {} m of its line from {} up to the \
                         domain's top (it lies inside a wall, an obstacle or a fixed body)",
                        sig(h),
                        fmt_point(base, dim)
                    )
                })
            }
            // A front is a max over all the fluid; a wall patch is resolved onto the wall's
            // particles by the loader, which refuses a patch with none; no water through a
            // section is a discharge of 0, which it measures.
            ProbeKind::Front { .. } | ProbeKind::WallPressure(_) | ProbeKind::Discharge { .. } => {
                None
            }
        })
        .collect()
}

/// The cells of edge dx over the domain that fluid can reach.
struct Reach {
    min: [f64; 3],
    dx: f64,
    h: f64,
    n: [usize; 3],
    reached: Vec<bool>,
}

impl Reach {
    fn new(sc: &Scenario) -> Option<Self> {
        let dim = sc.physics.dim as usize;
        let dx = sc.physics.dx;
        let n = [0, 1, 2].map(|a| {
            if a < dim {
                (((sc.domain.max[a] - sc.domain.min[a]) / dx).ceil() as usize).max(1)
            } else {
                1
            }
        });
        let total = n.iter().map(|&c| c as u64).product::<u64>();
        if total > MAX_CELLS {
            return None;
        }
        let min = sc.domain.min;
        let index = |x: [f64; 3]| -> Option<usize> {
            let mut c = [0usize; 3];
            for a in 0..dim {
                let f = ((x[a] - min[a]) / dx).floor();
                if f < 0.0 || f >= n[a] as f64 {
                    return None;
                }
                c[a] = f as usize;
            }
            Some(c[0] + n[0] * (c[1] + n[1] * c[2]))
        };
        // 0: open, 1: blocked, 2: reached.
        let mut state = vec![0u8; total as usize];
        let owner = |i: usize| sc.bodies.iter().position(|b| b.particles.contains(&i));
        for (i, p) in sc.particles.iter().enumerate() {
            let fixed = match p.kind {
                Kind::Fluid | Kind::Inlet | Kind::Solid | Kind::SolidClamped => false,
                _ => owner(i).is_none_or(|k| sc.bodies[k].motion.is_fixed()),
            };
            if let (true, Some(c)) = (fixed, index(p.pos)) {
                state[c] = 1;
            }
        }
        let planes = &sc.walls.mirror_planes;
        if !planes.is_empty() {
            for (c, s) in state.iter_mut().enumerate() {
                let x = centre(min, dx, n, c);
                let behind = planes.iter().any(|m| {
                    (0..3)
                        .map(|a| (x[a] - m.point[a]) * m.normal[a])
                        .sum::<f64>()
                        < 0.0
                });
                if behind {
                    *s = 1;
                }
            }
        }
        let mut queue = VecDeque::new();
        for p in &sc.particles {
            if matches!(p.kind, Kind::Fluid | Kind::Inlet) {
                if let Some(c) = index(p.pos) {
                    if state[c] != 2 {
                        state[c] = 2;
                        queue.push_back(c);
                    }
                }
            }
        }
        let stride = [1, n[0], n[0] * n[1]];
        while let Some(c) = queue.pop_front() {
            let at = [c % n[0], (c / n[0]) % n[1], c / (n[0] * n[1])];
            for a in 0..dim {
                for up in [false, true] {
                    let next = match up {
                        false if at[a] > 0 => c - stride[a],
                        true if at[a] + 1 < n[a] => c + stride[a],
                        _ => continue,
                    };
                    if state[next] == 0 {
                        state[next] = 2;
                        queue.push_back(next);
                    }
                }
            }
        }
        Some(Self {
            min,
            dx,
            h: sc.physics.h,
            n,
            reached: state.into_iter().map(|s| s == 2).collect(),
        })
    }

    /// Whether a reached cell comes within h of the segment from `a` to `b` (a cell is a box
    /// of edge dx: its nearest point, not its centre, counts).
    fn near(&self, a: [f64; 3], b: [f64; 3]) -> bool {
        let (dx, h, n) = (self.dx, self.h, self.n);
        let lo = [0, 1, 2].map(|k| a[k].min(b[k]) - h);
        let hi = [0, 1, 2].map(|k| a[k].max(b[k]) + h);
        let range = |k: usize| {
            let from = ((lo[k] - self.min[k]) / dx).floor().max(0.0) as usize;
            let to = (((hi[k] - self.min[k]) / dx).floor().max(0.0) as usize).min(n[k] - 1);
            from..=to
        };
        for z in range(2) {
            for y in range(1) {
                for x in range(0) {
                    let c = x + n[0] * (y + n[1] * z);
                    if !self.reached[c] {
                        continue;
                    }
                    let cmin = [x, y, z].map(|i| i as f64 * dx);
                    let cmin = [0, 1, 2].map(|k| self.min[k] + cmin[k]);
                    if box_segment_distance2(cmin, dx, n, a, b) <= h * h {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// The centre of cell `c`.
fn centre(min: [f64; 3], dx: f64, n: [usize; 3], c: usize) -> [f64; 3] {
    let at = [c % n[0], (c / n[0]) % n[1], c / (n[0] * n[1])];
    [0, 1, 2].map(|k| min[k] + (at[k] as f64 + 0.5) * dx)
}

/// Squared distance from the box [cmin, cmin + dx] (an axis of one cell ignored: 2D) to the
/// axis-aligned segment a–b (a probe's point, or a gauge's vertical line): per axis the gap
/// between the two intervals, exact for such a segment.
fn box_segment_distance2(cmin: [f64; 3], dx: f64, n: [usize; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3)
        .filter(|&k| n[k] > 1)
        .map(|k| {
            let gap = (cmin[k] - a[k].max(b[k])).max(a[k].min(b[k]) - (cmin[k] + dx));
            gap.max(0.0).powi(2)
        })
        .sum()
}

/// The first `dim` coordinates of `x` to 6 significant digits, for messages.
pub fn fmt_point(x: &[f64; 3], dim: u32) -> String {
    let parts: Vec<String> = x[..dim as usize]
        .iter()
        .map(|c| format!("{}", sig(*c)))
        .collect();
    format!("[{}]", parts.join(", "))
}

/// `x` to 6 significant digits, for messages.
pub fn sig(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(5 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}
