//! A shard of a sweep's plan (`sweep --shard I/K`): which of K parts of one plan a results
//! directory holds. Which cells belong to a shard is the plan's rule
//! ([`crate::sweep::plan::Plan::shard`]); this is only the pair, as `meta.json` records it.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::limits::MAX_SHARDS;

/// Shard `index` of `count` (1 ≤ index ≤ count ≤ [`MAX_SHARDS`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Shard {
    /// Which part, from 1.
    pub index: usize,
    /// How many parts the plan is split into.
    pub count: usize,
}

/// A `--shard` value that is not `I/K` with 1 ≤ I ≤ K ≤ [`MAX_SHARDS`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("--shard '{0}': expected I/K with 1 ≤ I ≤ K ≤ {MAX_SHARDS} (shard I of K, e.g. 2/3)")]
pub struct BadShard(pub String);

impl Shard {
    /// The pair, if 1 ≤ `index` ≤ `count` ≤ [`MAX_SHARDS`].
    pub fn new(index: usize, count: usize) -> Result<Shard, BadShard> {
        if index >= 1 && index <= count && count <= MAX_SHARDS {
            Ok(Shard { index, count })
        } else {
            Err(BadShard(format!("{index}/{count}")))
        }
    }
}

impl FromStr for Shard {
    type Err = BadShard;

    fn from_str(s: &str) -> Result<Shard, BadShard> {
        let bad = || BadShard(s.to_owned());
        let (i, k) = s.split_once('/').ok_or_else(bad)?;
        let number = |t: &str| t.trim().parse::<usize>().map_err(|_| bad());
        Shard::new(number(i)?, number(k)?).map_err(|_| bad())
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shard_parses_as_i_of_k_and_prints_back_the_same() {
        let s: Shard = "2/3".parse().unwrap();
        assert_eq!(s, Shard { index: 2, count: 3 });
        assert_eq!(s.to_string(), "2/3");
        assert_eq!(
            " 1 / 1 ".trim().parse::<Shard>().unwrap(),
            Shard::new(1, 1).unwrap()
        );
    }

    #[test]
    fn zero_an_index_beyond_the_count_and_too_many_shards_are_refused() {
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", "-1/2", "1/1025", ""] {
            let err = bad.parse::<Shard>().unwrap_err();
            assert!(err.to_string().contains("expected I/K"), "{bad}: {err}");
        }
        assert!("1024/1024".parse::<Shard>().is_ok());
    }
}
