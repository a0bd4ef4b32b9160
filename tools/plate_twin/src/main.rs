//! f64 twin of wgsph's oscillating plate (cases/oscillating_plate_2d.toml) for experiments that
//! lavapipe makes too slow: the same lattice, clamp, first-mode initial velocity, solid rates
//! (shaders/elastic.wgsl: continuity, momentum with σ = −pI + τ, Monaghan viscosity, GMS
//! artificial stress, Jaumann rate) and time integration (shaders/integrate.wgsl: velocity
//! Verlet positions, predictor–corrector v, ρ, τ with stored rates, CFL/force time step), on
//! a cell list instead of brute force. It reproduces the GPU's tip history to 4 digits at
//! H/dx = 5 and 8 (docs/validation.md). Beside the period and tip peaks it reports the total
//! energy E = kinetic + elastic (Σ V (p²/2K + τ:τ/4G)) and the work done by the artificial
//! stress and by the artificial viscosity, so the energy budget can be closed.
//!
//!   cargo run --release -- [res=H/dx] [hdx=1.3] [kern=wendland|cubic] [eps=0.3] [alpha=0.1]
//!                          [n=4] [cfl=0.2] [corr=0..4] [hg=0] [periods=1.65] [tipv=0.01] [v=1]
//!                          [int=pc|kdk] [tl=0|1|2 ...]
//!
//! corr (experiments, not in wgsph): 1 corrected ∇v for τ (B_i = (Σ V_j x_ji ⊗ ∇W_ij)⁻¹),
//! 2 and the momentum with B_i∇W, B_j∇W, 3 corrected ∇v for τ and ρ, 4 all three.
//! hg (experiment, not in wgsph): a viscosity on the part of v_ij that the (corrected when
//! corr ≥ 1) velocity gradients do not explain, e_ij = v_ij − ½(∇v_i + ∇v_j) x_ij, in Monaghan's
//! form with coefficient hg, both signs; meant with alpha=0.
//! AXIAL=1 starts the first axial mode instead, v_x = V sin(πs/2L), and measures the tip's
//! x-displacement against T = 4L/sqrt(E/((1 − ν²)ρ)) (plane strain, σ_yy = 0).
//! HOLDER=1 clamps like SPHinXsys instead: the insert (x ≤ 0.06 m) is free, held by fixed
//! particles 3 dx thick above, below and behind it.
//! SHAPE=1 prints the mid-thickness deflection against the mode shape at t = T/4.
//! int=kdk (experiment): kick–drift–kick for the updated-Lagrangian scheme instead of the
//! predictor–corrector (ρ and τ advanced between the half kicks; two neighbour passes a step).
//! tl=1 (experiment): total-Lagrangian solid with a kick–drift–kick step (src/tl.rs; options
//! mat=svk|neo|lin, tlb=0|1, ls=0|1|2, gq=1, hgc=α, hgproj=1, hgx=1; alpha, eps, corr, hg and
//! int are then ignored). Recommended: `tl=1 ls=2 gq=1` (period +4.4 % at H/dx = 5, +2.4 % at
//! 10, energy conserved, cfl 0.2). tl=2: decomposed (Laplacian shear) form, does not work here
//! (see tl.rs). RQ=1 with tl prints the Rayleigh quotient of the smooth plane-strain bending
//! field instead of running (the discrete energy of a smooth mode, no dynamics).
//! STATIC=F (experiment): a static cantilever instead of the free vibration. The plate starts
//! at rest, a load F [N per metre of width] pulls its free end's column down and a damping
//! −ζ v (STATIC_ZETA=ζ, default 40 /s, about 0.8 of critical for the first mode) acts on every
//! free particle; after `periods` theory periods the tip's deflection is compared with
//! Euler–Bernoulli, F a³/(3D), D = E H³/(12(1 − ν²)), a the load's arm (the column's centre),
//! and with Timoshenko's, which adds F a/(κ G H), κ = 5/6.
#![allow(clippy::needless_range_loop)]

mod tl;

use std::f64::consts::PI;

#[derive(Clone, Copy, PartialEq)]
enum Kern {
    Wendland,
    Cubic,
}

#[derive(Clone)]
struct Cfg {
    dx: f64,
    hdx: f64,
    kern: Kern,
    eps: f64,
    alpha: f64,
    cfl: f64,
    n_exp: i32,
    corr: u32, // see the header
    hg: f64,
    periods: f64,
    tipv: f64,
    verbose: bool,
    kdk: bool,             // kick–drift–kick for the updated-Lagrangian scheme (int=kdk)
    tl: Option<tl::TlCfg>, // total-Lagrangian solid (tl=1|2, see tl.rs)
}

#[derive(Clone, Copy, Default)]
struct P {
    x: [f64; 2],
    v: [f64; 2],
    rho: f64,
    tau: [f64; 4],
    clamped: bool,
    /// In the free end's column (STATIC).
    loaded: bool,
}
#[derive(Clone, Copy, Default)]
struct R {
    a: [f64; 2],
    drho: f64,
    dtau: [f64; 4],
    a_art: [f64; 2],
    a_vis: [f64; 2],
}

