//! Ordering cells and deciding which is fastest: every comparison of two cells pairs their
//! runs by round ([`order`]); one is called faster only where the interval of the ratio
//! excludes 1. [`verdict`] decides the fastest of a core count's cells; the helpers below word
//! a verdict and name cells. The findings ([`super::findings`]), the placements, the rank
//! shift and the machine comparison all read these, so they sit below all of them.

use super::cell::Best;
use super::numbers::{interval, secs};
use sph_harness::results::intervals::{MIN_ROUNDS, Ratio};
use sph_strategies::StrategyName;

/// A strategy's best cell at one core count (boxed: verdicts hold several).
pub type Entry = (StrategyName, Box<Best>);

/// Why two cells cannot be ordered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unknown {
    /// They share this many rounds, fewer than [`MIN_ROUNDS`]: no interval.
    Rounds(usize),
    /// Their runs do not pair (other rounds: another shard or phase, or a sweep whose rounds
    /// do not pair).
    Unpaired,
}

/// What the paired rounds say about one cell `a` against another `b`. The ratio is `b`'s
/// time over `a`'s, paired by round: how many times faster `a` is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Order {
    /// `a` is faster: the interval lies above 1.
    AFaster(Ratio),
    /// `b` is faster: the interval lies below 1.
    BFaster(Ratio),
    /// The interval contains 1: not distinguishable.
    Unresolved(Ratio),
    /// No interval.
    Unknown(Unknown),
}

/// `a` against `b`, by their runs paired by round (see [`Order`]).
pub fn order(a: &Best, b: &Best) -> Order {
    // A strategy the confirmation left out (it lost by more than twice in the grid) has only
    // grid runs: it pairs with the other's runs of the grid's rounds.
    let paired = b.runs.ratio(&a.runs).or_else(|| b.grid().ratio(a.grid()));
    let Some(r) = paired else {
        return Order::Unknown(Unknown::Unpaired);
    };
    match r.interval {
        None => Order::Unknown(Unknown::Rounds(r.rounds)),
        Some(_) if !r.resolved() => Order::Unresolved(r),
        Some(_) if r.value > 1.0 => Order::AFaster(r),
        Some(_) => Order::BFaster(r),
    }
}

impl Order {
    /// Whether the order is resolved (either way).
    pub fn resolved(&self) -> bool {
        matches!(self, Order::AFaster(_) | Order::BFaster(_))
    }
}

/// Whether a cell was measured without contention.
pub fn calm(b: &Best) -> bool {
    !b.contended
}

/// What can be said about the fastest strategy at one core count, from the cells measured
/// without contention (lowest mean first).
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// Only one cell.
    Only(Entry),
    /// Some cell cannot be ordered against the lowest mean.
    Unknown {
        /// The lowest mean.
        lowest: Entry,
        /// The first cell (by mean) it cannot be ordered against.
        against: Entry,
        /// Why.
        why: Unknown,
    },
    /// The lowest mean is faster than every other cell, each by its paired rounds.
    Fastest {
        /// The fastest.
        winner: Entry,
        /// The second lowest mean.
        runner_up: Entry,
        /// How many times faster the winner is than the runner-up.
        by: Ratio,
    },
    /// These cells are not distinguishable from the lowest mean (it first).
    Tied {
        /// The lowest mean and the cells not distinguishable from it.
        tied: Vec<Entry>,
        /// How many are slower by their paired rounds.
        slower: usize,
    },
}

/// The verdict on `trusted` (lowest mean first); `None` when it is empty.
pub fn verdict(trusted: &[Entry]) -> Option<Verdict> {
    let first = trusted.first()?.clone();
    let Some(runner_up) = trusted.get(1).cloned() else {
        return Some(Verdict::Only(first));
    };
    let mut tied = vec![first.clone()];
    let mut by = None;
    for other in &trusted[1..] {
        match order(&first.1, &other.1) {
            Order::Unknown(why) => {
                return Some(Verdict::Unknown {
                    lowest: first,
                    against: other.clone(),
                    why,
                });
            }
            Order::AFaster(r) => {
                by.get_or_insert(r);
            }
            Order::BFaster(_) | Order::Unresolved(_) => tied.push(other.clone()),
        }
    }
    Some(match by {
        Some(by) if tied.len() == 1 => Verdict::Fastest {
            winner: first,
            runner_up,
            by,
        },
        _ => Verdict::Tied {
            slower: trusted.len() - tied.len(),
            tied,
        },
    })
}

/// The cells of `at` measured without contention, lowest mean first (the first of equals).
pub fn trusted(at: &[Entry]) -> Vec<Entry> {
    let mut trusted: Vec<Entry> = at.iter().filter(|(_, b)| calm(b)).cloned().collect();
    trusted.sort_by(|a, b| a.1.mean_s.total_cmp(&b.1.mean_s));
    trusted
}

impl Unknown {
    /// Why no order: `only 2 paired rounds (3 are needed for an interval)`.
    pub fn phrase(self) -> String {
        match self {
            Unknown::Rounds(k) => format!(
                "with only {} in common ({MIN_ROUNDS} are needed for an interval)",
                sph_harness::output::console::plural(k, "paired round", "paired rounds")
            ),
            Unknown::Unpaired => "these cells did not run in the same rounds".to_owned(),
        }
    }
}

/// A verdict in a few words, strategies by name only (the table beside it has the numbers).
pub fn verdict_phrase(v: Option<&Verdict>) -> String {
    match v {
        None => "no cell was measured without contention".to_owned(),
        Some(Verdict::Only((s, _))) => format!("only {s} was measured"),
        Some(Verdict::Unknown {
            lowest: (s, _),
            why,
            ..
        }) => format!(
            "the lowest mean is {s}'s, but {}, so no strategy can be called fastest",
            why.phrase()
        ),
        Some(Verdict::Fastest { winner, .. }) => format!("**{}** is fastest", winner.0),
        Some(Verdict::Tied { tied, .. }) => format!(
            "{} are not distinguishable by their paired rounds",
            names(&tied.iter().map(|(s, _)| *s).collect::<Vec<_>>())
        ),
    }
}

/// Strategy names as `a`, `a and b`, `a, b and c`.
pub fn names(strategies: &[StrategyName]) -> String {
    and_list(&strategies.iter().map(|s| s.to_string()).collect::<Vec<_>>())
}

/// A cell by its series and chunks: `rayon-chunks with 45 chunks`, or pinned,
/// `rayon-chunks (spread) with 45 chunks`.
pub fn named(b: &Best) -> String {
    format!(
        "{}{}",
        b.key(),
        b.chunks
            .map_or_else(String::new, |k| format!(" with {k} chunks"))
    )
}

/// A cell as findings name it: `rayon-chunks with 45 chunks (0.412 s [0.40–0.42])`.
pub fn describe((_, b): &Entry) -> String {
    format!("{} ({} s{})", named(b), secs(b.mean_s), interval(b.mean_ci))
}

/// `a`, `a and b`, `a, b and c`.
pub fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}
