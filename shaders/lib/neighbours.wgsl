// Neighbour search over the cell list: the index ranges of the sorted particles in the cells
// around a point. The pass file declares `cell_start` (slot s holds the sorted particles
// cell_start[s] .. cell_start[s + 1]). Cells are the support 2h (CELL_REACH 1) or h
// (CELL_REACH 2): a point's neighbours are in the (2 CELL_REACH + 1)^DIM cells around its own.

// Rows of the neighbourhood along x, each at most two ranges (a row that wraps past the slot
// table's end); or, on a periodic grid (cells of 2h), one range per cell.
const MAX_RANGES: u32 = max(2u * u32(2 * CELL_REACH + 1) * u32(2 * CELL_REACH + 1), 27u);
alias NeighbourRanges = array<vec2<u32>, MAX_RANGES>;

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

// The distance, in cells, from a point at `f` in its cell (0 ≤ f < 1 but for rounding) to
// the cells `d` away along one axis.
fn cell_gap(f: f32, d: i32) -> f32 {
    if (d > 0) {
        return max(f32(d) - f, 0.0);
    }
    return select(0.0, max(f - f32(d + 1), 0.0), d < 0);
}

// The sorted particles within the support of `p`, and others, as index ranges [x, y).
//
// Where rows are contiguous (params.contiguous_rows: no periodic axis; the slot hash's strides
// keep the cells of any neighbourhood in distinct slots, Grid::contiguous_rows) the cells of a row along x have
// consecutive slots, so a row is one range (two where it wraps past the table's end). A row
// is cut to the cells the support's sphere reaches from `p` (none, when the row lies beyond
// it): which cells a particle's neighbours can be in depends only on where it is, so the sum
// over the neighbours keeps its order. The reach is CELL_REACH cells, a support and a margin
// of 10⁻⁴ (Grid::new), far above f32 rounding. Cells beyond the grid hold no particle
// (cell_of clamps) and are left out; a slot may hold particles of far cells, which the
// distance test rejects.
//
// Otherwise (a periodic axis: cells of 2h) one range per distinct slot of the 3^DIM cells
// around.
fn neighbour_ranges(p: Pos, ranges: ptr<function, NeighbourRanges>) -> u32 {
    let c = cell_of(p);
    var n = 0u;
    if (params.contiguous_rows != 0u) {
        let g = vec3<i32>(params.grid_cells);
        // Where `p` is in its cell, in cells (`cell_of`'s local cell).
        let cells = p.off * params.inv_cell_size;
        let f = cells - clamp(floor(cells), vec3<f32>(0.0), vec3<f32>(f32(params.cells_per_block - 1u)));
        let reach2 = f32(CELL_REACH * CELL_REACH);
        let zr = select(0, CELL_REACH, DIM == 3u);
        let table_end = params.hash_mask + 1u;
        for (var dz = -zr; dz <= zr; dz++) {
            let gz = cell_gap(f.z, dz);
            for (var dy = -CELL_REACH; dy <= CELL_REACH; dy++) {
                let y = c.y + dy;
                let z = c.z + dz;
                let gy = cell_gap(f.y, dy);
                let gap2 = gy * gy + gz * gz;
                if (y < 0 || y >= g.y || z < 0 || z >= g.z || gap2 >= reach2) {
                    continue;
                }
                let r = sqrt(reach2 - gap2);
                let first = max(i32(floor(f.x - r)), -CELL_REACH);
                let last = min(i32(floor(f.x + r)), CELL_REACH);
                let x0 = max(c.x + first, 0);
                let x1 = min(c.x + last, g.x - 1);
                let s0 = slot_of_cell(vec3<i32>(x0, y, z));
                let s1 = s0 + u32(x1 - x0) + 1u;
                if (s1 <= table_end) {
                    (*ranges)[n] = vec2<u32>(cell_start[s0], cell_start[s1]);
                    n += select(0u, 1u, (*ranges)[n].y > (*ranges)[n].x);
                } else {
                    (*ranges)[n] = vec2<u32>(cell_start[s0], cell_start[table_end]);
                    n += select(0u, 1u, (*ranges)[n].y > (*ranges)[n].x);
                    (*ranges)[n] = vec2<u32>(cell_start[0], cell_start[s1 - table_end]);
                    n += select(0u, 1u, (*ranges)[n].y > (*ranges)[n].x);
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