const E: f64 = 2.0e6;
const NU: f64 = 0.3975;
const RHO0: f64 = 1000.0;
const L: f64 = 0.2;
const H: f64 = 0.02;
const KL: f64 = 1.875;

fn w(k: Kern, h: f64, r: f64) -> f64 {
    let q = r / h;
    match k {
        Kern::Wendland => {
            7.0 / (4.0 * PI * h * h) * (1.0 - 0.5 * q).max(0.0).powi(4) * (2.0 * q + 1.0)
        }
        Kern::Cubic => {
            let a = 10.0 / (7.0 * PI * h * h);
            if q < 1.0 {
                a * (1.0 - 1.5 * q * q + 0.75 * q * q * q)
            } else {
                a * 0.25 * (2.0 - q).max(0.0).powi(3)
            }
        }
    }
}
fn fk(k: Kern, h: f64, r: f64) -> f64 {
    let q = r / h;
    match k {
        Kern::Wendland => {
            -5.0 * 7.0 / (4.0 * PI * h * h) / (h * h) * (1.0 - 0.5 * q).max(0.0).powi(3)
        }
        Kern::Cubic => {
            let a = 10.0 / (7.0 * PI * h * h);
            if q < 1.0 {
                a / (h * h) * (-3.0 + 2.25 * q)
            } else {
                -0.75 * a * (2.0 - q).max(0.0).powi(2) / (h * h * q)
            }
        }
    }
}

fn shape(s: f64) -> f64 {
    let k = KL / L;
    (KL.sin() + KL.sinh()) * ((k * s).cos() - (k * s).cosh())
        - (KL.cos() + KL.cosh()) * ((k * s).sin() - (k * s).sinh())
}

struct Sim {
    w_art: f64,
    w_vis: f64,
    c: Cfg,
    h: f64,
    m: f64,
    c2: f64,
    mu: f64,
    k_bulk: f64,
    w_dx: f64,
    p: Vec<P>,
    r: Vec<R>,
    tip: usize,
    y0: f64,
    tl: Option<tl::Tl>,
    e_tl: f64,
    /// STATIC: the end load [N/m], the damping rate [1/s] and the loaded particles' number.
    static_load: Option<f64>,
    zeta: f64,
    n_loaded: usize,
}

