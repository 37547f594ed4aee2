//! The one Markdown table writer of Strata's reports: a header of titled,
//! aligned columns, then rows of cells, each cell kept from breaking its row
//! ([`cell_text`]).
//!
//! ```
//! use strata_markdown::{Align, Table};
//!
//! let mut t = Table::new().left("method").right("ms");
//! t.row(["ray", "5.000"]);
//! t.row(["a|b", ""]);
//! assert_eq!(
//!     t.to_string(),
//!     "| method | ms |\n|---|---:|\n| ray | 5.000 |\n| a/b |  |\n"
//! );
//! # let _ = Align::Left;
//! ```

#![warn(missing_docs)]

use std::fmt;

/// How a column's cells sit: text left, numbers right.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Align {
    /// `---`
    Left,
    /// `---:`
    Right,
}

/// Keep user text from breaking a table row: `|` becomes `/`, a line break
/// a space.
pub fn cell_text(s: &str) -> String {
    s.replace('|', "/").replace('\n', " ")
}

/// A Markdown table: columns, then rows. Every header and cell goes through
/// [`cell_text`] and stands between single spaces (an empty cell: `|  |`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Table {
    titles: Vec<String>,
    aligns: Vec<Align>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table without columns yet.
    pub fn new() -> Table {
        Table::default()
    }

    /// Add a column.
    pub fn column(mut self, title: impl AsRef<str>, align: Align) -> Table {
        self.titles.push(cell_text(title.as_ref()));
        self.aligns.push(align);
        self
    }

    /// Add a left-aligned (text) column.
    pub fn left(self, title: impl AsRef<str>) -> Table {
        self.column(title, Align::Left)
    }

    /// Add a right-aligned (number) column.
    pub fn right(self, title: impl AsRef<str>) -> Table {
        self.column(title, Align::Right)
    }

    /// Add one column per title, all aligned alike.
    pub fn columns<S: AsRef<str>>(
        mut self,
        titles: impl IntoIterator<Item = S>,
        align: Align,
    ) -> Table {
        for t in titles {
            self = self.column(t, align);
        }
        self
    }

    /// Add a row. It should have one cell per column (debug builds check).
    pub fn row<S: AsRef<str>>(&mut self, cells: impl IntoIterator<Item = S>) {
        let row: Vec<String> = cells.into_iter().map(|c| cell_text(c.as_ref())).collect();
        debug_assert_eq!(row.len(), self.titles.len(), "cells {row:?}");
        self.rows.push(row);
    }

    /// Rows added so far.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// No rows yet.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Append the table (each line ending in a line break) to `md`.
    pub fn write_to(&self, md: &mut String) {
        md.push_str(&self.to_string());
    }
}

fn line(f: &mut fmt::Formatter<'_>, cells: &[String]) -> fmt::Result {
    f.write_str("|")?;
    for c in cells {
        write!(f, " {c} |")?;
    }
    f.write_str("\n")
}

impl fmt::Display for Table {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        line(f, &self.titles)?;
        f.write_str("|")?;
        for a in &self.aligns {
            f.write_str(match a {
                Align::Left => "---|",
                Align::Right => "---:|",
            })?;
        }
        f.write_str("\n")?;
        for r in &self.rows {
            line(f, r)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_alignment_and_escaped_cells() {
        let mut t = Table::new()
            .left("view")
            .columns(["ray", "mesh|q"], Align::Right);
        t.row(["river", "1.0", "2.0"]);
        t.row(["a\nb", "", "**3**"]);
        assert_eq!(t.len(), 2);
        assert_eq!(
            t.to_string(),
            "| view | ray | mesh/q |\n|---|---:|---:|\n| river | 1.0 | 2.0 |\n| a b |  | **3** |\n"
        );
    }

    #[test]
    fn a_table_without_rows_is_its_header() {
        let t = Table::new().left("a");
        assert!(t.is_empty());
        let mut md = String::from("x\n");
        t.write_to(&mut md);
        assert_eq!(md, "x\n| a |\n|---|\n");
    }

    #[test]
    fn cell_text_keeps_rows_whole() {
        assert_eq!(cell_text("a|b\nc"), "a/b c");
        assert_eq!(cell_text(&cell_text("a|b")), "a/b");
    }
}
