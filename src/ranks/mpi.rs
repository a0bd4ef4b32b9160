//! [`Ranks`] over MPI (rsmpi, the system's MPI library). A rank that fails aborts the whole
//! job (`MPI_Abort`) after saying which rank and why, so the others do not wait for it forever.

use anyhow::{bail, Result};
use mpi::collective::{CommunicatorCollectives, SystemOperation};
use mpi::environment::Universe;
use mpi::point_to_point::{Destination, Source};
use mpi::topology::{Communicator, SimpleCommunicator};

use super::Ranks;

pub struct Mpi {
    world: SimpleCommunicator,
    // Finalizes MPI when dropped: declared last, dropped after the communicator.
    _universe: Universe,
}

impl Mpi {
    /// Initializes MPI; `None` when it was already initialized in this process.
    pub fn init() -> Option<Self> {
        let universe = mpi::initialize()?;
        Some(Self {
            world: universe.world(),
            _universe: universe,
        })
    }
}

impl Ranks for Mpi {
    fn rank(&self) -> usize {
        self.world.rank() as usize
    }

    fn size(&self) -> usize {
        self.world.size() as usize
    }

    fn abort(&self, why: &anyhow::Error) -> ! {
        eprintln!("rank {} of {}: {why:#}", self.rank(), self.size());
        // mpirun forwards a rank's output on its own schedule, and the abort tears the job
        // down at once: a message every rank printed before aborting was lost in one job of
        // four (issue 64). A moment's wait lets it through; a job that is failing loses
        // nothing by it.
        let _ = std::io::Write::flush(&mut std::io::stderr());
        std::thread::sleep(std::time::Duration::from_millis(500));
        self.world.abort(1)
    }

    fn min(&self, x: f64) -> f64 {
        let mut out = x;
        self.world
            .all_reduce_into(&x, &mut out, SystemOperation::min());
        out
    }

    fn sum_in_rank_order(&self, x: &[f64]) -> Vec<f64> {
        let mut all = vec![0.0; x.len() * self.size()];
        self.world.all_gather_into(x, &mut all[..]);
        // One part per rank (none when `x` is empty: the sum is empty too).
        let parts: Vec<Vec<f64>> = all.chunks(x.len().max(1)).map(<[f64]>::to_vec).collect();
        super::sum_in_order(&parts)
    }

    fn exchange(&self, sends: &[(usize, Vec<u8>)], from: &[usize]) -> Result<Vec<Vec<u8>>> {
        for &(to, _) in sends {
            if to >= self.size() || to == self.rank() {
                bail!(
                    "rank {} cannot send to rank {to} of {}",
                    self.rank(),
                    self.size()
                );
            }
        }
        // Every send is posted before any receive waits, so neighbours swapping both ways
        // cannot deadlock; a receive takes a message of any length (matched probe).
        mpi::request::scope(|scope| {
            let requests: Vec<_> = sends
                .iter()
                .map(|(to, bytes)| {
                    self.world
                        .process_at_rank(*to as i32)
                        .immediate_send(scope, &bytes[..])
                })
                .collect();
            let received = from
                .iter()
                .map(|&r| self.world.process_at_rank(r as i32).receive_vec::<u8>().0)
                .collect();
            for r in requests {
                r.wait();
            }
            Ok(received)
        })
    }
}
