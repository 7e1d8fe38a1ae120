//! The summary rows' own functions ([`super::rows`]) on fixture rows: a file of its own, since
//! the fixtures build on the rows.

use super::fixtures::row;
use super::rows::{Contended, Status, fastest};
use sph_strategies::StrategyName;

#[test]
fn the_fastest_cell_skips_failed_ones_and_takes_a_contended_one_only_as_a_last_resort() {
    let mut contended = row(StrategyName::RayonIter, 2, None, 1.0);
    contended.contended = Some(true);
    let mut failed = row(StrategyName::RayonIter, 2, None, 0.5);
    failed.status = Status::Failed;
    let calm = row(StrategyName::RayonIter, 2, None, 2.0);
    let rows = [contended, failed, calm];
    assert_eq!(
        fastest(&rows, Contended::Compete).unwrap().mean_s,
        Some(1.0)
    );
    assert_eq!(
        fastest(&rows, Contended::LastResort).unwrap().mean_s,
        Some(2.0)
    );
    assert_eq!(
        fastest(&rows[..1], Contended::LastResort).unwrap().mean_s,
        Some(1.0)
    );
    assert!(fastest(&rows[1..2], Contended::Compete).is_none());
}

#[test]
fn rows_write_the_names_the_command_line_uses() {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.serialize(row(StrategyName::CrossbeamPool, 2, Some(4), 1.0))
        .unwrap();
    let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
    let line = text.lines().nth(1).unwrap();
    assert!(
        line.starts_with("crossbeam-pool,all-pairs,seed,60,3,2,4,"),
        "{line}"
    );
}
