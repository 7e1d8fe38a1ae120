//! Checking a sweep's parameters ([`SweepParams`], recorded in `meta.json`): the command line
//! and `--resume` refuse the same things.

pub use crate::results::params::SweepParams;

impl SweepParams {
    /// Checks the parameters as the command line does: every list non-empty, sorted, free of
    /// repeats and inside its documented range ([`crate::limits`]), and the fake lists (if
    /// any) readable. `--resume` runs it on a `meta.json` that may have been edited.
    pub fn validate(&self) -> anyhow::Result<()> {
        use crate::limits::{self, check};
        fn list(what: &'static str, values: &[usize], max: usize) -> anyhow::Result<()> {
            if values.is_empty() {
                anyhow::bail!("{what}: the list is empty");
            }
            if values.windows(2).any(|w| w[0] >= w[1]) {
                let shown: Vec<String> = values.iter().map(ToString::to_string).collect();
                anyhow::bail!(
                    "{what}: the list {} is not sorted without repeats",
                    shown.join(",")
                );
            }
            for &v in values {
                check(what, v, 1, max)?;
            }
            Ok(())
        }
        if self.strategies.is_empty()
            || self.presets.is_empty()
            || self.neighbors.is_empty()
            || self.pin.is_empty()
        {
            anyhow::bail!("strategies, presets, neighbors and pin must each name at least one");
        }
        list("cores", &self.cores, limits::MAX_CORES)?;
        list("chunks", &self.chunks, limits::MAX_CHUNKS)?;
        list("n", &self.n, limits::MAX_PARTICLES)?;
        check("steps", self.steps, 1, limits::MAX_STEPS)?;
        check("trials", self.trials, 1, limits::MAX_TRIALS)?;
        check("warmup", self.warmup, 0, limits::MAX_WARMUP)?;
        check("confirm-rounds", self.confirm_rounds, 0, limits::MAX_TRIALS)?;

        let lists = [
            self.presets.len(),
            self.neighbors.len(),
            self.n.len(),
            self.strategies.len(),
            self.cores.len(),
            self.chunks.len(),
            self.pin.len(),
        ];
        let cells = lists.iter().try_fold(1usize, |a, &b| a.checked_mul(b));
        match cells {
            Some(c) if c <= limits::MAX_CELLS => {}
            _ => anyhow::bail!(
                "the sweep would have more than {} cells (presets × neighbors × n × strategies \
                 × cores × chunks × pin); split it into smaller sweeps",
                limits::MAX_CELLS
            ),
        }
        super::timing::Timing::new(
            self.fake_timings.as_deref(),
            self.fake_contention.as_deref(),
        )?;
        if let Some(shard) = self.shard {
            if self.pass_cost || self.anchor.is_some() {
                anyhow::bail!(
                    "--shard {shard} with --pass-cost or --anchor: a shard holds part of the \
                     cells, and a merge of shards is not one machine's run; measure them in a \
                     sweep of their own"
                );
            }
            let whole = super::plan::Plan::whole(self);
            if whole.shard(shard).cells.is_empty() {
                let parts = match whole.non_reference_cells() {
                    0 => whole.groups.len(),
                    k => k,
                };
                anyhow::bail!(
                    "--shard {shard}: shard {} would have no cells: the plan has {parts} to \
                     deal (cells besides the seq references, or groups when seq is all it \
                     measures), so split it into at most {parts} shards",
                    shard.index
                );
            }
        }
        if let Some(path) = &self.anchor {
            super::anchor::check(self, path)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_solver::models::Preset;
    use sph_solver::sph::neighbors::NeighborMode;
    use sph_strategies::StrategyName;

    fn example() -> SweepParams {
        SweepParams {
            strategies: StrategyName::ALL.to_vec(),
            presets: vec![Preset::Seed, Preset::Cpp],
            neighbors: vec![NeighborMode::Grid],
            n: vec![60, 1000],
            seed: 7,
            ..SweepParams::small()
        }
    }

    #[test]
    fn parameters_round_trip_through_json_by_name() {
        let p = example();
        let json = serde_json::to_string(&p).unwrap();
        assert!(json.contains(r#""presets":["seed","cpp"]"#), "{json}");
        assert!(json.contains(r#""neighbors":["grid"]"#), "{json}");
        assert!(json.contains(r#""rayon-chunks""#), "{json}");
        assert!(!json.contains("fake_timings"), "{json}");
        assert_eq!(serde_json::from_str::<SweepParams>(&json).unwrap(), p);
    }

    #[test]
    fn validation_refuses_what_the_command_line_refuses() {
        assert!(example().validate().is_ok());
        let mut p = example();
        p.cores = vec![0];
        assert!(
            p.validate()
                .unwrap_err()
                .to_string()
                .contains("cores must be between 1")
        );
        let mut p = example();
        p.trials = 0;
        assert!(p.validate().unwrap_err().to_string().contains("trials"));
        let mut p = example();
        p.chunks = vec![5, 2];
        assert!(p.validate().unwrap_err().to_string().contains("not sorted"));
        let mut p = example();
        p.n = vec![];
        assert!(p.validate().unwrap_err().to_string().contains("empty"));
        let mut p = example();
        p.fake_contention = Some("2".into());
        assert!(
            p.validate()
                .unwrap_err()
                .to_string()
                .contains("--fake-contention")
        );
    }

    #[test]
    fn an_empty_shard_is_refused_naming_the_most_shards_the_plan_allows() {
        use crate::results::shard::Shard;
        let mut p = example();
        p.strategies = vec![StrategyName::StdStatic];
        p.presets = vec![Preset::Seed];
        p.n = vec![60];
        p.cores = vec![1, 2];
        p.shard = Some(Shard::new(2, 2).unwrap());
        assert!(p.validate().is_ok());
        p.shard = Some(Shard::new(3, 3).unwrap());
        let err = p.validate().unwrap_err().to_string();
        assert!(
            err.contains("--shard 3/3") && err.contains("at most 2 shards"),
            "{err}"
        );
    }

    #[test]
    fn an_unpinned_plan_has_the_fingerprint_it_had_before_pin_existed() {
        let p = example();
        let json = serde_json::to_string(&p).unwrap();
        assert!(!json.contains("\"pin\""), "{json}");
        let mut pinned = example();
        pinned.pin = vec![crate::topology::Pin::None, crate::topology::Pin::Spread];
        assert!(
            serde_json::to_string(&pinned)
                .unwrap()
                .contains("\"pin\":[\"none\",\"spread\"]")
        );
        assert_ne!(p.fingerprint(), pinned.fingerprint());
    }

    #[test]
    fn the_fingerprint_ignores_the_shard_and_nothing_else() {
        use crate::results::shard::Shard;
        let p = example();
        let mut shard = example();
        shard.shard = Some(Shard::new(2, 3).unwrap());
        assert_eq!(p.fingerprint(), shard.fingerprint());
        assert_eq!(p.fingerprint().len(), 16);
        let mut other = example();
        other.steps += 1;
        assert_ne!(p.fingerprint(), other.fingerprint());
        let mut other = example();
        other.seed += 1;
        assert_ne!(p.fingerprint(), other.fingerprint());
    }

    #[test]
    fn an_unknown_name_in_json_is_an_error_listing_the_known_ones() {
        let json = serde_json::to_string(&example())
            .unwrap()
            .replace("\"grid\"", "\"octree\"");
        let err = serde_json::from_str::<SweepParams>(&json).unwrap_err();
        assert!(err.to_string().contains("unknown name 'octree'"), "{err}");
        assert!(err.to_string().contains("all-pairs"), "{err}");
    }
}
