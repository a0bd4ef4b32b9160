//! What each rank reports of its part of a run (`run.json`, `wgsph bench` under mpirun): the
//! solver's subdomains fill it in, the output writes it.

/// One rank's part of a run over several ranks (`run.json`, `wgsph bench` under mpirun).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RankSummary {
    pub adapter: String,
    /// The particles this rank owned at the end.
    pub own_particles: u64,
    /// Halo copies, migrants and their bytes sent to the neighbours, per step.
    pub halo_particles_per_step: f64,
    pub migrants_per_step: f64,
    pub halo_bytes_per_step: f64,
    /// Wall seconds per step in each part of the step.
    pub seconds_per_step: Split,
    /// Times the cuts moved.
    pub rebalances: u32,
    /// Entries of this rank's slot table, sized by its own particles or cells
    /// (`Grid::for_subdomain`).
    #[serde(default)]
    pub hash_slots: u64,
    /// The share of the rank's steps that overlapped the exchange with its interior's sums
    /// (`time.overlap_exchange`, where the case allows; a resume may change it).
    #[serde(default)]
    pub overlapped: f64,
    /// The share of those steps whose exchange ended while those sums were still running:
    /// the exchange wholly hidden behind them.
    #[serde(default)]
    pub exchange_hidden: f64,
}

/// Where a subdomain's step time goes, in seconds summed over steps.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Split {
    /// The GPU up to the exchange (predictors, packing) and reading the records back.
    pub pack: f64,
    /// Swapping the records with the neighbours (waiting for the slower one included).
    pub exchange: f64,
    /// Writing the received particles and the GPU from the sort to the time step.
    pub compute: f64,
    /// Agreeing on the time step and the counts (waiting for the slowest rank included).
    pub agree: f64,
}

impl std::ops::Sub for Split {
    type Output = Split;
    fn sub(self, o: Split) -> Split {
        Split {
            pack: self.pack - o.pack,
            exchange: self.exchange - o.exchange,
            compute: self.compute - o.compute,
            agree: self.agree - o.agree,
        }
    }
}
