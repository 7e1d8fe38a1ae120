//! Markdown tables: every table of the reports is written by [`Table`], so heads, rules and
//! rows have one form.
//!
//! A table is its head line, its rule line (`---` under a left-aligned column, `---:` under a
//! right-aligned one) and one line per row, each line ending in `\n`; nothing follows the last
//! row, so `writeln!(md, "{table}")` leaves the blank line that ends it. A line is `|`, then
//! ` {cell} |` per cell. A column without a head (the machine table's names) is written `| |`;
//! a row's cells are written verbatim, an empty one `|  |`: both as the reports always had them.
//! A cell holding a `|` is the caller's to escape (`\|`).

use std::fmt;

/// Which side a column's cells align to, as its rule says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Align {
    /// Text: the rule `---`.
    Left,
    /// Numbers: the rule `---:`.
    Right,
}

/// A column of a [`Table`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Column {
    /// The head's text; empty for a column without a head.
    pub head: String,
    /// How its cells align.
    pub align: Align,
}

impl Column {
    /// A left-aligned column headed `head`.
    pub fn left(head: impl Into<String>) -> Column {
        Column {
            head: head.into(),
            align: Align::Left,
        }
    }

    /// A right-aligned column headed `head`.
    pub fn right(head: impl Into<String>) -> Column {
        Column {
            head: head.into(),
            align: Align::Right,
        }
    }
}

/// A markdown table as it is written: its head and rule, then the rows added so far.
#[derive(Debug, Clone)]
pub struct Table {
    /// The lines written.
    md: String,
    /// How many columns the head has; each row has as many cells.
    width: usize,
}

impl Table {
    /// A table of `columns`, without rows yet.
    pub fn new(columns: impl IntoIterator<Item = Column>) -> Table {
        let mut head = String::from("|");
        let mut rule = String::from("|");
        let mut width = 0;
        for c in columns {
            if !c.head.is_empty() {
                head.push(' ');
                head.push_str(&c.head);
            }
            head.push_str(" |");
            rule.push_str(match c.align {
                Align::Left => "---|",
                Align::Right => "---:|",
            });
            width += 1;
        }
        Table {
            md: format!("{head}\n{rule}\n"),
            width,
        }
    }

    /// Adds a row of `cells`, one per column, in order. Panics on a row of another width: a
    /// table that lost a cell would shift every cell after it into the wrong column.
    pub fn row<S: AsRef<str>>(&mut self, cells: impl IntoIterator<Item = S>) -> &mut Table {
        self.md.push('|');
        let mut n = 0;
        for cell in cells {
            self.md.push(' ');
            self.md.push_str(cell.as_ref());
            self.md.push_str(" |");
            n += 1;
        }
        self.md.push('\n');
        assert_eq!(
            n, self.width,
            "a row of {n} cells in a table of {} columns",
            self.width
        );
        self
    }
}

/// The table's markdown: head, rule and rows, each line ending in `\n`.
impl fmt::Display for Table {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.md)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_says_each_columns_alignment_and_rows_follow_the_head() {
        let mut t = Table::new([Column::left("strategy"), Column::right("cores")]);
        t.row(["seq", "1"])
            .row(["rayon-iter".to_owned(), 2.to_string()]);
        assert_eq!(
            t.to_string(),
            "| strategy | cores |\n|---|---:|\n| seq | 1 |\n| rayon-iter | 2 |\n"
        );
    }

    #[test]
    fn a_column_without_a_head_is_one_space_wide_and_an_empty_cell_is_written_as_given() {
        let mut t = Table::new([Column::left(""), Column::left("`a`")]);
        t.row(["CPU", ""]);
        assert_eq!(t.to_string(), "| | `a` |\n|---|---|\n| CPU |  |\n");
    }

    #[test]
    fn a_table_without_rows_is_its_head_and_rule() {
        let t = Table::new([Column::right("n")]);
        assert_eq!(t.to_string(), "| n |\n|---:|\n");
    }

    #[test]
    #[should_panic(expected = "a row of 1 cells in a table of 2 columns")]
    fn a_row_short_of_cells_is_refused() {
        Table::new([Column::left("a"), Column::left("b")]).row(["x"]);
    }
}
