// Neighbour search over the cell list: the index ranges of the sorted particles in the cells
// around a point. The pass file declares `cell_start` (slot s holds the sorted particles
// cell_start[s] .. cell_start[s + 1]) and `code`. Cells are the support 2h (CELL_REACH 1) or h
// (CELL_REACH 2): a point's neighbours are in the (2 CELL_REACH + 1)^DIM cells around its own.
//
// A slot's particles are ordered by code word (cell_list.wgsl's `rank_in_cell`), so its fluid,
// of kind 0, comes first: a sum over the fluid alone walks the slots of `neighbour_rows` one by
// one (`SlotWalk`) and leaves each at its first particle of another kind, never testing the walls around
// (most of a wall particle's neighbours, and most particles of a tank are walls), as
// DualSPHysics' cell lists keep boundary and fluid particles apart.

// Rows of the neighbourhood along x, each at most two ranges (a row that wraps past the slot
// table's end or a periodic x axis); or, on a periodic grid with a hashed table (cells of 2h),
// one range per cell.
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
                if (any_periodic()) {
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

// The `len` cells from `first` along x, whose slots follow each other (modulo the table's
// size), as one run of slots or, where they wrap past the table's end, two. Returns the new
// count of runs. Both entries are written and the count chosen by `select`: a branch here,
// inlined in every neighbour loop, slows them on SIMD adapters (docs/performance.md).
fn push_row(rows: ptr<function, NeighbourRanges>, n: u32, first: vec3<i32>, len: u32) -> u32 {
    let table_end = params.hash_mask + 1u;
    let s0 = slot_of_cell(first);
    let s1 = s0 + len;
    let wraps = s1 > table_end;
    (*rows)[n] = vec2<u32>(s0, min(s1, table_end));
    (*rows)[n + 1u] = vec2<u32>(0u, select(0u, s1 - table_end, wraps));
    return n + select(1u, 2u, wraps);
}

// The slots of the cells around `p` that can hold particles within its support, as runs of
// consecutive slots [x, y).
//
// Where rows are contiguous (params.contiguous_rows: the slot hash's strides keep the cells of
// any neighbourhood in distinct slots, Grid::contiguous_rows) the cells of a row along x have
// consecutive slots, so a row is one run (two where it wraps past the table's end). A row
// is cut to the cells the support's sphere reaches from `p` (none, when the row lies beyond
// it): which cells a particle's neighbours can be in depends only on where it is, so the sum
// over the neighbours keeps its order. The reach is CELL_REACH cells, a support and a margin
// of 10⁻⁴ (Grid::new), far above f32 rounding. Cells beyond the grid hold no particle
// (cell_of clamps) and are left out; a slot may hold particles of far cells, which the
// distance test rejects.
//
// On a periodic axis the rows wrap: y and z to the period's other side, and a row along a
// periodic x in two (the cells past the period's end are the first ones). Rows then exist
// only where every cell has its own slot (the linear index, below the table's end), so a row
// is still at most two runs; a period's cells may be wider than the reach's, which only
// makes the cut keep more.
//
// Otherwise (a periodic grid with a hashed table: cells of 2h) one run per distinct slot of
// the 3^DIM cells around.
fn neighbour_rows(p: Pos, rows: ptr<function, NeighbourRanges>) -> u32 {
    let c = cell_of(p);
    var n = 0u;
    if (params.contiguous_rows != 0u) {
        let g = vec3<i32>(params.grid_cells);
        let wraps = periodic_axes();
        // Where `p` is in its cell, in cells (`cell_of`'s local cell).
        let cells = p.off * params.inv_cell_size;
        let f = cells - clamp(floor(cells), vec3<f32>(0.0), vec3<f32>(f32(params.cells_per_block - 1u)));
        let reach2 = f32(CELL_REACH * CELL_REACH);
        let zr = select(0, CELL_REACH, DIM == 3u);
        for (var dz = -zr; dz <= zr; dz++) {
            let gz = cell_gap(f.z, dz);
            for (var dy = -CELL_REACH; dy <= CELL_REACH; dy++) {
                let gy = cell_gap(f.y, dy);
                let gap2 = gy * gy + gz * gz;
                var yz = vec2<i32>(c.y + dy, c.z + dz);
                yz = select(yz, (yz + g.yz) % g.yz, wraps.yz);
                if (any(yz < vec2<i32>(0)) || any(yz >= g.yz) || gap2 >= reach2) {
                    continue;
                }
                let r = sqrt(reach2 - gap2);
                var x0 = c.x + max(i32(floor(f.x - r)), -CELL_REACH);
                var x1 = c.x + min(i32(floor(f.x + r)), CELL_REACH);
                if (wraps.x && x0 < 0) {
                    n = push_row(rows, n, vec3<i32>(x0 + g.x, yz), u32(-x0));
                    x0 = 0;
                } else if (wraps.x && x1 >= g.x) {
                    n = push_row(rows, n, vec3<i32>(0, yz), u32(x1 - g.x + 1));
                    x1 = g.x - 1;
                }
                x0 = max(x0, 0);
                x1 = min(x1, g.x - 1);
                // (Empty only for a point past the far face, in the last cell: x0 = g.x.)
                if (x0 <= x1) {
                    n = push_row(rows, n, vec3<i32>(x0, yz), u32(x1 - x0 + 1));
                }
            }
        }
        return n;
    }
    var slots: array<u32, 27>;
    let n_slots = neighbour_slots(c, &slots);
    for (var s = 0u; s < n_slots; s++) {
        (*rows)[s] = vec2<u32>(slots[s], slots[s] + 1u);
    }
    return n_slots;
}

// The sorted particles of the cells around `p` (`neighbour_rows`), as index ranges [x, y): a
// run of slots is one range of the sorted arrays; empty ones are dropped.
fn neighbour_ranges(p: Pos, ranges: ptr<function, NeighbourRanges>) -> u32 {
    let n_rows = neighbour_rows(p, ranges);
    var n = 0u;
    for (var r = 0u; r < n_rows; r++) {
        let run = (*ranges)[r];
        (*ranges)[n] = vec2<u32>(cell_start[run.x], cell_start[run.y]);
        n += select(0u, 1u, (*ranges)[n].y > (*ranges)[n].x);
    }
    return n;
}

// A walk over the particles of the slots of `neighbour_rows`, slot by slot in the rows' order,
// each slot's from its first: the fluid alone (a slot is left at its first particle of another
// kind), or every kind (a body particle's sums, in the same order). The sums over the fluid
// alone, and a body particle's, loop so:
//     var rows: NeighbourRanges;
//     var w = slot_walk(p, &rows, every_kind);
//     for (; walk_on(&w, &rows); w.j++) { let j = w.j; ... }
struct SlotWalk {
    n_rows: u32,
    every_kind: bool,
    // The row and the slot walked, the particle visited and the end of the slot's particles.
    row: u32,
    slot: u32,
    j: u32,
    end: u32,
}

fn slot_walk(p: Pos, rows: ptr<function, NeighbourRanges>, every_kind: bool) -> SlotWalk {
    let n_rows = neighbour_rows(p, rows);
    let slot = (*rows)[0].x;
    return SlotWalk(n_rows, every_kind, 0u, slot, cell_start[slot], cell_start[slot + 1u]);
}

// Whether the walk has a particle left, `w.j`: the one it is at if the walk takes it, otherwise
// the first it takes in the slots after.
fn walk_on(w: ptr<function, SlotWalk>, rows: ptr<function, NeighbourRanges>) -> bool {
    while ((*w).row < (*w).n_rows) {
        if ((*w).j < (*w).end && ((*w).every_kind || code_kind(code[(*w).j]) == KIND_FLUID)) {
            return true;
        }
        (*w).slot++;
        if ((*w).slot >= (*rows)[(*w).row].y) {
            (*w).row++;
            if ((*w).row >= (*w).n_rows) {
                break;
            }
            (*w).slot = (*rows)[(*w).row].x;
        }
        (*w).j = cell_start[(*w).slot];
        (*w).end = cell_start[(*w).slot + 1u];
    }
    return false;
}
