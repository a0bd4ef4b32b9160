//! The host's memory while a run's particles go to the GPU (issue 64, item 5): beyond the
//! case's own particles, making a solver holds at most a piece of their packed arrays at a time
//! (`sph::initial::write_in_pieces`), not a whole copy of them (it held the packed arrays, their
//! code words again and a zeroed rate array: 60 bytes a particle). Counted by this binary's
//! allocator, so the adapter's own memory (lavapipe's device memory, the queue's staging) is
//! not in it.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

/// The system's allocator, counting the bytes held now and the most held since a reset.
struct Counting;

static HELD: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn held(change: isize) {
    let now = (HELD.fetch_add(change as usize, Relaxed) as isize + change) as usize;
    PEAK.fetch_max(now, Relaxed);
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        held(layout.size() as isize);
        System.alloc(layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        held(layout.size() as isize);
        System.alloc_zeroed(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        held(-(layout.size() as isize));
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        held(new_size as isize - layout.size() as isize);
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// A fluid cube of 421 875 particles, more than six upload pieces: making its solver (the warm-up step
/// included) holds less than 16 bytes a particle more than before, less than one f32 array of
/// four components.
#[test]
fn making_a_solver_holds_no_whole_copy_of_the_particles() {
    let ctx = common::gpu();
    let set = ["particles.dx_m=0.0135", "particles.h_over_dx=1.2"].map(String::from);
    let sc = wgsph::case::load(std::path::Path::new("cases/bench_fluid_cube.toml"), &set).unwrap();
    let n = sc.particles.len();
    assert!(n > 6 * wgsph::sph::initial::UPLOAD_PIECE, "{n} particles");
    let before = HELD.load(Relaxed);
    PEAK.store(before, Relaxed);
    let solver = wgsph::sph::Solver::new(ctx, &sc).unwrap();
    let extra = (PEAK.load(Relaxed) - before) as f64 / n as f64;
    println!("{n} particles: {extra:.1} bytes a particle more at the peak");
    assert!(extra < 16.0, "{extra:.1} bytes a particle");
    drop(solver);
}
