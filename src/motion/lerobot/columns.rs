//! A LeRobot data file's columns as armscope reads them, however they were written: integers of
//! either width, floats of either width, and vectors as FixedSizeList, List or LargeList.

use arrow::array::{Array, AsArray};
use arrow::datatypes::{Float32Type, Float64Type, Int64Type};

pub fn int_column(array: &dyn Array, name: &str) -> Result<Vec<i64>, String> {
    if let Some(a) = array.as_primitive_opt::<Int64Type>() {
        return Ok(a.values().to_vec());
    }
    if let Some(a) = array.as_primitive_opt::<arrow::datatypes::Int32Type>() {
        return Ok(a.values().iter().map(|&v| v as i64).collect());
    }
    Err(format!("column '{name}' is {}, not integers", array.data_type()))
}

pub fn float_scalars(array: &dyn Array, name: &str) -> Result<Vec<f64>, String> {
    if let Some(a) = array.as_primitive_opt::<Float32Type>() {
        return Ok(a.values().iter().map(|&v| v as f64).collect());
    }
    if let Some(a) = array.as_primitive_opt::<Float64Type>() {
        return Ok(a.values().to_vec());
    }
    // some writers keep shape-[1] features as one-element lists
    let column = VectorColumn::new(array, name, 1)?;
    Ok((0..array.len()).map(|row| column.get(row, 0)).collect())
}

/// A column of fixed-width float vectors however it was written: FixedSizeList, List, LargeList
/// of float32 or float64, or a plain float column (width 1).
pub struct VectorColumn<'a> {
    starts: Vec<usize>,
    floats: Floats<'a>,
}

enum Floats<'a> {
    F32(&'a [f32]),
    F64(&'a [f64]),
}

impl<'a> VectorColumn<'a> {
    pub fn new(array: &'a dyn Array, name: &str, width: usize) -> Result<Self, String> {
        let rows = array.len();
        let floats = |child: &'a dyn Array| -> Result<Floats<'a>, String> {
            if let Some(a) = child.as_primitive_opt::<Float32Type>() {
                Ok(Floats::F32(a.values()))
            } else if let Some(a) = child.as_primitive_opt::<Float64Type>() {
                Ok(Floats::F64(a.values()))
            } else {
                Err(format!("column '{name}' holds {}, not floats", child.data_type()))
            }
        };
        let wrong_width = |row: usize, got: usize| format!("column '{name}' row {row} has {got} values, info.json's features say {width}");
        if let Some(list) = array.as_fixed_size_list_opt() {
            if list.value_length() as usize != width {
                return Err(wrong_width(0, list.value_length() as usize));
            }
            let starts = (0..rows).map(|r| list.value_offset(r) as usize).collect();
            return Ok(Self { starts, floats: floats(list.values().as_ref())? });
        }
        if let Some(list) = array.as_list_opt::<i32>() {
            return Ok(Self { starts: list_starts(list.value_offsets(), width).map_err(|(r, got)| wrong_width(r, got))?, floats: floats(list.values().as_ref())? });
        }
        if let Some(list) = array.as_list_opt::<i64>() {
            return Ok(Self { starts: list_starts(list.value_offsets(), width).map_err(|(r, got)| wrong_width(r, got))?, floats: floats(list.values().as_ref())? });
        }
        if width == 1 {
            return Ok(Self { starts: (0..rows).collect(), floats: floats(array)? });
        }
        Err(format!("column '{name}' is {}, not a list of {width} floats", array.data_type()))
    }

    pub fn get(&self, row: usize, k: usize) -> f64 {
        let i = self.starts[row] + k;
        match self.floats {
            Floats::F32(v) => v[i] as f64,
            Floats::F64(v) => v[i],
        }
    }
}

/// Each row's first value in a List or LargeList column, if every row holds `width` values (else
/// the first row that does not, and how many it holds).
fn list_starts<O: arrow::array::OffsetSizeTrait>(offsets: &[O], width: usize) -> Result<Vec<usize>, (usize, usize)> {
    offsets
        .windows(2)
        .enumerate()
        .map(|(row, w)| {
            let (start, end) = (w[0].as_usize(), w[1].as_usize());
            if end - start == width { Ok(start) } else { Err((row, end - start)) }
        })
        .collect()
}

