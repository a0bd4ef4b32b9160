use super::*;

/// The box [lo, hi] as 8 vertices and 12 triangles facing out.
pub(crate) fn cuboid(lo: Point, hi: Point) -> (Vec<Point>, Vec<[usize; 3]>) {
    let v = (0..8)
        .map(|i| [0, 1, 2].map(|a| if i >> a & 1 == 1 { hi[a] } else { lo[a] }))
        .collect();
    let f = vec![
        [0, 2, 3],
        [0, 3, 1],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [0, 4, 6],
        [0, 6, 2],
        [1, 3, 7],
        [1, 7, 5],
    ];
    (v, f)
}

/// A latitude–longitude sphere of `rings` bands and `sectors` sectors, facing out.
pub(crate) fn globe(
    c: Point,
    r: f64,
    rings: usize,
    sectors: usize,
) -> (Vec<Point>, Vec<[usize; 3]>) {
    use std::f64::consts::PI;
    let mut v = vec![[c[0], c[1], c[2] + r]];
    for k in 1..rings {
        let th = PI * k as f64 / rings as f64;
        for j in 0..sectors {
            let ph = 2.0 * PI * j as f64 / sectors as f64;
            v.push([
                c[0] + r * th.sin() * ph.cos(),
                c[1] + r * th.sin() * ph.sin(),
                c[2] + r * th.cos(),
            ]);
        }
    }
    v.push([c[0], c[1], c[2] - r]);
    let south = v.len() - 1;
    let at = |k: usize, j: usize| 1 + (k - 1) * sectors + j % sectors;
    let mut f = Vec::new();
    for j in 0..sectors {
        f.push([0, at(1, j), at(1, j + 1)]);
        for k in 1..rings - 1 {
            let (a, b, c, d) = (at(k, j), at(k, j + 1), at(k + 1, j), at(k + 1, j + 1));
            f.push([a, c, d]);
            f.push([a, d, b]);
        }
        f.push([south, at(rings - 1, j + 1), at(rings - 1, j)]);
    }
    (v, f)
}

/// The square [0, s]² at height z facing up, as two triangles.
fn square(s: f64, z: f64) -> (Vec<Point>, Vec<[usize; 3]>) {
    let v = vec![[0.0, 0.0, z], [s, 0.0, z], [s, s, z], [0.0, s, z]];
    (v, vec![[0, 1, 2], [0, 2, 3]])
}

fn surface((v, f): (Vec<Point>, Vec<[usize; 3]>)) -> Surface {
    Surface::new(&v, &f).unwrap()
}

#[test]
fn a_placement_scales_then_turns_then_moves() {
    let place = Placement {
        scale: 0.001,
        rotate_deg: [0.0, 0.0, 90.0],
        translate: [10.0, 0.0, 1.0],
    };
    let q = place.apply([1000.0, 0.0, 500.0]);
    let expect = [10.0, 1.0, 1.5];
    assert!((0..3).all(|a| (q[a] - expect[a]).abs() < 1e-12), "{q:?}");
    // About x: y goes to z.
    let q = Placement {
        rotate_deg: [90.0, 0.0, 0.0],
        ..Placement::default()
    }
    .apply([0.0, 1.0, 0.0]);
    assert!(q[1].abs() < 1e-12 && (q[2] - 1.0).abs() < 1e-12, "{q:?}");
}

#[test]
fn edges_tell_closed_open_and_flipped_surfaces_apart() {
    let (v, f) = cuboid([0.0; 3], [1.0; 3]);
    assert!(Edges::of(&v, &f).closed());
    let open = Edges::of(&v, &f[1..]);
    assert_eq!((open.open, open.crowded, open.same_way), (3, 0, 0));
    let mut flipped = f.clone();
    flipped[4].swap(1, 2);
    let e = Edges::of(&v, &flipped);
    assert_eq!((e.open, e.same_way), (0, 3));
    assert!(e.same_way_example.is_some());
    let mut crowded = f.clone();
    crowded.push([0, 2, 3]);
    assert!(Edges::of(&v, &crowded).crowded > 0);
    let (v, f) = square(1.0, 0.0);
    assert_eq!(Edges::of(&v, &f).open, 4);
}

#[test]
fn the_winding_number_is_one_inside_and_zero_outside_even_with_a_hole() {
    let (v, f) = cuboid([0.0; 3], [1.0; 3]);
    let closed = surface((v.clone(), f.clone()));
    assert!((closed.winding_number([0.5, 0.4, 0.3]) - 1.0).abs() < 1e-12);
    assert!(closed.winding_number([1.5, 0.4, 0.3]).abs() < 1e-12);
    // One triangle missing: counting crossings through the hole fails, the winding number
    // stays above one half inside.
    let holed = surface((v, f[1..].to_vec()));
    assert!(holed.winding_number([0.5, 0.5, 0.5]) > 0.7);
    assert!(holed.winding_number([0.5, 0.5, -0.5]) < 0.3);
    // Enough triangles that far clusters count by their dipoles.
    let ball = surface(globe([0.0; 3], 1.0, 40, 80));
    assert!(ball.clusters.len() > 1);
    for (p, w) in [
        ([0.1, 0.2, -0.3], 1.0),
        ([0.0, 0.0, 0.97], 1.0),
        ([3.0, 1.0, 0.0], 0.0),
    ] {
        assert!((ball.winding_number(p) - w).abs() < 0.02, "{p:?}");
    }
}

