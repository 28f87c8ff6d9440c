//! A CSV table of recorded motion: a header naming `t` (seconds) and one column per joint, one row
//! per sample (`#` lines are comments).

use super::{Column, Episode, check_increasing};
use crate::error::Error;
use std::path::Path;

pub fn read(path: &Path) -> Result<Episode, Error> {
    let fail = |m: String| Error::flag(path.display().to_string(), m);
    let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines.next().ok_or_else(|| fail("empty: a header `t,JOINT,…` and one row per sample".into()))?;
    let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
    let time_column = names.iter().position(|n| n == "t" || n == "time").ok_or_else(|| fail(format!("no column 't' (columns: {})", names.join(", "))))?;
    let mut time = Vec::new();
    let mut values: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for (line_number, line) in lines {
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != names.len() {
            return Err(fail(format!("line {}: {} values, the header names {}", line_number + 1, cells.len(), names.len())));
        }
        for (k, cell) in cells.iter().enumerate() {
            let v: f64 = cell.trim().parse().map_err(|_| fail(format!("line {}: '{}' in column '{}' is not a number", line_number + 1, cell.trim(), names[k])))?;
            values[k].push(v);
        }
    }
    let t0 = values[time_column].first().copied().ok_or_else(|| fail("no rows".into()))?;
    time.extend(values[time_column].iter().map(|t| t - t0));
    check_increasing(&values[time_column], "column 't'").map_err(fail)?;
    let label = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let columns = names.into_iter().zip(values).enumerate().filter(|(k, _)| *k != time_column).map(|(_, (name, values))| Column { name, values }).collect();
    Ok(Episode { label, index: None, time, columns, effort: Vec::new(), notices: Vec::new() })
}
