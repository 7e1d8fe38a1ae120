//! The grid's sort in bands ([`super::sort`]) against the serial sort, through a whole rebuild
//! of the grid: a file of its own, since it needs both the grid and the sort.

use sph_strategies::Executor;

use super::Grid;
use super::sort::PARALLEL_SORT;
use crate::cutting::Cutting;
use crate::scene::splitmix::SplitMix64;
use crate::sph::neighbors::{Bounds, Neighbors};
use crate::sph::state::Positions;
use sph_strategies::seq::SeqExecutor;

/// The grid's arrays after a rebuild over `x`, `y` on `exec`.
fn rebuilt(exec: &impl Executor, bounds: Bounds, x: &[f64], y: &[f64]) -> [Vec<u64>; 5] {
    let mut grid = Grid::<u8>::new(bounds, 16.0, x.len());
    grid.rebuild(exec, Positions { x, y }).unwrap();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect();
    let wide = |v: &[u32]| v.iter().map(|&c| c as u64).collect();
    [
        wide(&grid.cell_of),
        wide(&grid.start),
        wide(&grid.order),
        bits(&grid.sorted_x),
        bits(&grid.sorted_y),
    ]
}

#[test]
fn the_sort_in_bands_gives_the_serial_sorts_arrays_however_the_passes_are_cut() {
    let n = PARALLEL_SORT + 1234;
    let mut rng = SplitMix64::new(11);
    let mut draw = |lo: f64, hi: f64| lo + rng.next_f64() * (hi - lo);
    for (width, height) in [(320.0, 240.0), (8000.0, 6000.0)] {
        let bounds = Bounds {
            min_x: 0.0,
            min_y: 0.0,
            max_x: width,
            max_y: height,
        };
        // Spread over the tank and past its edges; then all in one corner, so that most
        // bands are empty and one holds nearly every particle.
        let spread: (Vec<f64>, Vec<f64>) = (0..n)
            .map(|_| (draw(-20.0, width + 20.0), draw(-20.0, height + 20.0)))
            .unzip();
        let corner: (Vec<f64>, Vec<f64>) =
            (0..n).map(|_| (draw(0.0, 40.0), draw(0.0, 40.0))).unzip();
        for (x, y) in [spread, corner] {
            let serial = rebuilt(&SeqExecutor, bounds, &x, &y);
            assert!(serial[2].windows(2).any(|w| w[0] > w[1]), "a real sort");
            for chunks in [1, 2, 7, 64, 1000] {
                let banded = rebuilt(&Cutting(chunks), bounds, &x, &y);
                for (field, (a, b)) in ["cell_of", "start", "order", "sorted_x", "sorted_y"]
                    .iter()
                    .zip(serial.iter().zip(&banded))
                {
                    assert!(a == b, "{width}x{height}, {chunks} chunks: {field} differs");
                }
            }
        }
    }
}
