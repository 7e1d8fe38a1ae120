//! The value lists of `--cores`, `--chunks` and `--n`.
//!
//! A list is comma-separated items, each one of
//! - `A`: the single value A;
//! - `A..B`: A, A + step, … up to and including B when the step lands on it (the last value is
//!   never above B), with the option's default step (see [`Axis::default_step`]);
//! - `A..B:S`: the same with step S;
//! - `paper` (for `--chunks` only): the seed program's own chunk counts, [`PAPER_CHUNKS`].
//!
//! The result is sorted ascending without repeats, so `--chunks 45,10,10` runs 10 and 45.
//! Every value must be at least 1.

use std::fmt;

/// The chunk counts the seed program swept: what `--chunks paper` means.
pub const PAPER_CHUNKS: [usize; 17] = [
    2, 4, 8, 12, 16, 20, 25, 35, 45, 60, 75, 100, 150, 200, 250, 333, 400,
];

/// The step of a `--chunks` range written without one: `10..200` is 10, 20, …, 200.
pub const CHUNKS_DEFAULT_STEP: usize = 10;

/// The most values one list may expand to (a guard against typos such as `1..1000000000`).
pub const MAX_VALUES: usize = 10_000;

/// Which option a list belongs to: decides the default step, the words allowed and the
/// wording of errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// `--cores`: worker threads.
    Cores,
    /// `--chunks`: chunks per pass.
    Chunks,
    /// `--n`: particle counts.
    Particles,
}

impl Axis {
    /// The step of `A..B` written without `:S`: 1 for cores, [`CHUNKS_DEFAULT_STEP`] for
    /// chunks, none for particle counts (a range of those must say its step).
    pub fn default_step(self) -> Option<usize> {
        match self {
            Axis::Cores => Some(1),
            Axis::Chunks => Some(CHUNKS_DEFAULT_STEP),
            Axis::Particles => None,
        }
    }

    /// The largest value allowed (see [`crate::limits`]).
    pub fn max(self) -> usize {
        match self {
            Axis::Cores => crate::limits::MAX_CORES,
            Axis::Chunks => crate::limits::MAX_CHUNKS,
            Axis::Particles => crate::limits::MAX_PARTICLES,
        }
    }

    /// What the values count, for messages.
    fn noun(self) -> &'static str {
        match self {
            Axis::Cores => "cores",
            Axis::Chunks => "chunks",
            Axis::Particles => "particle counts",
        }
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.noun())
    }
}

/// Why a list could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RangeError {
    /// The list, or one of its comma-separated items, is empty.
    #[error("no value given (expected e.g. 4, 1..6, 10..200:10 or 10,45,90)")]
    Empty,
    /// `A..B` with B below A.
    #[error("'{item}' is reversed: {end} is below {start} (write {end}..{start})")]
    Reversed {
        /// The item as written.
        item: String,
        /// A.
        start: usize,
        /// B.
        end: usize,
    },
    /// `A..B:0`.
    #[error("'{item}' has step 0; the step must be at least 1")]
    ZeroStep {
        /// The item as written.
        item: String,
    },
    /// A value of 0.
    #[error("'{item}' includes 0; {axis} must be at least 1")]
    Zero {
        /// The item as written.
        item: String,
        /// The option's values.
        axis: Axis,
    },
    /// Not a number, range or known word.
    #[error("'{item}' is not a whole number, a range A..B or A..B:S{}", paper_hint(*axis))]
    Garbage {
        /// The item as written.
        item: String,
        /// The option's values.
        axis: Axis,
    },
    /// `A..B` where the option has no default step.
    #[error("'{item}' needs a step for {axis}, e.g. {item}:{}", suggested_step(*start, *end))]
    MissingStep {
        /// The item as written.
        item: String,
        /// The option's values.
        axis: Axis,
        /// A.
        start: usize,
        /// B.
        end: usize,
    },
    /// A value above the axis's maximum.
    #[error("'{item}' goes above {max}, the most {axis} allowed")]
    TooLarge {
        /// The item as written.
        item: String,
        /// The option's values.
        axis: Axis,
        /// The maximum.
        max: usize,
    },
    /// More values than [`MAX_VALUES`].
    #[error("the list gives more than {MAX_VALUES} values")]
    TooMany,
}

fn paper_hint(axis: Axis) -> &'static str {
    match axis {
        Axis::Chunks => ", or the word paper",
        _ => "",
    }
}

/// A step that splits `start..end` into about ten values, for the `MissingStep` hint.
fn suggested_step(start: usize, end: usize) -> usize {
    (end.saturating_sub(start) / 10).max(1)
}

