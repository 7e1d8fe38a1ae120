//! The sides of a comparison: which results directories pool into one machine's study.
//!
//! By default ([`SideRule::ByMachine`]) directories whose `meta.json` machines are the same
//! hardware ([`Machine::same_hardware`], the one rule for "same machine") form one side and
//! pool as one study; each other machine is a side of its own. `--compare`
//! ([`SideRule::EachDirectory`]) makes every directory a side, whatever its machine. Sides
//! are tagged `A`, `B`, … in the order their first directory was given.

use std::path::Path;

use crate::report::load::Sweep;
use crate::report::view::GroupView;
use sph_harness::results::meta::Machine;

/// How directories are grouped into sides.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SideRule {
    /// One side per machine: directories of the same hardware pool (the default).
    ByMachine,
    /// One side per directory, even on the same machine (`--compare`).
    EachDirectory,
}

/// One side: one machine's directories (or, under `--compare`, one directory).
#[derive(Debug, Clone)]
pub struct Side<'a> {
    /// `A`, `B`, …: how tables and charts name the side.
    pub tag: String,
    /// Its sweeps, in the order given.
    pub sweeps: Vec<&'a Sweep>,
    /// Its groups ([`GroupView::of`] its sweeps).
    pub views: Vec<GroupView>,
}

impl Side<'_> {
    /// The side's machine (its first directory's; the others have the same hardware, or the
    /// side has one directory).
    pub fn machine(&self) -> &Machine {
        &self.sweeps[0].meta.machine
    }

    /// Its directories, in the order given.
    pub fn dirs(&self) -> Vec<&Path> {
        self.sweeps.iter().map(|s| s.dir.as_path()).collect()
    }

    /// The view of group `g`, if the side measured it.
    pub fn view(&self, g: &crate::report::series::Group) -> Option<&GroupView> {
        self.views.iter().find(|v| v.group == *g)
    }
}

/// The tag of the side at `index`: `A` … `Z`, then `S27`, `S28`, ….
pub fn tag(index: usize) -> String {
    match u8::try_from(index) {
        Ok(i) if i < 26 => char::from(b'A' + i).to_string(),
        _ => format!("S{}", index + 1),
    }
}

/// The sides of `sweeps` under `rule`, in the order their first directory appears.
pub fn sides(sweeps: &[Sweep], rule: SideRule) -> Vec<Side<'_>> {
    let mut out: Vec<Side<'_>> = Vec::new();
    for s in sweeps {
        let joins = match rule {
            SideRule::ByMachine => out
                .iter()
                .position(|side| side.machine().same_hardware(&s.meta.machine)),
            SideRule::EachDirectory => None,
        };
        match joins {
            Some(i) => out[i].sweeps.push(s),
            None => out.push(Side {
                tag: tag(out.len()),
                sweeps: vec![s],
                views: Vec::new(),
            }),
        }
    }
    for side in &mut out {
        side.views = GroupView::of(side.sweeps.iter().copied());
    }
    out
}

/// Whether `sides` make a comparison rather than one pooled study: more than one machine, or
/// `--compare`.
pub fn is_comparison(sides: &[Side<'_>], rule: SideRule) -> bool {
    rule == SideRule::EachDirectory || sides.len() > 1
}

/// The sets of sides (by index, each set of two or more) that ran on the same hardware:
/// never any under [`SideRule::ByMachine`]; under `--compare`, what the report must warn of.
pub fn same_hardware_sets(sides: &[Side<'_>]) -> Vec<Vec<usize>> {
    let mut sets: Vec<Vec<usize>> = Vec::new();
    for (i, side) in sides.iter().enumerate() {
        match sets
            .iter_mut()
            .find(|set| sides[set[0]].machine().same_hardware(side.machine()))
        {
            Some(set) => set.push(i),
            None => sets.push(vec![i]),
        }
    }
    sets.retain(|set| set.len() > 1);
    sets
}

/// How each side is named beside its tag: its machine's [`Machine::label`], and where two
/// sides share a label (`--compare` on one machine) its directories' last components too
/// (the machines table and each side's section give them whole).
pub fn names(sides: &[Side<'_>]) -> Vec<String> {
    let labels: Vec<String> = sides.iter().map(|s| s.machine().label()).collect();
    labels
        .iter()
        .zip(sides)
        .map(|(label, side)| {
            if labels.iter().filter(|l| *l == label).count() > 1 {
                let dirs: Vec<String> = side
                    .dirs()
                    .iter()
                    .map(|d| {
                        d.file_name().map_or_else(
                            || d.display().to_string(),
                            |n| n.to_string_lossy().into_owned(),
                        )
                    })
                    .collect();
                format!("{label} ({})", dirs.join(", "))
            } else {
                label.clone()
            }
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use sph_harness::results::fixtures::row;
    use sph_harness::results::fixtures::sweep_on;
    use sph_harness::results::rows::SummaryRow;
    use sph_strategies::StrategyName;

    fn seq() -> Vec<SummaryRow> {
        vec![row(StrategyName::Seq, 1, None, 4.0)]
    }

    #[test]
    fn directories_of_the_same_hardware_pool_into_one_side_and_others_stand_apart() {
        let sweeps = [
            sweep_on("a", "Xeon", 2, seq()),
            sweep_on("b", "EPYC", 16, seq()),
            sweep_on("c", "Xeon", 2, seq()),
        ];
        let by_machine = sides(&sweeps, SideRule::ByMachine);
        let dirs: Vec<(String, Vec<&Path>)> = by_machine
            .iter()
            .map(|s| (s.tag.clone(), s.dirs()))
            .collect();
        assert_eq!(
            dirs,
            [
                ("A".to_owned(), vec![Path::new("a"), Path::new("c")]),
                ("B".to_owned(), vec![Path::new("b")]),
            ]
        );
        let rows: usize = by_machine[0].sweeps.iter().map(|s| s.rows.len()).sum();
        assert_eq!(rows, 2);
        assert!(is_comparison(&by_machine, SideRule::ByMachine));
        assert!(same_hardware_sets(&by_machine).is_empty());
        assert_eq!(
            names(&by_machine),
            ["Xeon, 2 hardware threads", "EPYC, 16 hardware threads"]
        );
    }

    #[test]
    fn one_machine_is_one_pooled_study_unless_compare_sets_each_directory_apart() {
        let sweeps = [
            sweep_on("a", "Xeon", 2, seq()),
            sweep_on("b", "Xeon", 2, seq()),
        ];
        let pooled = sides(&sweeps, SideRule::ByMachine);
        assert_eq!(pooled.len(), 1);
        assert!(!is_comparison(&pooled, SideRule::ByMachine));
        let apart = sides(&sweeps, SideRule::EachDirectory);
        assert_eq!(apart.len(), 2);
        assert!(is_comparison(&apart, SideRule::EachDirectory));
        assert_eq!(same_hardware_sets(&apart), [vec![0, 1]]);
        assert_eq!(
            names(&apart),
            [
                "Xeon, 2 hardware threads (a)",
                "Xeon, 2 hardware threads (b)"
            ]
        );
    }

    #[test]
    fn the_same_model_with_another_thread_count_is_another_machine() {
        let sweeps = [
            sweep_on("a", "Xeon", 2, seq()),
            sweep_on("b", "Xeon", 4, seq()),
        ];
        assert_eq!(sides(&sweeps, SideRule::ByMachine).len(), 2);
    }

    #[test]
    fn tags_run_from_a_to_z_then_number_the_sides() {
        assert_eq!(
            (tag(0), tag(25), tag(26)),
            ("A".into(), "Z".into(), "S27".into())
        );
    }
}
