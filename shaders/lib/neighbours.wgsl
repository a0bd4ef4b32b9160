// Neighbour search over the cell list: the index ranges of the sorted particles in the cells
// around a point. The pass file declares `cell_start` (slot s holds the sorted particles
// cell_start[s] .. cell_start[s + 1]).

// The distinct slots of the 3^DIM cells around `c` (two neighbour cells can share a slot;
// visiting it twice would count its particles twice).
fn neighbour_slots(c: vec3<i32>, slots: ptr<function, array<u32, 27>>) -> u32 {
    var n = 0u;
    let zr = select(0, 1, DIM == 3u);
    for (var dz = -zr; dz <= zr; dz++) {
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                var cn = c + vec3<i32>(dx, dy, dz);
                if (params.periodic != 0u) {
                    let cells = vec3<i32>(params.grid_cells);
                    cn = select(cn, (cn + cells) % cells, periodic_axes());
                }
                let s = slot_of_cell(cn);
                var seen = false;
                for (var k = 0u; k < n; k++) {
                    seen = seen || ((*slots)[k] == s);
                }
                if (!seen) {
                    (*slots)[n] = s;
                    n++;
                }
            }
        }
    }
    return n;
}

// The sorted particles of the 3^DIM cells around `c` as index ranges [x, y), at most 27. On a
// dense grid (params.dense_grid: a slot per cell, the slot being the cell's linear index, no
// periodic axis) the three cells of a row along x have consecutive slots, so a row is one range
// (9 in 3D, 3 in 2D, rather than 27 or 9 cells); cells beyond the grid hold no particle
// (cell_of clamps) and are left out. Otherwise one range per distinct slot.
fn neighbour_ranges(c: vec3<i32>, ranges: ptr<function, array<vec2<u32>, 27>>) -> u32 {
    var n = 0u;
    if (params.dense_grid != 0u) {
        let g = vec3<i32>(params.grid_cells);
        let x0 = u32(max(c.x - 1, 0));
        let x1 = u32(min(c.x + 1, g.x - 1));
        let zr = select(0, 1, DIM == 3u);
        for (var dz = -zr; dz <= zr; dz++) {
            for (var dy = -1; dy <= 1; dy++) {
                let y = c.y + dy;
                let z = c.z + dz;
                if (y < 0 || y >= g.y || z < 0 || z >= g.z) {
                    continue;
                }
                let row = u32(y + g.y * z) * u32(g.x);
                let range = vec2<u32>(cell_start[row + x0], cell_start[row + x1 + 1u]);
                if (range.y > range.x) {
                    (*ranges)[n] = range;
                    n++;
                }
            }
        }
        return n;
    }
    var slots: array<u32, 27>;
    let n_slots = neighbour_slots(c, &slots);
    for (var s = 0u; s < n_slots; s++) {
        (*ranges)[s] = vec2<u32>(cell_start[slots[s]], cell_start[slots[s] + 1u]);
    }
    return n_slots;
}
