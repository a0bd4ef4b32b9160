// A particle's id and what is indexed by it (the pass declares `code`). With WIDE_IDS (runs of
// 2^28 particles or more, `layout::IdSplit`) the code word keeps the id's low ID_LOW_BITS bits
// and the rest is the word after the n code words, which the sort gathers with them.

fn particle_id(i: u32) -> u32 {
    if (WIDE_IDS) {
        return whole_id(code[i], code[params.n_particles + i]);
    }
    return code[i] & ID_MASK;
}

// Index of solid particle i in the solid arrays: id − params.solid_id_base.
fn solid_slot(i: u32) -> u32 {
    return particle_id(i) - params.solid_id_base;
}
