// The water's share of what the walls leave of the kernel at a point (docs/equations.md
// eq. 34), the criterion of the flood maps' surface and of the depth gauges: ψ = φ_f / (1 − φ_s).
// The pass file declares `pos`, `velrho`, `code` and `cell_start`; needs neighbours.wgsl.
// Where the walls fill more than this share of the kernel, the point lies inside them: ψ is
// not formed there (it would divide by almost nothing).
const MAP_MAX_SOLID_SHARE: f32 = 0.9;

// The fluid's and the walls' shares of the kernel at x (a wall's particle at the reference
// volume m/ρ0: its share is its place, not its density), and the fluid's Σ v W V.
struct MapSums {
    fluid: f32,
    solid: f32,
    momentum: vec2<f32>,
}

fn map_sums(x: vec3<f32>) -> MapSums {
    let p = pos_of_point(x);
    let support2 = 4.0 * params.h * params.h;
    var s = MapSums(0.0, 0.0, vec2<f32>(0.0));
    var rows: NeighbourRanges;
    var w = slot_walk(p, &rows, true);
    for (; walk_on(&w, &rows); w.j++) {
        let j = w.j;
        let x_ij = rel_pos(p, pos[j]);
        let r2 = dot(x_ij, x_ij);
        let kind = code_kind(code[j]);
        if (r2 >= support2 || kind == KIND_EXCLUDED || kind == KIND_INLET) {
            continue;
        }
        let wk = kernel_w(sqrt(r2) / params.h);
        if (kind == KIND_FLUID) {
            let vr = velrho[j];
            let wv = wk * params.mass / vr.w;
            s.fluid += wv;
            s.momentum += wv * vr.xy;
        } else {
            s.solid += wk * params.mass / params.rho0;
        }
    }
    return s;
}

// ψ = φ_f / (1 − φ_s), 0 inside the walls.
fn water_fraction(s: MapSums) -> f32 {
    if (s.solid > MAP_MAX_SOLID_SHARE) {
        return 0.0;
    }
    return s.fluid / (1.0 - s.solid);
}