/// Expands `spec` into its values for `axis`: sorted ascending, without repeats, all ≥ 1.
pub fn parse(spec: &str, axis: Axis) -> Result<Vec<usize>, RangeError> {
    let mut values = Vec::new();
    for item in spec.split(',') {
        expand_item(item.trim(), axis, &mut values)?;
    }
    values.sort_unstable();
    values.dedup();
    Ok(values)
}

/// Appends the values of one item to `out`.
// Over ~60 lines on purpose: the grammar of one range item (`A`, `A..B`, `A..B:S`) with an error
// message per way it can be wrong.
fn expand_item(item: &str, axis: Axis, out: &mut Vec<usize>) -> Result<(), RangeError> {
    if item.is_empty() {
        return Err(RangeError::Empty);
    }
    if item == "paper" && axis == Axis::Chunks {
        out.extend_from_slice(&PAPER_CHUNKS);
        return Ok(());
    }
    let garbage = || RangeError::Garbage {
        item: item.to_owned(),
        axis,
    };
    let zero = || RangeError::Zero {
        item: item.to_owned(),
        axis,
    };
    let number = |s: &str| -> Result<usize, RangeError> {
        // Only digits: `usize::from_str` would also take a leading '+'.
        if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) {
            return Err(garbage());
        }
        s.parse().map_err(|_| garbage())
    };

    let too_large = || RangeError::TooLarge {
        item: item.to_owned(),
        axis,
        max: axis.max(),
    };
    let Some((start, rest)) = item.split_once("..") else {
        let v = number(item)?;
        if v == 0 {
            return Err(zero());
        }
        if v > axis.max() {
            return Err(too_large());
        }
        return push_checked(out, std::iter::once(v));
    };
    let (end, step) = match rest.split_once(':') {
        Some((end, step)) => (number(end)?, Some(number(step)?)),
        None => (number(rest)?, None),
    };
    let start = number(start)?;
    if step == Some(0) {
        return Err(RangeError::ZeroStep {
            item: item.to_owned(),
        });
    }
    if end < start {
        return Err(RangeError::Reversed {
            item: item.to_owned(),
            start,
            end,
        });
    }
    if start == 0 {
        return Err(zero());
    }
    if end > axis.max() {
        return Err(too_large());
    }
    let step = match step.or(axis.default_step()) {
        Some(step) => step,
        None => {
            return Err(RangeError::MissingStep {
                item: item.to_owned(),
                axis,
                start,
                end,
            });
        }
    };
    if (end - start) / step >= MAX_VALUES {
        return Err(RangeError::TooMany);
    }
    push_checked(out, (start..=end).step_by(step))
}

fn push_checked(
    out: &mut Vec<usize>,
    values: impl Iterator<Item = usize>,
) -> Result<(), RangeError> {
    out.extend(values);
    if out.len() > MAX_VALUES {
        return Err(RangeError::TooMany);
    }
    Ok(())
}