impl Sim {
    fn new(c: Cfg) -> Sim {
        let dx = c.dx;
        let nx = (0.26 / dx).round() as usize;
        let ny = (H / dx).round() as usize;
        let mut p = Vec::new();
        let cs = (E / (3.0 * (1.0 - 2.0 * NU)) / RHO0).sqrt();
        let vtip = c.tipv * cs;
        for j in 0..ny {
            for i in 0..nx {
                let x = [(i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx];
                let clamped = x[0] <= 0.06 && std::env::var("HOLDER").is_err();
                let s = x[0] - 0.06;
                let v = if clamped || s <= 0.0 {
                    0.0
                } else {
                    vtip * shape(s) / shape(L)
                };
                let axial = std::env::var("AXIAL").is_ok();
                let vx = if axial && !clamped && s > 0.0 {
                    vtip * (0.5 * PI * s / L).sin()
                } else {
                    0.0
                };
                p.push(P {
                    x,
                    v: if axial { [vx, 0.0] } else { [0.0, v] },
                    rho: RHO0,
                    tau: [0.0; 4],
                    clamped,
                    loaded: false,
                });
            }
        }
        if std::env::var("HOLDER").is_ok() {
            // SPHinXsys-like: a fixed holder 3 dx thick above, below and behind the free insert.
            let ni = (0.06 / dx).round() as i64;
            for j in -3..(ny as i64 + 3) {
                for i in -3..ni {
                    if i >= 0 && j >= 0 && j < ny as i64 {
                        continue;
                    }
                    let x = [(i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx];
                    p.push(P {
                        x,
                        v: [0.0; 2],
                        rho: RHO0,
                        tau: [0.0; 4],
                        clamped: true,
                        loaded: false,
                    });
                }
            }
        }
        let tip = (0..p.len())
            .max_by(|&a, &b| {
                let key = |q: &P| q.x[0] - 1e-3 * (q.x[1] - 0.5 * H).abs();
                key(&p[a]).partial_cmp(&key(&p[b])).unwrap()
            })
            .unwrap();
        for q in p.iter_mut() {
            q.loaded = !q.clamped && q.x[0] > 0.26 - dx;
        }
        let n_loaded = p.iter().filter(|q| q.loaded).count();
        let env = |k: &str| std::env::var(k).ok().map(|v| v.parse::<f64>().expect(k));
        let h = c.hdx * dx;
        let kb = E / (3.0 * (1.0 - 2.0 * NU));
        let y0 = p[tip].x[1];
        let n = p.len();
        let mut s = Sim {
            w_art: 0.0,
            w_vis: 0.0,
            h,
            m: RHO0 * dx * dx,
            c2: kb / RHO0,
            mu: E / (2.0 * (1.0 + NU)),
            k_bulk: kb,
            w_dx: w(c.kern, h, dx),
            p,
            r: vec![R::default(); n],
            tip,
            y0,
            c,
            tl: None,
            e_tl: 0.0,
            static_load: env("STATIC"),
            zeta: env("STATIC_ZETA").unwrap_or(40.0),
            n_loaded,
        };
        if let Some(tc) = s.c.tl.clone() {
            let nb = s.neighbours();
            let x0: Vec<[f64; 2]> = s.p.iter().map(|q| q.x).collect();
            s.tl = Some(tl::Tl::new(tc, &x0, &nb, s.c.kern, s.h, dx));
        }
        s
    }

    /// Total-Lagrangian accelerations into self.r (and the elastic energy into self.e_tl).
    fn tl_rates(&mut self) {
        let x: Vec<[f64; 2]> = self.p.iter().map(|q| q.x).collect();
        let cl: Vec<bool> = self.p.iter().map(|q| q.clamped).collect();
        let (acc, e) = self.tl.as_ref().unwrap().accel(&x, &cl);
        self.e_tl = e;
        for (r, a) in self.r.iter_mut().zip(acc) {
            *r = R { a, ..R::default() };
        }
        let mut r = std::mem::take(&mut self.r);
        self.external(&mut r);
        self.r = r;
    }

    /// STATIC: the end load and the damping (see the header), added to the rates.
    fn external(&self, r: &mut [R]) {
        let Some(f) = self.static_load else {
            return;
        };
        let a_load = f / (self.n_loaded as f64 * self.m);
        for (q, ri) in self.p.iter().zip(r) {
            if q.clamped {
                continue;
            }
            if q.loaded {
                ri.a[1] -= a_load;
            }
            for a in 0..2 {
                ri.a[a] -= self.zeta * q.v[a];
            }
        }
    }

    /// Kick–drift–kick (velocity Verlet) for the total-Lagrangian solid.
    fn step_tl(&mut self, dt: f64) {
        for (q, r) in self.p.iter_mut().zip(&self.r) {
            if !q.clamped {
                for a in 0..2 {
                    q.v[a] += 0.5 * dt * r.a[a];
                    q.x[a] += dt * q.v[a];
                }
            }
        }
        self.tl_rates();
        for (q, r) in self.p.iter_mut().zip(&self.r) {
            if !q.clamped {
                for a in 0..2 {
                    q.v[a] += 0.5 * dt * r.a[a];
                }
            }
        }
    }

    /// Kick–drift–kick for the updated-Lagrangian scheme: half kick, drift, ρ and τ over the
    /// whole step from the half-step velocities at the new positions, then the second half
    /// kick with the new stresses (two neighbour passes a step).
    fn step_kdk(&mut self, dt: f64) {
        let p0 = self.power();
        for (q, r) in self.p.iter_mut().zip(&self.r) {
            if !q.clamped {
                for a in 0..2 {
                    q.v[a] += 0.5 * dt * r.a[a];
                    q.x[a] += dt * q.v[a];
                }
            }
        }
        let mid = self.rates();
        for (q, r) in self.p.iter_mut().zip(&mid) {
            q.rho += dt * r.drho;
            for k in 0..4 {
                q.tau[k] += dt * r.dtau[k];
            }
        }
        let new = self.rates();
        for (q, r) in self.p.iter_mut().zip(&new) {
            if !q.clamped {
                for a in 0..2 {
                    q.v[a] += 0.5 * dt * r.a[a];
                }
            }
        }
        self.r = new;
        let p1 = self.power();
        self.w_art += 0.5 * dt * (p0.0 + p1.0);
        self.w_vis += 0.5 * dt * (p0.1 + p1.1);
    }

    fn neighbours(&self) -> Vec<Vec<usize>> {
        let cell = 2.0 * self.h;
        let (mut xmin, mut ymin) = (f64::MAX, f64::MAX);
        for q in &self.p {
            xmin = xmin.min(q.x[0]);
            ymin = ymin.min(q.x[1]);
        }
        let key = |x: &[f64; 2]| (((x[0] - xmin) / cell) as i64, ((x[1] - ymin) / cell) as i64);
        let mut map: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
        for (i, q) in self.p.iter().enumerate() {
            map.entry(key(&q.x)).or_default().push(i);
        }
        let s2 = cell * cell;
        self.p
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let (cx, cy) = key(&q.x);
                let mut out = Vec::new();
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        if let Some(v) = map.get(&(cx + dx, cy + dy)) {
                            for &j in v {
                                if j == i {
                                    continue;
                                }
                                let d = [q.x[0] - self.p[j].x[0], q.x[1] - self.p[j].x[1]];
                                if d[0] * d[0] + d[1] * d[1] < s2 {
                                    out.push(j);
                                }
                            }
                        }
                    }
                }
                out
            })
            .collect()
    }

    fn sigma(&self, q: &P) -> [[f64; 2]; 2] {
        let pr = self.c2 * (q.rho - RHO0);
        [[q.tau[0] - pr, q.tau[3]], [q.tau[3], q.tau[1] - pr]]
    }

    fn art(&self, s: &[[f64; 2]; 2], rho: f64) -> [[f64; 2]; 2] {
        if self.c.eps == 0.0 {
            return [[0.0; 2]; 2];
        }
        let (sxx, syy, sxy) = (s[0][0], s[1][1], s[0][1]);
        let th = if sxy != 0.0 || sxx != syy {
            0.5 * (2.0 * sxy).atan2(sxx - syy)
        } else {
            0.0
        };
        let (sn, c) = th.sin_cos();
        let pxx = c * c * sxx + 2.0 * c * sn * sxy + sn * sn * syy;
        let pyy = sn * sn * sxx - 2.0 * c * sn * sxy + c * c * syy;
        let k = -self.c.eps / (rho * rho);
        let rxx = if pxx > 0.0 { k * pxx } else { 0.0 };
        let ryy = if pyy > 0.0 { k * pyy } else { 0.0 };
        [
            [c * c * rxx + sn * sn * ryy, c * sn * (rxx - ryy)],
            [c * sn * (rxx - ryy), sn * sn * rxx + c * c * ryy],
        ]
    }

    fn rates(&self) -> Vec<R> {
        let nb = self.neighbours();
        let h = self.h;
        let m = self.m;
        let cs = self.c2.sqrt();
        let eta2 = 0.01 * h * h;
        let n = self.p.len();
        let sig: Vec<_> = self.p.iter().map(|q| self.sigma(q)).collect();
        let a: Vec<_> = (0..n)
            .map(|i| {
                let r2 = self.p[i].rho * self.p[i].rho;
                sig[i].map(|row| row.map(|x| x / r2))
            })
            .collect();
        let ar: Vec<_> = (0..n).map(|i| self.art(&sig[i], self.p[i].rho)).collect();
        // Correction matrices B_i = (Σ V_j (x_j − x_i) ⊗ ∇_i W_ij)^-1 with the sign such that B·Σ V_j(v_j−v_i)⊗∇W gives ∇v exactly for linear v.
        let bmat: Vec<[[f64; 2]; 2]> = (0..n)
            .map(|i| {
                if self.c.corr == 0 {
                    return [[1.0, 0.0], [0.0, 1.0]];
                }
                let mut mm = [[0.0; 2]; 2];
                for &j in &nb[i] {
                    let x_ij = [
                        self.p[i].x[0] - self.p[j].x[0],
                        self.p[i].x[1] - self.p[j].x[1],
                    ];
                    let r = (x_ij[0] * x_ij[0] + x_ij[1] * x_ij[1]).sqrt();
                    let f = fk(self.c.kern, h, r);
                    let dw = [x_ij[0] * f, x_ij[1] * f];
                    let vj = m / self.p[j].rho;
                    // Σ V_j (x_j − x_i)^a ∂_b W
                    for aa in 0..2 {
                        for bb in 0..2 {
                            mm[aa][bb] += vj * (-x_ij[aa]) * dw[bb];
                        }
                    }
                }
                // (∇v)^ab ≈ Σ V_j (v_j−v_i)^a ∂_c W  · (M^-1)^cb ; M^ac = Σ V_j x_ji^a ∂_c W
                let det = mm[0][0] * mm[1][1] - mm[0][1] * mm[1][0];
                [
                    [mm[1][1] / det, -mm[0][1] / det],
                    [-mm[1][0] / det, mm[0][0] / det],
                ]
            })
            .collect();
        // Velocity gradients (corrected with B when corr ≥ 1) for the non-affine viscosity.
        let grads: Vec<[[f64; 2]; 2]> = (0..n)
            .map(|i| {
                let mut g = [[0.0; 2]; 2];
                if self.c.hg == 0.0 {
                    return g;
                }
                for &j in &nb[i] {
                    let x_ij = [
                        self.p[i].x[0] - self.p[j].x[0],
                        self.p[i].x[1] - self.p[j].x[1],
                    ];
                    let r = (x_ij[0] * x_ij[0] + x_ij[1] * x_ij[1]).sqrt();
                    let f = fk(self.c.kern, h, r);
                    for aa in 0..2 {
                        for bb in 0..2 {
                            g[aa][bb] += m / self.p[j].rho
                                * (self.p[j].v[aa] - self.p[i].v[aa])
                                * x_ij[bb]
                                * f;
                        }
                    }
                }
                let b = &bmat[i];
                let g0 = g;
                for aa in 0..2 {
                    for bb in 0..2 {
                        g[aa][bb] = g0[aa][0] * b[0][bb] + g0[aa][1] * b[1][bb];
                    }
                }
                g
            })
            .collect();
        let mut out = (0..n)
            .map(|i| {
                let pi = &self.p[i];
                let mut acc = [0.0; 2];
                let mut a_art = [0.0; 2];
                let mut a_vis = [0.0; 2];
                let mut drho = 0.0;
                let mut gv = [[0.0; 2]; 2];
                for &j in &nb[i] {
                    let pj = &self.p[j];
                    let x_ij = [pi.x[0] - pj.x[0], pi.x[1] - pj.x[1]];
                    let r2 = x_ij[0] * x_ij[0] + x_ij[1] * x_ij[1];
                    let r = r2.sqrt();
                    let f = fk(self.c.kern, h, r);
                    let dw = [x_ij[0] * f, x_ij[1] * f];
                    let v_ij = [pi.v[0] - pj.v[0], pi.v[1] - pj.v[1]];
                    drho += m * (v_ij[0] * dw[0] + v_ij[1] * dw[1]);
                    let vx = v_ij[0] * x_ij[0] + v_ij[1] * x_ij[1];
                    let hgp = if self.c.hg > 0.0 {
                        let gm = [
                            [
                                0.5 * (grads[i][0][0] + grads[j][0][0]),
                                0.5 * (grads[i][0][1] + grads[j][0][1]),
                            ],
                            [
                                0.5 * (grads[i][1][0] + grads[j][1][0]),
                                0.5 * (grads[i][1][1] + grads[j][1][1]),
                            ],
                        ];
                        let e = [
                            v_ij[0] - gm[0][0] * x_ij[0] - gm[0][1] * x_ij[1],
                            v_ij[1] - gm[1][0] * x_ij[0] - gm[1][1] * x_ij[1],
                        ];
                        let ex = e[0] * x_ij[0] + e[1] * x_ij[1];
                        -self.c.hg * cs * (h * ex / (r2 + eta2)) / (0.5 * (pi.rho + pj.rho))
                    } else {
                        0.0
                    };
                    let piij = hgp
                        + if vx < 0.0 {
                            -self.c.alpha * cs * (h * vx / (r2 + eta2)) / (0.5 * (pi.rho + pj.rho))
                        } else {
                            0.0
                        };
                    let fn_ = (w(self.c.kern, h, r) / self.w_dx).powi(self.c.n_exp);
                    // momentum: with corr==2 use corrected gradients B_i ∇W for σ_i and B_j ∇W for σ_j
                    let (dwi, dwj) = if self.c.corr == 2 || self.c.corr == 4 {
                        let bi = &bmat[i];
                        let bj = &bmat[j];
                        (
                            [
                                dw[0] * bi[0][0] + dw[1] * bi[1][0],
                                dw[0] * bi[0][1] + dw[1] * bi[1][1],
                            ],
                            [
                                dw[0] * bj[0][0] + dw[1] * bj[1][0],
                                dw[0] * bj[0][1] + dw[1] * bj[1][1],
                            ],
                        )
                    } else {
                        (dw, dw)
                    };
                    for aa in 0..2 {
                        for bb in 0..2 {
                            let tt = (ar[i][aa][bb] + ar[j][aa][bb]) * fn_
                                - if aa == bb { piij } else { 0.0 };
                            acc[aa] +=
                                m * (a[i][aa][bb] * dwi[bb] + a[j][aa][bb] * dwj[bb] + tt * dw[bb]);
                            a_art[aa] += m * (ar[i][aa][bb] + ar[j][aa][bb]) * fn_ * dw[bb];
                            if aa == bb {
                                a_vis[aa] -= m * piij * dw[bb];
                            }
                            gv[aa][bb] += m / pj.rho * (pj.v[aa] - pi.v[aa]) * dw[bb];
                        }
                    }
                }
                if self.c.corr >= 1 {
                    let b = &bmat[i];
                    let g = gv;
                    for aa in 0..2 {
                        for bb in 0..2 {
                            gv[aa][bb] = g[aa][0] * b[0][bb] + g[aa][1] * b[1][bb];
                        }
                    }
                }
                if self.c.corr >= 3 {
                    drho = -pi.rho * (gv[0][0] + gv[1][1]);
                }
                let e = [
                    [gv[0][0], 0.5 * (gv[0][1] + gv[1][0])],
                    [0.5 * (gv[0][1] + gv[1][0]), gv[1][1]],
                ];
                let om = 0.5 * (gv[0][1] - gv[1][0]); // Ω^xy ; Ω^yx = -om
                let tr3 = (e[0][0] + e[1][1]) / 3.0;
                let t = &pi.tau; // xx yy zz xy
                                 // τΩᵀ + Ωτ: with Ω = [[0, om],[-om,0]]
                                 // (τΩᵀ)^ab = τ^ac Ω^bc ; (Ωτ)^ab = Ω^ac τ^cb
                let tm = [[t[0], t[3]], [t[3], t[1]]];
                let omm = [[0.0, om], [-om, 0.0]];
                let mut d = [[0.0; 2]; 2];
                for aa in 0..2 {
                    for bb in 0..2 {
                        let mut s = 2.0 * self.mu * (e[aa][bb] - if aa == bb { tr3 } else { 0.0 });
                        for cc in 0..2 {
                            s += tm[aa][cc] * omm[bb][cc] + omm[aa][cc] * tm[cc][bb];
                        }
                        d[aa][bb] = s;
                    }
                }
                let dzz = 2.0 * self.mu * (-tr3);
                R {
                    a: if pi.clamped { [0.0; 2] } else { acc },
                    drho,
                    dtau: [d[0][0], d[1][1], dzz, d[0][1]],
                    a_art,
                    a_vis,
                }
            })
            .collect::<Vec<R>>();
        self.external(&mut out);
        out
    }

    fn energy(&self) -> (f64, f64) {
        if self.tl.is_some() {
            let ke: f64 = self
                .p
                .iter()
                .filter(|q| !q.clamped)
                .map(|q| 0.5 * self.m * (q.v[0] * q.v[0] + q.v[1] * q.v[1]))
                .sum();
            return (ke, self.e_tl);
        }
        let mut ke = 0.0;
        let mut ee = 0.0;
        for q in &self.p {
            if !q.clamped {
                ke += 0.5 * self.m * (q.v[0] * q.v[0] + q.v[1] * q.v[1]);
            }
            let pr = self.c2 * (q.rho - RHO0);
            let t = &q.tau;
            ee += self.m / q.rho
                * (pr * pr / (2.0 * self.k_bulk)
                    + (t[0] * t[0] + t[1] * t[1] + t[2] * t[2] + 2.0 * t[3] * t[3])
                        / (4.0 * self.mu));
        }
        (ke, ee)
    }

    fn dt_next(&self) -> f64 {
        let mut sp: f64 = 0.0;
        let mut ac: f64 = 0.0;
        for (q, r) in self.p.iter().zip(&self.r) {
            sp = sp.max(self.c2.sqrt() + (q.v[0] * q.v[0] + q.v[1] * q.v[1]).sqrt());
            if !q.clamped {
                ac = ac.max((r.a[0] * r.a[0] + r.a[1] * r.a[1]).sqrt());
            }
        }
        let mut dt = self.c.cfl * self.h / sp;
        if ac > 0.0 {
            dt = dt.min(self.c.cfl * (self.h / ac).sqrt());
        }
        dt
    }

    fn power(&self) -> (f64, f64) {
        let mut pa = 0.0;
        let mut pv = 0.0;
        for (q, r) in self.p.iter().zip(&self.r) {
            if q.clamped {
                continue;
            }
            pa += self.m * (q.v[0] * r.a_art[0] + q.v[1] * r.a_art[1]);
            pv += self.m * (q.v[0] * r.a_vis[0] + q.v[1] * r.a_vis[1]);
        }
        (pa, pv)
    }
    fn step(&mut self, dt: f64) {
        if self.tl.is_some() {
            return self.step_tl(dt);
        }
        if self.c.kdk {
            return self.step_kdk(dt);
        }
        let p0 = self.power();
        let old = self.r.clone();
        for (q, r) in self.p.iter_mut().zip(&old) {
            if !q.clamped {
                for a in 0..2 {
                    q.x[a] += dt * q.v[a] + 0.5 * dt * dt * r.a[a];
                    q.v[a] += dt * r.a[a];
                }
            }
            q.rho += dt * r.drho;
            for k in 0..4 {
                q.tau[k] += dt * r.dtau[k];
            }
        }
        let new = self.rates();
        for ((q, r), o) in self.p.iter_mut().zip(&new).zip(&old) {
            if !q.clamped {
                for a in 0..2 {
                    q.v[a] += 0.5 * dt * (r.a[a] - o.a[a]);
                }
            }
            q.rho += 0.5 * dt * (r.drho - o.drho);
            for k in 0..4 {
                q.tau[k] += 0.5 * dt * (r.dtau[k] - o.dtau[k]);
            }
        }
        self.r = new;
        let p1 = self.power();
        self.w_art += 0.5 * dt * (p0.0 + p1.0);
        self.w_vis += 0.5 * dt * (p0.1 + p1.1);
    }
}

