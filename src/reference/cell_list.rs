//! Twin of shaders/cell_list.wgsl: the slot of each particle and the sorted order.

use crate::grid::Grid;

/// Slot of each particle (given as GPU block + offset), `slots` for excluded ones (a
/// subdomain's free entries, which go to `slots + 1`, are not among a twin's particles).
pub fn cell_key(grid: &Grid, pos: &[([f32; 3], [u32; 3])], excluded: &[bool]) -> Vec<u32> {
    pos.iter()
        .zip(excluded)
        .map(|((off, b), &ex)| {
            if ex {
                grid.slots
            } else {
                grid.slot_of(*off, *b)
            }
        })
        .collect()
}

/// The order the GPU sort must produce: by slot, ties by code word (`codes[i]` of the particle
/// stored at i: kind, then id, so a slot's fluid comes first); and the slot starts (slots + 3
/// entries). Excluded particles (the extra slots) are not ordered by the GPU, so callers
/// compare them as a set.
pub fn sorted_order(grid: &Grid, keys: &[u32], codes: &[u32]) -> (Vec<usize>, Vec<u32>) {
    let mut order: Vec<usize> = (0..keys.len()).collect();
    order.sort_by_key(|&i| (keys[i], codes[i]));
    let mut counts = vec![0u32; grid.slots as usize + 3];
    for &k in keys {
        counts[k as usize] += 1;
    }
    let mut start = vec![0u32; counts.len()];
    for s in 1..counts.len() {
        start[s] = start[s - 1] + counts[s - 1];
    }
    (order, start)
}
