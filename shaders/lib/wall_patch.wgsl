// The boundary particles a wall-pressure sensor sums over (WallPatch in scenario.rs): the
// probe's column test (probes.wgsl) and, on fixed walls, the sensor each particle belongs to
// and the fluid that loads it (interaction.wgsl). The sensors are `tables.wall_sensors` (common.wgsl).

const NO_SENSOR: u32 = 0xFFFFFFFFu;

// Whether fluid at x loads the sensor's particles: in front of its face and over it, not
// beyond an edge.
fn faces_sensor(s: WallSensor, x: vec3<f32>) -> bool {
    return dot(x - s.point, s.normal) > s.face && all(x >= s.over_lo) && all(x <= s.over_hi);
}

// Whether a boundary particle at x belongs to the patch: (x − point)·normal in [−3h, h] (every
// particle the fluid reaches, 2h from the nearest fluid, and a face given half a spacing off)
// and closer than `radius` to the normal line through `point`.
fn in_wall_patch(point: vec3<f32>, normal: vec3<f32>, radius: f32, x: vec3<f32>) -> bool {
    let r = x - point;
    let d = dot(r, normal);
    let t2 = dot(r, r) - d * d;
    return d >= -3.0 * params.h && d <= params.h && t2 < radius * radius;
}

// The sensor a fixed wall's particle at x belongs to (WallParams::sensor_of): of those whose
// patch holds it, the one whose face it lies least deep behind, the first of those within
// h/100 of that (so that f32 rounding does not split a tie); NO_SENSOR for none.
fn owning_sensor(x: vec3<f32>) -> u32 {
    var best = NO_SENSOR;
    var best_depth = 0.0;
    for (var k = 0u; k < N_WALL_SENSORS; k++) {
        let s = tables.wall_sensors[k];
        let depth = s.face - dot(x - s.point, s.normal);
        let nearer = depth < best_depth - 0.01 * params.h;
        if (in_wall_patch(s.point, s.normal, s.radius, x) && (best == NO_SENSOR || nearer)) {
            best = k;
            best_depth = depth;
        }
    }
    return best;
}
