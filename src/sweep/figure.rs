//! The summary figure of a sweep, from its table: for each swept key, the first critical
//! point's `ε` and the axial load `fz/(n Pcrit)` where the path ended (the target, unless
//! it stopped short) against the key's values, one curve per combination of the other
//! keys' values. A key whose values are not numbers is plotted against their place in the
//! sweep, the values listed in the axis label.

use super::table::{SweepTable, RESULT_COLUMNS};
use crate::output::chart::{lines_svg, Curve, DrawError, LinePanel};

/// The file name of the summary figure of swept key `key`.
pub fn summary_file(key: &str) -> String {
    let slug: String = key
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("sweep-{slug}.svg")
}

/// The swept keys of a table: the columns between `status` and the results.
pub fn swept_keys(table: &SweepTable) -> Vec<String> {
    table
        .headers
        .iter()
        .skip(2)
        .take_while(|h| h.as_str() != RESULT_COLUMNS[0])
        .cloned()
        .collect()
}

/// The summary figures of `table`, one per swept key, as (file name, SVG); `caption` is
/// under every title.
pub fn summary_figures(
    table: &SweepTable,
    caption: &[String],
) -> Result<Vec<(String, String)>, DrawError> {
    let keys = swept_keys(table);
    let mut files = Vec::new();
    for key in &keys {
        let (positions, x_label) = axis_positions(table, key);
        let others: Vec<&String> = keys.iter().filter(|k| *k != key).collect();
        // one curve per combination of the other keys' values, in the order met
        let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
        for row in 0..table.rows.len() {
            let label = others
                .iter()
                .map(|k| format!("{k} = {}", table.get(row, k).unwrap_or("")))
                .collect::<Vec<_>>()
                .join(", ");
            match groups.iter_mut().find(|(l, _)| *l == label) {
                Some((_, rows)) => rows.push(row),
                None => groups.push((label, vec![row])),
            }
        }
        let panel = |column: &str, title: &str, y_label: &str| LinePanel {
            title: title.to_string(),
            x_label: x_label.clone(),
            y_label: y_label.to_string(),
            curves: groups
                .iter()
                .enumerate()
                .map(|(i, (label, rows))| Curve {
                    label: label.clone(),
                    points: rows
                        .iter()
                        .map(|&r| (positions[r], cell(table, r, column)))
                        .collect(),
                    dashed: false,
                    marked: true,
                    color: i,
                })
                .collect(),
            shaded: Vec::new(),
        };
        let panels = [
            panel(
                "critical_eps",
                "first critical point",
                "compression ratio ε at it (–)",
            ),
            panel(
                "fz",
                "axial load where the path ended",
                "Σ Fz / (n Pcrit) (–)",
            ),
        ];
        let title = format!("sweep summary against {key}");
        files.push((summary_file(key), lines_svg(&title, caption, &panels)?));
    }
    Ok(files)
}

/// A number of the table (NaN, left out of the figure, where the cell is empty, not a
/// number, or the case did not end well).
fn cell(table: &SweepTable, row: usize, column: &str) -> f64 {
    let ok = table.get(row, "status").is_some_and(|s| s != "failed");
    table
        .get(row, column)
        .filter(|_| ok)
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|v| v.is_finite())
        .unwrap_or(f64::NAN)
}

/// The x position of every row on the axis of `key`, and the axis label: the values when
/// all are numbers, else their place among the distinct values (listed in the label).
fn axis_positions(table: &SweepTable, key: &str) -> (Vec<f64>, String) {
    let values: Vec<&str> = (0..table.rows.len())
        .map(|r| table.get(r, key).unwrap_or(""))
        .collect();
    let numbers: Option<Vec<f64>> = values.iter().map(|v| v.trim().parse().ok()).collect();
    if let Some(numbers) = numbers {
        return (numbers, key.to_string());
    }
    let mut distinct: Vec<&str> = Vec::new();
    for v in &values {
        if !distinct.contains(v) {
            distinct.push(v);
        }
    }
    let positions = values
        .iter()
        .map(|v| (distinct.iter().position(|d| d == v).unwrap_or(0) + 1) as f64)
        .collect();
    let listed: Vec<String> = distinct
        .iter()
        .enumerate()
        .map(|(i, v)| format!("{} = {v}", i + 1))
        .collect();
    (positions, format!("{key} ({})", listed.join(", ")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> SweepTable {
        let mut headers: Vec<String> = ["case", "status", "geometry.helices", "boundary.tip"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        headers.extend(RESULT_COLUMNS.iter().map(|s| s.to_string()));
        let row = |case: &str, status: &str, n: &str, tip: &str, crit: &str, fz: &str| {
            let mut r: Vec<String> = vec![case.into(), status.into(), n.into(), tip.into()];
            r.extend(RESULT_COLUMNS.iter().map(|c| match *c {
                "critical_eps" => crit.to_string(),
                "fz" => fz.to_string(),
                _ => String::new(),
            }));
            r
        };
        SweepTable {
            headers,
            rows: vec![
                row("001", "ok", "2", "fixed", "0.34", "-4.8"),
                row("002", "ok", "4", "fixed", "", "-4.9"),
                row("003", "failed", "2", "slide", "0.1", "-1"),
                row("004", "ok", "4", "slide", "0.15", "-2.1"),
            ],
        }
    }

    #[test]
    fn a_sweep_gets_a_figure_per_key_with_a_curve_per_other_value() {
        let t = table();
        assert_eq!(swept_keys(&t), ["geometry.helices", "boundary.tip"]);
        let files = summary_figures(&t, &["sweep s".into()]).expect("figures");
        let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            ["sweep-geometry_helices.svg", "sweep-boundary_tip.svg"]
        );
        let svg = &files[0].1;
        assert!(svg.contains("boundary.tip = fixed") && svg.contains("boundary.tip = slide"));
        assert!(files[1].1.contains("boundary.tip (1 = fixed, 2 = slide)"));
        // a failed case and an empty cell are left out
        assert!(cell(&t, 2, "critical_eps").is_nan());
        assert!(cell(&t, 1, "critical_eps").is_nan());
        assert_eq!(cell(&t, 3, "fz"), -2.1);
    }
}
