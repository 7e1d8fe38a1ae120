//! A grid's cells: their size and counts, and the cell of a position.

/// Cell size and counts of a grid (small and `Copy`, so kernels can share it).
#[derive(Debug, Clone, Copy)]
pub(super) struct Shape {
    /// Cells per px: the reciprocal of the cell edge (just over the kernel radius).
    pub(super) per_cell: f64,
    /// Left edge of the first column.
    pub(super) x0: f64,
    /// Lower edge of the first row.
    pub(super) y0: f64,
    /// Cells along x, the empty column on either side included.
    pub(super) cols: usize,
    /// Cells along y, the empty row on either side included.
    pub(super) rows: usize,
}

impl Shape {
    /// The (column, row) of a position, inside the ring of empty cells. Positions outside
    /// the domain fall into the edge cells, which never loses a neighbour: anything within H
    /// of an edge-cell particle is in that cell or the one next to it.
    #[inline(always)]
    pub(super) fn coords(&self, x: f64, y: f64) -> (usize, usize) {
        // `as i64` saturates (NaN gives 0) and is one instruction on x86-64, unlike `as usize`.
        let cx = (((x - self.x0) * self.per_cell) as i64).clamp(0, self.cols as i64 - 3);
        let cy = (((y - self.y0) * self.per_cell) as i64).clamp(0, self.rows as i64 - 3);
        (cx as usize + 1, cy as usize + 1)
    }

    /// The row-major cell number of a position.
    #[inline]
    pub(super) fn cell_of(&self, x: f64, y: f64) -> u32 {
        let (cx, cy) = self.coords(x, y);
        (cy * self.cols + cx) as u32
    }
}
