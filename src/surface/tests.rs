//! The reconstruction on shapes whose surface is known.

use super::*;

/// Lattice points (spacing `dx`, cell centres from the origin) within [lo, hi] that `keep`.
fn lattice(dx: f64, lo: [f64; 3], hi: [f64; 3], keep: impl Fn([f64; 3]) -> bool) -> Vec<[f64; 3]> {
    let n = |a: usize| ((hi[a] - lo[a]) / dx).round() as i64;
    let mut out = Vec::new();
    for i in 0..n(0) {
        for j in 0..n(1) {
            for k in 0..n(2) {
                let x = [i, j, k].map(|c| c as f64 + 0.5);
                let x = [lo[0] + x[0] * dx, lo[1] + x[1] * dx, lo[2] + x[2] * dx];
                if keep(x) {
                    out.push(x);
                }
            }
        }
    }
    out
}

/// The defaults of a run of spacing `dx` and h = 1.3 dx.
fn params(dx: f64) -> SurfaceParams {
    SurfaceParams {
        particle_radius: 0.5 * dx,
        support_radius: 2.6 * dx,
        cube_size: 0.5 * dx,
        iso_threshold: 0.6,
        rho0: 1000.0,
    }
}

/// A ball of lattice particles gives a sphere of the ball's radius: the radius of the sphere of
/// the particles' volume N dx³ on average within a quarter spacing (measured: +0.1 dx), every
/// vertex within half a spacing (the lattice's staircase outline: −0.13 … +0.37 dx), every
/// triangle facing outwards.
#[test]
fn a_ball_of_particles_gives_a_sphere_of_its_radius() {
    let (dx, r) = (0.01, 0.1);
    let ball = lattice(dx, [-0.12; 3], [0.12; 3], |x| {
        x.iter().map(|c| c * c).sum::<f64>() <= r * r
    });
    let mesh = reconstruct(&ball, 0.0, &params(dx)).unwrap();
    let r_eq = (3.0 * ball.len() as f64 * dx.powi(3) / (4.0 * std::f64::consts::PI)).cbrt();
    let radii: Vec<f64> = (mesh.vertices.iter())
        .map(|v| v.iter().map(|c| c * c).sum::<f64>().sqrt())
        .collect();
    let (lo, hi) = radii
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &d| (lo.min(d), hi.max(d)));
    let mean = radii.iter().sum::<f64>() / radii.len() as f64;
    println!(
        "{} particles, {} vertices, {} triangles: radius {mean:.5} ({lo:.5} … {hi:.5}) against {r_eq:.5}",
        ball.len(),
        mesh.vertices.len(),
        mesh.triangles.len()
    );
    assert!(mesh.triangles.len() > 1000);
    // Every triangle is counter-clockwise seen from outside (its normal points away from the
    // centre), as `SurfaceMesh` documents.
    let outward = |t: &[usize; 3]| {
        let [a, b, c] = t.map(|i| mesh.vertices[i]);
        let (u, v) = (
            [0, 1, 2].map(|k| b[k] - a[k]),
            [0, 1, 2].map(|k| c[k] - a[k]),
        );
        let n =
            [0, 1, 2].map(|k| u[(k + 1) % 3] * v[(k + 2) % 3] - u[(k + 2) % 3] * v[(k + 1) % 3]);
        (0..3).map(|k| n[k] * a[k]).sum::<f64>() > 0.0
    };
    assert!(
        mesh.triangles.iter().all(outward),
        "a triangle faces inwards"
    );
    assert!(
        (mean - r_eq).abs() < 0.25 * dx,
        "mean radius {mean}, ball {r_eq}"
    );
    assert!(lo > r_eq - 0.5 * dx && hi < r_eq + 0.5 * dx, "{lo} … {hi}");
}

/// A block of still water gives a flat top at the water's height: over its middle (more than
/// 3h from the sides) every vertex of the top within a quarter spacing of 0.1 m (measured:
/// +0.047 … +0.052 dx).
#[test]
fn still_water_gives_a_flat_surface_at_its_height() {
    let (dx, depth) = (0.01, 0.1);
    let block = lattice(dx, [0.0; 3], [0.2, 0.2, depth], |_| true);
    let mesh = reconstruct(&block, 1.5, &params(dx)).unwrap();
    assert_eq!(mesh.time_s, 1.5);
    let top: Vec<f64> = (mesh.vertices.iter())
        .filter(|v| (0.05..0.15).contains(&v[0]) && (0.05..0.15).contains(&v[1]) && v[2] > 0.05)
        .map(|v| v[2])
        .collect();
    let (lo, hi) = top
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &z| (lo.min(z), hi.max(z)));
    println!("{} top vertices at z {lo:.5} … {hi:.5}", top.len());
    assert!(top.len() > 100);
    assert!(
        lo > depth - 0.25 * dx && hi < depth + 0.25 * dx,
        "{lo} … {hi}"
    );
}

#[test]
fn no_fluid_gives_no_triangles_and_bad_parameters_are_named() {
    let mesh = reconstruct(&[], 2.0, &params(0.01)).unwrap();
    assert!(mesh.vertices.is_empty() && mesh.triangles.is_empty());
    let bad = SurfaceParams {
        cube_size: 0.0,
        ..params(0.01)
    };
    let e = reconstruct(&[[0.0; 3]], 0.0, &bad).unwrap_err().to_string();
    assert!(e.contains("--cube-size"), "{e}");
}
