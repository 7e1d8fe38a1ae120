//! Where worker threads go: the CPU order of each placement ([`Pin`]), and how many threads of
//! a spread placement share a physical core ([`SmtSplit`]). Pure functions of a [`Topology`].

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::Topology;

/// How worker threads are placed on logical CPUs.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Pin {
    /// Not pinned: the OS scheduler places and moves threads (the default).
    #[default]
    None,
    /// Fill the SMT siblings of one physical core before the next core: the fewest cores,
    /// sharing their caches and execution units.
    Compact,
    /// One thread per physical core first, then each core's second sibling, and so on: the
    /// most cores, with SMT only once every core has a thread.
    Spread,
}

impl Pin {
    /// Every placement, the default (`none`) first.
    pub const ALL: [Pin; 3] = [Pin::None, Pin::Compact, Pin::Spread];

    /// The name used on the command line and in output files.
    pub fn as_str(self) -> &'static str {
        match self {
            Pin::None => "none",
            Pin::Compact => "compact",
            Pin::Spread => "spread",
        }
    }
}

impl fmt::Display for Pin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A placement name that is not one of [`Pin::ALL`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown placement '{given}' (known: {known})")]
pub struct UnknownPin {
    /// What was asked for.
    pub given: String,
    /// The known names, comma-separated.
    pub known: String,
}

impl FromStr for Pin {
    type Err = UnknownPin;

    fn from_str(s: &str) -> Result<Pin, UnknownPin> {
        Pin::ALL
            .into_iter()
            .find(|p| p.as_str() == s)
            .ok_or_else(|| UnknownPin {
                given: s.to_owned(),
                known: Pin::ALL.map(Pin::as_str).join(", "),
            })
    }
}

/// How the threads of a spread placement sit on the hardware.
///
/// `physical + siblings` is the number of threads that have a logical CPU of their own,
/// min(threads, [`Topology::logical_cpus`]); threads beyond the logical CPUs are
/// oversubscription and counted in neither (each time-shares a CPU with an earlier thread,
/// `threads − physical − siblings` of them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SmtSplit {
    /// Threads alone on their physical core: min(threads, physical cores).
    pub physical: usize,
    /// Threads on an SMT sibling of a core that already runs one of them.
    pub siblings: usize,
}

impl Topology {
    /// The logical CPUs worker threads 0, 1, 2, … are pinned to under `pin` (thread `i` to
    /// `order[i % order.len()]`), every usable CPU once; `None` for [`Pin::None`] (the OS
    /// decides) and where not even the CPU numbers are known.
    ///
    /// Cores come in [`Topology::siblings`]' order: by package, then core id. `compact`
    /// takes each core's siblings in turn; `spread` takes the first sibling of every core,
    /// then the second of every core that has one, and so on. `spread` fills one package's
    /// cores before the next package's: it does not alternate sockets, so a few threads on a
    /// two-socket machine share one socket's L3 and memory. Where the siblings are unknown
    /// (no readable sysfs), both are the usable CPUs in ascending order.
    pub fn order(&self, pin: Pin) -> Option<Vec<usize>> {
        if pin == Pin::None || self.cpus.is_empty() {
            return None;
        }
        if self.siblings.is_empty() {
            return Some(self.cpus.clone());
        }
        Some(match pin {
            Pin::None | Pin::Compact => self.siblings.concat(),
            Pin::Spread => {
                let rounds = self.siblings.iter().map(Vec::len).max().unwrap_or(0);
                (0..rounds)
                    .flat_map(|k| self.siblings.iter().filter_map(move |core| core.get(k)))
                    .copied()
                    .collect()
            }
        })
    }

    /// How `threads` worker threads placed by [`Pin::Spread`] split between physical cores
    /// and SMT siblings (see [`SmtSplit`]); `None` where the physical cores are unknown.
    pub fn split(&self, threads: usize) -> Option<SmtSplit> {
        let cores = self.physical_cores?;
        let physical = threads.min(cores);
        let placed = threads.min(self.logical_cpus);
        Some(SmtSplit {
            physical,
            siblings: placed.saturating_sub(physical),
        })
    }

