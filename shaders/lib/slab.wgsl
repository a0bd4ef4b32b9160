// A subdomain's slab of the one global cell grid (issue 32; docs/scaling.md): the cell layers
// [own_lo, own_hi) along the cut axis.

// Mirrored by `layout::HaloCtl`.
struct HaloCtl {
    axis: u32,
    own_lo: u32,
    own_hi: u32,
    layers: u32,        // halo thickness in cell layers
    lower: u32,         // 1: a neighbour owns the layers below own_lo
    upper: u32,         // 1: a neighbour owns the layers from own_hi on
    capacity: u32,      // records `halo_out` holds
    lean: u32,          // 1: copies packed for the density filter (halo.wgsl `LEAN_WORDS`)
    moving: u32,        // 1: the cuts move (halo.wgsl `packs`)
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// The cell layer along the cut axis of a particle at `p`.
fn slab_layer(p: Pos, axis: u32) -> u32 {
    return u32(cell_of(p)[axis]);
}

// Whether a particle in cell layer `layer` reads nothing the exchange brings, so that its sums
// can run while the halo travels (the overlapped step, docs/scaling.md). With cells of 2h a
// particle reads the layers next to its own, and through a fixed ghost (whose values the ghost
// pass interpolates from the fluid around it) the layers next to those: as far as the halo is
// thick (`halo::halo_layers`: one layer, two with fixed ghosts). The exchange writes the halo
// layers beyond a cut and, with the migrants (which move less than a layer a step), the first
// own layer by it: a particle one layer more than the halo's thickness inside every cut that
// has a neighbour reads neither.
fn reads_no_arrival(layer: u32, ctl: HaloCtl) -> bool {
    let margin = ctl.layers + 1u;
    return layer >= ctl.own_lo + margin * ctl.lower && layer + margin * ctl.upper < ctl.own_hi;
}