/// Writes `values` back in the list syntax, compactly: runs of three or more with a common
/// step become `A..B:S` (`A..B` when S is the axis's default step), the rest are listed, e.g.
/// `1..6` or `2,4,8..20:4`. [`parse`] of the result gives `values` back.
pub fn compact(values: &[usize], axis: Axis) -> String {
    let mut parts = Vec::new();
    let mut i = 0;
    while i < values.len() {
        let mut j = i + 1;
        if j < values.len() {
            let step = values[j] - values[i];
            while j + 1 < values.len() && values[j + 1] - values[j] == step {
                j += 1;
            }
            if j - i >= 2 {
                parts.push(if Some(step) == axis.default_step() {
                    format!("{}..{}", values[i], values[j])
                } else {
                    format!("{}..{}:{step}", values[i], values[j])
                });
                i = j + 1;
                continue;
            }
        }
        parts.push(values[i].to_string());
        i += 1;
    }
    parts.join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cores(s: &str) -> Result<Vec<usize>, RangeError> {
        parse(s, Axis::Cores)
    }

    fn chunks(s: &str) -> Result<Vec<usize>, RangeError> {
        parse(s, Axis::Chunks)
    }

    #[test]
    fn a_single_value_is_a_list_of_one() {
        assert_eq!(cores("4"), Ok(vec![4]));
        assert_eq!(cores(" 4 "), Ok(vec![4]));
    }

    #[test]
    fn a_cores_range_is_inclusive_with_step_one() {
        assert_eq!(cores("1..6"), Ok(vec![1, 2, 3, 4, 5, 6]));
        assert_eq!(cores("3..3"), Ok(vec![3]));
    }

    #[test]
    fn a_bare_chunks_range_steps_by_ten() {
        assert_eq!(
            chunks("10..200"),
            Ok((1..=20).map(|k| 10 * k).collect::<Vec<_>>())
        );
        // The last value is never above the end.
        assert_eq!(chunks("5..30"), Ok(vec![5, 15, 25]));
    }

    #[test]
    fn an_explicit_step_is_used_and_the_last_value_stays_below_the_end() {
        assert_eq!(chunks("10..45:10"), Ok(vec![10, 20, 30, 40]));
        assert_eq!(cores("1..6:2"), Ok(vec![1, 3, 5]));
        assert_eq!(
            parse("1000..3000:1000", Axis::Particles),
            Ok(vec![1000, 2000, 3000])
        );
    }

    #[test]
    fn comma_lists_mix_items_and_come_out_sorted_without_repeats() {
        assert_eq!(chunks("90,10,45"), Ok(vec![10, 45, 90]));
        assert_eq!(chunks("10,1..3:1,10"), Ok(vec![1, 2, 3, 10]));
    }

    #[test]
    fn paper_means_the_seed_programs_chunk_counts() {
        assert_eq!(chunks("paper"), Ok(PAPER_CHUNKS.to_vec()));
        assert_eq!(chunks("paper,1").unwrap()[0], 1);
        assert!(matches!(cores("paper"), Err(RangeError::Garbage { .. })));
    }

    #[test]
    fn a_reversed_range_is_an_error_that_shows_the_fix() {
        let err = cores("5..1").unwrap_err();
        assert!(matches!(
            err,
            RangeError::Reversed {
                start: 5,
                end: 1,
                ..
            }
        ));
        assert!(err.to_string().contains("write 1..5"), "{err}");
    }

    #[test]
    fn step_zero_is_an_error() {
        assert!(matches!(cores("1..5:0"), Err(RangeError::ZeroStep { .. })));
    }

    #[test]
    fn zero_cores_or_chunks_is_an_error() {
        assert!(matches!(cores("0..2"), Err(RangeError::Zero { .. })));
        assert!(matches!(cores("0"), Err(RangeError::Zero { .. })));
        assert!(matches!(chunks("0,10"), Err(RangeError::Zero { .. })));
        assert!(
            cores("0..2")
                .unwrap_err()
                .to_string()
                .contains("cores must be at least 1")
        );
    }

    #[test]
    fn empty_lists_and_empty_items_are_errors() {
        assert_eq!(cores(""), Err(RangeError::Empty));
        assert_eq!(cores("1,,2"), Err(RangeError::Empty));
        assert_eq!(cores("1,"), Err(RangeError::Empty));
    }

    #[test]
    fn anything_else_is_garbage() {
        for bad in [
            "abc", "1..", "..4", "1..4:", "1-4", "+3", "-1", "1.5", "1..4:2:3", "1...4",
        ] {
            assert!(
                matches!(cores(bad), Err(RangeError::Garbage { .. })),
                "{bad}: {:?}",
                cores(bad)
            );
        }
    }

    #[test]
    fn a_range_of_particle_counts_must_give_its_step() {
        let err = parse("1000..5000", Axis::Particles).unwrap_err();
        assert!(matches!(err, RangeError::MissingStep { .. }));
        assert!(err.to_string().contains("1000..5000:400"), "{err}");
    }

    #[test]
    fn huge_lists_are_refused_before_they_are_built() {
        let chunks_of = |s| parse(s, Axis::Chunks);
        assert_eq!(chunks_of("1..1000000:1"), Err(RangeError::TooMany));
        assert!(chunks_of("1..10000:1").is_ok());
    }

    #[test]
    fn values_above_the_documented_maximum_are_refused() {
        assert_eq!(cores("1024").unwrap(), [1024]);
        for bad in ["1025", "1..2000", "18446744073709551615", "1,5000"] {
            assert!(
                matches!(cores(bad), Err(RangeError::TooLarge { max: 1024, .. })),
                "{bad}"
            );
        }
        let err = cores("1..2000").unwrap_err().to_string();
        assert_eq!(err, "'1..2000' goes above 1024, the most cores allowed");
        assert!(parse("200000000", Axis::Particles).is_err());
    }

    #[test]
    fn compact_writes_runs_as_ranges() {
        assert_eq!(compact(&[1, 2, 3, 4, 5, 6], Axis::Cores), "1..6");
        assert_eq!(compact(&[1, 2, 3], Axis::Chunks), "1..3:1");
        assert_eq!(compact(&[10, 20, 30, 45], Axis::Chunks), "10..30,45");
        assert_eq!(compact(&[2, 5], Axis::Cores), "2,5");
        assert_eq!(compact(&[7], Axis::Cores), "7");
        assert_eq!(compact(&[], Axis::Cores), "");
        for list in [vec![1, 2, 3, 4, 5, 6], PAPER_CHUNKS.to_vec(), vec![3, 9]] {
            for axis in [Axis::Cores, Axis::Chunks, Axis::Particles] {
                assert_eq!(parse(&compact(&list, axis), axis), Ok(list.clone()));
            }
        }
    }
}