#[test]
fn behind_a_surface_is_against_its_faces_on_edges_and_corners_too() {
    let plane = surface(square(1.0, 0.0));
    assert!(plane.behind([0.5, 0.5, -0.05], 0.1, 0.0));
    assert!(!plane.behind([0.5, 0.5, 0.05], 0.1, 0.0));
    assert!(!plane.behind([0.5, 0.5, -0.15], 0.1, 0.0));
    // On the shared diagonal, and at a corner.
    assert!(plane.behind([0.5, 0.5 + 1e-13, -0.01], 0.1, 0.0));
    assert!(plane.behind([1.0, 1.0, -0.01], 0.1, 0.0));
    // A box: inside near an edge and a corner is behind, outside is not.
    let b = surface(cuboid([0.0; 3], [1.0; 3]));
    assert!(b.behind([0.02, 0.03, 0.5], 0.1, 0.0));
    assert!(b.behind([0.02, 0.02, 0.02], 0.1, 0.0));
    assert!(!b.behind([-0.02, -0.02, -0.02], 0.1, 0.0));
    assert!(!b.behind([-0.02, 0.5, 0.5], 0.1, 0.0));
}

#[test]
fn the_wall_behind_a_closed_box_is_its_lattice_points() {
    let dx = 0.04;
    let b = surface(cuboid([0.0; 3], [0.2, 0.24, 0.16]));
    let wall = b.wall([0.0; 3], dx, 3.0 * dx, 10_000).unwrap();
    let mut expect = Vec::new();
    for i in 0..5 {
        for j in 0..6 {
            for k in 0..4 {
                expect.push([i, j, k]);
            }
        }
    }
    assert_eq!(wall, expect);
    // Deeper than the wall's depth, the box's inside is not wall.
    let big = surface(cuboid([0.0; 3], [0.4; 3]));
    let wall = big.wall([0.0; 3], dx, 2.0 * dx, 10_000).unwrap();
    assert_eq!(wall.len(), 10 * 10 * 10 - 6 * 6 * 6);
    assert_eq!(big.wall([0.0; 3], dx, 2.0 * dx, 100), None);
}

#[test]
fn the_wall_behind_an_open_plane_has_its_layers_and_rounds_its_rim() {
    let dx = 0.1;
    let plane = surface(square(1.0, 0.0));
    // Lattice points at z = −0.05, −0.15, …: three layers within 0.3 behind.
    let wall = plane.wall([0.0, 0.0, 0.0], dx, 0.3, 100_000).unwrap();
    let under: Vec<_> = wall
        .iter()
        .filter(|i| (0..10).contains(&i[0]) && (0..10).contains(&i[1]))
        .collect();
    assert_eq!(under.len(), 300);
    assert!(under.iter().all(|i| (-3..0).contains(&i[2])));
    // Beyond the rim the wall is the quarter disc behind the rim's edge.
    assert!(wall.iter().all(|i| i[2] < 0));
    assert!(wall.contains(&[10, 5, -1]) && wall.contains(&[11, 5, -1]));
    assert!(!wall.contains(&[12, 5, -3]));
}

#[test]
fn points_inside_a_ball_fill_its_volume() {
    let r = 0.5;
    let ball = surface(globe([0.0; 3], r, 48, 96));
    let dx = 0.05;
    let inside = ball.inside_points([-0.5; 3], dx, ([0; 3], [19; 3]));
    let volume = inside.len() as f64 * dx.powi(3);
    let exact = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    assert!(
        (volume / exact - 1.0).abs() < 0.03,
        "{volume} against {exact}"
    );
    let at = |i: [i64; 3]| i.map(|c| -0.5 + (c as f64 + 0.5) * dx);
    for i in &inside {
        assert!(norm(at(*i)) < r + dx, "{i:?}");
    }
}

#[test]
fn a_thin_plate_is_found_thin_and_a_thick_block_is_not() {
    let plate = surface(cuboid([0.0; 3], [1.0, 1.0, 0.01]));
    let (t, _) = plate.thinnest(0.1).unwrap();
    assert!((t - 0.01).abs() < 1e-12, "{t}");
    let block = surface(cuboid([0.0; 3], [1.0, 1.0, 0.5]));
    assert_eq!(block.thinnest(0.1), None);
    assert_eq!(surface(square(1.0, 0.0)).thinnest(0.1), None);
}

#[test]
fn degenerate_triangles_alone_are_no_surface() {
    let v = vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    assert!(Surface::new(&v, &[[0, 1, 2]]).is_none());
}