fn main() {
    let mut c = Cfg {
        dx: 0.004,
        hdx: 1.3,
        kern: Kern::Wendland,
        eps: 0.3,
        alpha: 0.1,
        cfl: 0.2,
        n_exp: 4,
        corr: 0,
        hg: 0.0,
        periods: 1.65,
        tipv: 0.01,
        verbose: false,
        kdk: false,
        tl: None,
    };
    let mut tc = tl::TlCfg {
        mode: 0,
        mat: tl::Mat::Svk,
        corrected: true,
        ls: 0,
        zeta: 1.0,
        hgc: 0.0,
        hgproj: false,
        hgx: false,
        gq: false,
    };
    for a in std::env::args().skip(1) {
        let (k, v) = a.split_once('=').expect("k=v");
        match k {
            "hdx_ratio" | "H/dx" | "res" => c.dx = H / v.parse::<f64>().unwrap(),
            "hdx" => c.hdx = v.parse().unwrap(),
            "kern" => {
                c.kern = if v == "cubic" {
                    Kern::Cubic
                } else {
                    Kern::Wendland
                }
            }
            "eps" => c.eps = v.parse().unwrap(),
            "alpha" => c.alpha = v.parse().unwrap(),
            "cfl" => c.cfl = v.parse().unwrap(),
            "n" => c.n_exp = v.parse().unwrap(),
            "corr" => c.corr = v.parse().unwrap(),
            "hg" => c.hg = v.parse().unwrap(),
            "periods" => c.periods = v.parse().unwrap(),
            "tipv" => c.tipv = v.parse().unwrap(),
            "v" => c.verbose = v == "1",
            "int" => c.kdk = v == "kdk",
            "tl" => tc.mode = v.parse().unwrap(),
            "mat" => {
                tc.mat = match v {
                    "svk" => tl::Mat::Svk,
                    "neo" => tl::Mat::Neo,
                    "lin" => tl::Mat::Lin,
                    _ => panic!("mat=svk|neo|lin"),
                }
            }
            "tlb" => tc.corrected = v == "1",
            "ls" => tc.ls = v.parse().unwrap(),
            "zeta" => tc.zeta = v.parse().unwrap(),
            "hgc" => tc.hgc = v.parse().unwrap(),
            "hgproj" => tc.hgproj = v == "1",
            "hgx" => tc.hgx = v == "1",
            "gq" => tc.gq = v == "1",
            _ => panic!("unknown {k}"),
        }
    }
    if tc.mode > 0 {
        c.tl = Some(tc);
    }
    if std::env::var("STATIC").is_ok() {
        c.tipv = 0.0;
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut s = Sim::new(c.clone());
    let k = KL / L;
    let omega2 = E * H * H * k.powi(4) / (12.0 * RHO0 * (1.0 - NU * NU));
    let mut tth = 2.0 * PI / omega2.sqrt();
    let axial = std::env::var("AXIAL").is_ok();
    if axial {
        tth = 4.0 * L / (E / (1.0 - NU * NU) / RHO0).sqrt();
    }
    if s.tl.is_some() && std::env::var("RQ").is_ok() {
        // Rayleigh quotient of the smooth plane-strain bending field (E–B kinematics with the
        // Poisson thickening): ω² = 2 Φ(A u) / (A² Σ m |u|²).
        let lam = E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU));
        let mu = E / (2.0 * (1.0 + NU));
        let k = KL / L;
        let d1 = |s: f64| {
            k * ((KL.sin() + KL.sinh()) * (-(k * s).sin() - (k * s).sinh())
                - (KL.cos() + KL.cosh()) * ((k * s).cos() - (k * s).cosh()))
        };
        let d2 = |s: f64| {
            k * k
                * ((KL.sin() + KL.sinh()) * (-(k * s).cos() - (k * s).cosh())
                    - (KL.cos() + KL.cosh()) * (-(k * s).sin() - (k * s).sinh()))
        };
        let amp = 1e-6 / shape(L);
        let mut mu2 = 0.0;
        for q in s.p.iter_mut() {
            let sx = q.x[0] - 0.06;
            if q.clamped || sx <= 0.0 {
                continue;
            }
            let z = q.x[1] - 0.5 * H;
            let uy = shape(sx) + lam / (lam + 2.0 * mu) * 0.5 * z * z * d2(sx);
            let ux = -z * d1(sx);
            q.x[0] += amp * ux;
            q.x[1] += amp * uy;
            mu2 += s.m * amp * amp * (ux * ux + uy * uy);
        }
        s.tl_rates();
        let om2 = 2.0 * s.e_tl / mu2;
        let om2_th = E * H * H * k.powi(4) / (12.0 * RHO0 * (1.0 - NU * NU));
        println!(
            "{} | Rayleigh quotient of the smooth mode: T/T_EB = {:.4}",
            args.join(" "),
            (om2_th / om2).sqrt()
        );
        return;
    }
    if s.tl.is_some() {
        s.tl_rates();
    } else {
        s.r = s.rates();
    }
    let e0 = s.energy();
    let every = tth / 200.0;
    let nsamp = (c.periods * tth / every).round() as usize;
    let mut hist = vec![(0.0, 0.0)];
    let mut en = vec![(0.0, e0.0 + e0.1)];
    let mut t = 0.0;
    let mut steps = 0u64;
    for kk in 1..=nsamp {
        let target = kk as f64 * every;
        loop {
            let rem = target - t;
            let dt0 = s.dt_next();
            if rem <= 1e-4 * dt0 {
                break;
            }
            if steps > 200000 {
                println!(
                    "{} | too many steps at t {t:.4} (dt {dt0:.2e}) y {:+.4}",
                    args.join(" "),
                    s.p[s.tip].x[1] - s.y0
                );
                return;
            }
            let dt = dt0.min(rem);
            s.step(dt);
            t += dt;
            steps += 1;
        }
        t = target;
        let y = if axial {
            s.p[s.tip].x[0] - (0.26 - 0.5 * s.c.dx)
        } else {
            s.p[s.tip].x[1] - s.y0
        };
        hist.push((t, y));
        let e = s.energy();
        en.push((t, e.0 + e.1));
        if c.verbose && kk % 10 == 0 {
            println!(
                "t {t:.4} y {y:+.5} KE {:.4e} EE {:.4e} E {:.4e}",
                e.0,
                e.1,
                e.0 + e.1
            );
        }
        if !y.is_finite() {
            println!("blew up");
            return;
        }
        if std::env::var("SHAPE").is_ok() && kk == 50 {
            // mean y-displacement of each column vs s, normalised by the tip
            let ny = (H / s.c.dx).round() as usize;
            let nx = (0.26 / s.c.dx).round() as usize;
            let tipw: f64 = (0..ny)
                .map(|j| s.p[j * nx + nx - 1].x[1] - (j as f64 + 0.5) * s.c.dx)
                .sum::<f64>()
                / ny as f64;
            let k = KL / L;
            let phi = |x: f64| {
                (KL.sin() + KL.sinh()) * ((k * x).cos() - (k * x).cosh())
                    - (KL.cos() + KL.cosh()) * ((k * x).sin() - (k * x).sinh())
            };
            for i in (0..nx).step_by((nx / 13).max(1)) {
                let w: f64 = (0..ny)
                    .map(|j| s.p[j * nx + i].x[1] - (j as f64 + 0.5) * s.c.dx)
                    .sum::<f64>()
                    / ny as f64;
                let sx = (i as f64 + 0.5) * s.c.dx - 0.06;
                println!(
                    "s {:+.4} w/wtip {:.4} mode {:.4}",
                    sx,
                    w / tipw,
                    if sx > 0.0 { phi(sx) / phi(L) } else { 0.0 }
                );
            }
            println!("tip w {tipw:.5}");
        }
    }
    if let Some(f) = s.static_load {
        // The tip's deflection, settled, against beam theory at the load's arm a.
        let y = hist.last().unwrap().1;
        let drift = y - hist[hist.len() - 11].1;
        let a = L - 0.5 * s.c.dx;
        let d = E * H.powi(3) / (12.0 * (1.0 - NU * NU));
        let eb = -f * a.powi(3) / (3.0 * d);
        let g = E / (2.0 * (1.0 + NU));
        let timo = eb - f * a / (5.0 / 6.0 * g * H);
        println!(
            "{} | N {} steps {} | static tip {y:+.6} m (last 10 samples {drift:+.1e}) | E-B \
             {eb:+.6} ({:+.1} %) | Timoshenko {timo:+.6} ({:+.1} %)",
            args.join(" "),
            s.p.len(),
            steps,
            100.0 * (y / eb - 1.0),
            100.0 * (y / timo - 1.0)
        );
        return;
    }
    let cr: Vec<f64> = hist
        .windows(2)
        .skip(1)
        .filter(|w| (w[0].1 > 0.0) != (w[1].1 > 0.0))
        .map(|w| w[0].0 + (w[1].0 - w[0].0) * w[0].1 / (w[0].1 - w[1].1))
        .collect();
    let peak = |t0: f64, t1: f64| {
        hist.iter()
            .filter(|(t, _)| *t >= t0 && *t <= t1)
            .map(|(_, y)| y.abs())
            .fold(0.0, f64::max)
    };
    let emax = en.iter().map(|e| e.1).fold(0.0, f64::max);
    let eend = en.last().unwrap().1;
    print!(
        "{} | N {} steps {} | Emax/E0 {:.3} Eend/E0 {:.3} W_art/E0 {:+.3} W_visc/E0 {:+.3}",
        args.join(" "),
        s.p.len(),
        steps,
        emax / en[0].1,
        eend / en[0].1,
        s.w_art / en[0].1,
        s.w_vis / en[0].1
    );
    if cr.len() >= 3 {
        let per = cr[2] - cr[0];
        println!(
            " | T {:.4} err {:+.1}% | halves {:.4}/{:.4} | peaks {:.4}/{:.4}/{:.4}",
            per,
            100.0 * (per - tth) / tth,
            cr[1] - cr[0],
            cr[2] - cr[1],
            peak(0.0, cr[0]),
            peak(cr[0], cr[1]),
            peak(cr[1], cr[2])
        );
    } else {
        println!(" | crossings {:?} peak {:.4}", cr, peak(0.0, t));
    }
}