    /// Whether `threads` worker threads need SMT siblings, though not more than the logical
    /// CPUs: physical cores < `threads` ≤ logical CPUs. Beyond the logical CPUs it is `false`
    /// (that is oversubscription). `None` where the physical cores are unknown.
    pub fn is_smt(&self, threads: usize) -> Option<bool> {
        let cores = self.physical_cores?;
        Some(cores < threads && threads <= self.logical_cpus)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::fake::{FakeSys, smt_4x2, two_sockets};

    fn split(physical: usize, siblings: usize) -> Option<SmtSplit> {
        Some(SmtSplit { physical, siblings })
    }

    #[test]
    fn every_placement_parses_back_from_its_name_and_unknown_names_list_the_three() {
        for pin in Pin::ALL {
            assert_eq!(pin.to_string().parse::<Pin>(), Ok(pin));
            let json = serde_json::to_string(&pin).unwrap();
            assert_eq!(json, format!("\"{}\"", pin.as_str()));
        }
        let err = "scatter".parse::<Pin>().unwrap_err();
        assert_eq!(
            err.to_string(),
            "unknown placement 'scatter' (known: none, compact, spread)"
        );
    }

    #[test]
    fn compact_fills_a_cores_siblings_first_and_spread_one_thread_per_core_first() {
        let t = Topology::read(smt_4x2().root(), &[0, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(t.order(Pin::Compact), Some(vec![0, 4, 1, 5, 2, 6, 3, 7]));
        assert_eq!(t.order(Pin::Spread), Some(vec![0, 1, 2, 3, 4, 5, 6, 7]));
        assert_eq!(t.order(Pin::None), None);
    }

    #[test]
    fn on_two_sockets_both_orders_fill_package_0_before_package_1() {
        let t = Topology::read(two_sockets().root(), &[0, 1, 2, 3]);
        assert_eq!(t.order(Pin::Compact), Some(vec![0, 2, 1, 3]));
        assert_eq!(t.order(Pin::Spread), Some(vec![0, 2, 1, 3]));
    }

    #[test]
    fn orders_keep_to_the_affinity_mask() {
        let t = Topology::read(smt_4x2().root(), &[0, 1, 4, 6]);
        assert_eq!(t.order(Pin::Compact), Some(vec![0, 4, 1, 6]));
        assert_eq!(t.order(Pin::Spread), Some(vec![0, 1, 6, 4]));
    }

    #[test]
    fn without_siblings_both_orders_are_the_cpus_ascending() {
        let sys = FakeSys::new();
        let t = Topology::read(&sys.root().join("absent"), &[3, 1, 2]);
        assert_eq!(t.order(Pin::Compact), Some(vec![1, 2, 3]));
        assert_eq!(t.order(Pin::Spread), Some(vec![1, 2, 3]));
        assert_eq!(t.order(Pin::None), None);
        assert_eq!((t.split(2), t.is_smt(2)), (None, None));
        assert_eq!(Topology::default().order(Pin::Compact), None);
    }

    #[test]
    fn threads_beyond_the_cores_land_on_siblings_and_beyond_the_cpus_on_neither() {
        let t = Topology::read(smt_4x2().root(), &[0, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(t.split(0), split(0, 0));
        assert_eq!(t.split(1), split(1, 0));
        assert_eq!(t.split(4), split(4, 0));
        assert_eq!(t.split(6), split(4, 2));
        assert_eq!(t.split(8), split(4, 4));
        // Two threads oversubscribed.
        assert_eq!(t.split(10), split(4, 4));
        let smt: Vec<Option<bool>> = [1, 4, 5, 8, 9].map(|n| t.is_smt(n)).to_vec();
        assert_eq!(smt, [false, false, true, true, false].map(Some).to_vec());
    }

    #[test]
    fn one_thread_per_core_never_needs_smt() {
        let t = Topology::read(two_sockets().root(), &[0, 1, 2, 3]);
        assert_eq!(t.split(4), split(4, 0));
        assert_eq!(t.split(5), split(4, 0));
        assert_eq!(t.is_smt(4), Some(false));
        assert_eq!(t.is_smt(5), Some(false));
    }

    #[test]
    fn a_mask_with_some_siblings_counts_only_those() {
        // Cores 0 and 1 with both threads, core 2 with one: 3 cores, 5 CPUs.
        let t = Topology::read(smt_4x2().root(), &[0, 1, 2, 4, 5]);
        assert_eq!(t.order(Pin::Spread), Some(vec![0, 1, 2, 4, 5]));
        assert_eq!(t.split(4), split(3, 1));
        assert_eq!(t.split(5), split(3, 2));
        assert_eq!(t.is_smt(3), Some(false));
        assert_eq!(t.is_smt(5), Some(true));
    }
}
