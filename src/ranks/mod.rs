//! The ranks of a run (issue 32): what a subdomain needs from the others each step — the
//! smallest time step, loads summed in a fixed rank order, its halo and migrants swapped with
//! its neighbours — behind one trait, so the solver does not know whether it runs alone
//! ([`Single`]) or under MPI (`Mpi`, feature `mpi`: rsmpi over the system's MPI).

use anyhow::Result;

mod summary;
pub use summary::{RankSummary, Split};

#[cfg(feature = "mpi")]
mod mpi;
#[cfg(feature = "mpi")]
pub use self::mpi::Mpi;

pub trait Ranks {
    /// This rank, 0 ..= size − 1.
    fn rank(&self) -> usize;

    fn size(&self) -> usize;

    /// The smallest `x` over all ranks (exact: a minimum does not depend on the order).
    fn min(&self, x: f64) -> f64;

    /// The element-wise sum of every rank's `x` (same length everywhere), added in rank order
    /// 0, 1, 2, … on every rank: the same bits whatever order the messages arrive in.
    fn sum_in_rank_order(&self, x: &[f64]) -> Vec<f64>;

    /// Every rank's `x` (same length everywhere), in rank order, on every rank (exact: each
    /// value is added to zeros only).
    fn gather(&self, x: &[f64]) -> Vec<Vec<f64>> {
        let k = x.len();
        let mut mine = vec![0.0; k * self.size()];
        mine[self.rank() * k..(self.rank() + 1) * k].copy_from_slice(x);
        let all = self.sum_in_rank_order(&mine);
        (0..self.size())
            .map(|r| all[r * k..(r + 1) * k].to_vec())
            .collect()
    }

    /// Sends each `(rank, bytes)` and returns what each of `from` sent this rank, in `from`'s
    /// order. Every rank must call it, and each rank in `from` must send to this one.
    fn exchange(&self, sends: &[(usize, Vec<u8>)], from: &[usize]) -> Result<Vec<Vec<u8>>>;

    /// Says which rank failed and why on standard error, then ends every rank of the job (the
    /// others would wait for this one forever).
    fn abort(&self, why: &anyhow::Error) -> !;

    /// Returns once every rank has called it.
    fn barrier(&self) {
        self.min(0.0);
    }

    /// Every rank's `text` in rank order, on rank 0; the other ranks get nothing.
    fn gather_text(&self, text: &str) -> Result<Vec<String>> {
        let others: Vec<usize> = (1..self.size()).collect();
        let received = match self.rank() {
            0 => self.exchange(&[], &others)?,
            _ => {
                self.exchange(&[(0, text.as_bytes().to_vec())], &[])?;
                return Ok(Vec::new());
            }
        };
        let texts = received
            .iter()
            .map(|b| String::from_utf8_lossy(b).into_owned());
        Ok(std::iter::once(text.to_string()).chain(texts).collect())
    }
}

/// How many ranks the launcher started this process among: OpenMPI's `OMPI_COMM_WORLD_SIZE`,
/// else MPICH's and Slurm's `PMI_SIZE`; `None` outside a launcher.
pub fn launched_size() -> Option<usize> {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"]
        .iter()
        .find_map(|v| std::env::var(v).ok()?.trim().parse().ok())
}

/// Refuses a launch over several ranks in a build without MPI (N copies would each run the
/// whole case into the same folder). One rank under a launcher runs as without it.
pub fn refuse_several_ranks(command: &str) -> Result<()> {
    match launched_size() {
        Some(n) if n > 1 && !cfg!(feature = "mpi") => anyhow::bail!(
            "`wgsph {command}` was launched on {n} ranks, but this wgsph was built without \
             MPI: build it with `cargo build --release --features mpi` (README: several ranks)"
        ),
        _ => Ok(()),
    }
}

/// A run on one rank: nothing to combine, nobody to swap with.
pub struct Single;

impl Ranks for Single {
    fn rank(&self) -> usize {
        0
    }

    fn size(&self) -> usize {
        1
    }

    fn min(&self, x: f64) -> f64 {
        x
    }

    fn sum_in_rank_order(&self, x: &[f64]) -> Vec<f64> {
        x.to_vec()
    }

    fn exchange(&self, sends: &[(usize, Vec<u8>)], from: &[usize]) -> Result<Vec<Vec<u8>>> {
        anyhow::ensure!(
            sends.is_empty() && from.is_empty(),
            "a single rank has no neighbours to swap halos with"
        );
        Ok(Vec::new())
    }

    fn abort(&self, why: &anyhow::Error) -> ! {
        eprintln!("error: {why:#}");
        std::process::exit(1)
    }
}

/// Adds `parts` (one per rank, in rank order) element by element, in that order.
pub fn sum_in_order(parts: &[Vec<f64>]) -> Vec<f64> {
    let mut sum = parts.first().cloned().unwrap_or_default();
    for p in &parts[1.min(parts.len())..] {
        for (s, x) in sum.iter_mut().zip(p) {
            *s += x;
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sum_goes_in_rank_order() {
        // Left to right, 1e16 + 1 rounds to 1e16, then − 1e16 + 1 gives 1; added as
        // 1e16 − 1e16 + 1 + 1 it would be 2: the order is part of the result.
        let parts = vec![
            vec![1e16, 1.0],
            vec![1.0, 2.0],
            vec![-1e16, 3.0],
            vec![1.0, 4.0],
        ];
        assert_eq!(sum_in_order(&parts), vec![1.0, 10.0]);
        assert_eq!(sum_in_order(&[]), Vec::<f64>::new());
    }

    #[test]
    fn a_single_rank_combines_nothing() {
        let one = Single;
        assert_eq!((one.rank(), one.size(), one.min(2.5)), (0, 1, 2.5));
        assert_eq!(one.sum_in_rank_order(&[1.0, 2.0]), vec![1.0, 2.0]);
        assert_eq!(one.gather(&[3.0, -0.5]), vec![vec![3.0, -0.5]]);
        assert!(one.exchange(&[], &[]).unwrap().is_empty());
        assert!(one.exchange(&[(1, vec![0])], &[1]).is_err());
    }
}
