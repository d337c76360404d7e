//! Plain-text tables for the terminal, laid out by `comfy-table`: no borders, columns
//! left-aligned and two spaces apart, each row starting in the first column (so a row can
//! be found with `starts_with` or `grep '^name'`), trailing spaces trimmed.

use comfy_table::{Table, presets::NOTHING};

/// The table of `rows` under `header` (no header line when `header` is empty), ending in a
/// newline.
///
/// ```
/// let t = lobes::report::table::render(&["case", "n"], [vec!["a", "1"], vec!["longer", "22"]]);
/// assert_eq!(t, "case    n\na       1\nlonger  22\n");
/// ```
pub fn render<C: ToString>(header: &[&str], rows: impl IntoIterator<Item = Vec<C>>) -> String {
    let mut table = Table::new();
    table.load_style(NOTHING);
    if !header.is_empty() {
        table.set_header(header.to_vec());
    }
    for row in rows {
        table.add_row(row.iter().map(ToString::to_string).collect::<Vec<_>>());
    }
    for column in table.column_iter_mut() {
        column.set_padding((0, 2));
    }
    table.trim_fmt() + "\n"
}

#[cfg(test)]
mod tests {
    use super::render;

    #[test]
    fn columns_align_by_display_width_without_a_header() {
        // "θh, φh" is 6 characters wide (8 bytes): the next column starts at character 8
        let t = render(&[], [vec!["θh, φh", "1"], vec!["ωr", "2"]]);
        assert_eq!(t, "θh, φh  1\nωr      2\n");
    }
}
