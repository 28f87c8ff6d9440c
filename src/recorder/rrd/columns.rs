//! Columns sent to Rerun as they are kept: Arrow arrays built straight from the recorder's buffers,
//! and chunks sent in time order with consecutive row ids, without Rerun's generic serialization
//! and sort (each measured as a tenth to a quarter of the Rerun recorder's thread).

use super::column_pool::ColumnPool;
use rerun::external::arrow::buffer::{Buffer, OffsetBuffer};
use rerun::{RecordingStream, TimeColumn};
use std::sync::Arc;

/// A `Scalars` column of `width` values per row, its Arrow array copied straight from the buffer:
/// Rerun's generic serialization first turns every value into an `Option` with a validity flag
/// (a quarter of this recorder's thread's work, in memory that is new for every block).
pub(crate) fn scalar_column(values: &[f64], width: usize) -> rerun::SerializedComponentColumn {
    let rows = values.len() / width;
    list_column(Buffer::from_slice_ref(values), OffsetBuffer::from_lengths(std::iter::repeat_n(width, rows)), rerun::Scalars::descriptor_scalars())
}

/// A column of float64 lists, the values' bytes in `values` and each row's in `offsets`.
pub(super) fn list_column(values: Buffer, offsets: OffsetBuffer<i32>, descriptor: rerun::ComponentDescriptor) -> rerun::SerializedComponentColumn {
    use rerun::external::arrow::array::{ArrayRef, Float64Array, ListArray};
    use rerun::external::arrow::buffer::ScalarBuffer;
    use rerun::external::arrow::datatypes::{DataType, Field};
    let count = values.len() / std::mem::size_of::<f64>();
    let values: ArrayRef = Arc::new(Float64Array::new(ScalarBuffer::new(values, 0, count), None));
    let list = ListArray::new(Arc::new(Field::new_list_field(DataType::Float64, true)), offsets, values, None);
    rerun::SerializedComponentColumn::new(list, descriptor)
}

/// Line strips, one a row, stored as a `LineStrips3D` column keeps them: every strip's points back
/// to back, and each strip's length. A trail update appends its strip without a vector of its own
/// (one per update was a fifth of this recorder's thread), and the points move into Arrow uncopied.
#[derive(Default)]
pub(super) struct Strips {
    points: Vec<[f32; 3]>,
    lengths: Vec<usize>,
    /// Points the last block's strips had (the next block's room).
    last_points: usize,
}

impl Strips {
    pub(super) fn is_empty(&self) -> bool {
        self.lengths.is_empty()
    }

    /// Appends a strip; a block's first takes its points' memory from `pool`.
    pub(super) fn push(&mut self, strip: impl ExactSizeIterator<Item = [f32; 3]>, pool: &ColumnPool<[f32; 3]>) {
        if self.points.capacity() == 0 {
            self.points = pool.take(self.last_points.max(strip.len()));
        }
        self.lengths.push(strip.len());
        self.points.extend(strip);
    }

    /// The strips so far as a column, one strip per row: what `LineStrips3D::update_fields()
    /// .with_strips(..).columns_of_unit_batches()` makes (test below), without its generic
    /// serialization. The next block starts empty.
    pub(super) fn take_column(&mut self, pool: &ColumnPool<[f32; 3]>) -> rerun::SerializedComponentColumn {
        use rerun::external::arrow::array::{ArrayRef, FixedSizeListArray, Float32Array, ListArray};
        use rerun::external::arrow::buffer::ScalarBuffer;
        use rerun::external::arrow::datatypes::{DataType, Field};
        let strip_type = <rerun::components::LineStrip3D as rerun::Loggable>::arrow_datatype();
        let DataType::List(point_field) = &strip_type else { unreachable!("a line strip is a list of points") };
        let DataType::FixedSizeList(coordinate_field, 3) = point_field.data_type() else { unreachable!("a point is three float32") };
        let points = std::mem::take(&mut self.points);
        self.last_points = points.len();
        let count = 3 * points.len();
        let coordinates = Float32Array::new(ScalarBuffer::new(pool.buffer(points), 0, count), None);
        let points: ArrayRef = Arc::new(FixedSizeListArray::new(coordinate_field.clone(), 3, Arc::new(coordinates), None));
        let strip_list: ArrayRef = Arc::new(ListArray::new(point_field.clone(), OffsetBuffer::from_lengths(self.lengths.iter().copied()), points, None));
        let rows = ListArray::new(Arc::new(Field::new_list_field(strip_type.clone(), true)), OffsetBuffer::from_lengths(std::iter::repeat_n(1, self.lengths.len())), strip_list, None);
        self.lengths.clear();
        rerun::SerializedComponentColumn::new(rows, rerun::LineStrips3D::descriptor_strips())
    }
}

/// A column of one fixed-size float32 component (a translation, a quaternion) per row, built
/// from the values back to back, with the component's own Arrow type.
pub(super) fn float32_column<C: rerun::Loggable>(values: &[f32], descriptor: rerun::ComponentDescriptor) -> rerun::SerializedComponentColumn {
    use rerun::external::arrow::array::{ArrayRef, FixedSizeListArray, Float32Array, ListArray};
    use rerun::external::arrow::buffer::OffsetBuffer;
    use rerun::external::arrow::datatypes::{DataType, Field};
    let DataType::FixedSizeList(item, width) = C::arrow_datatype() else {
        unreachable!("translations and quaternions are fixed-size lists of float32")
    };
    let rows = values.len() / width as usize;
    let components: ArrayRef = Arc::new(FixedSizeListArray::new(item, width, Arc::new(Float32Array::from_iter_values(values.iter().copied())), None));
    let list = ListArray::new(Arc::new(Field::new_list_field(C::arrow_datatype(), true)), OffsetBuffer::from_lengths(std::iter::repeat_n(1, rows)), components, None);
    rerun::SerializedComponentColumn::new(list, descriptor)
}

/// `send_columns` for rows already in time order. Rerun's own first reorders every chunk by time
/// (a sort and a shuffle of each column, a fifth of this recorder's work); a block's rows are in
/// order, so here they keep it and get consecutive row ids.
pub(crate) fn send_in_order(
    rec: &RecordingStream,
    entity: &str,
    time: TimeColumn,
    columns: impl IntoIterator<Item = rerun::SerializedComponentColumn>,
) -> Result<(), rerun::log::ChunkError> {
    send_chunk_in_order(rec, entity, time, columns, &ColumnPool::default())
}

/// `send_in_order`, the row ids in memory from `ids`.
pub(super) fn send_chunk_in_order(
    rec: &RecordingStream,
    entity: &str,
    time: TimeColumn,
    columns: impl IntoIterator<Item = rerun::SerializedComponentColumn>,
    ids: &ColumnPool<[u8; 16]>,
) -> Result<(), rerun::log::ChunkError> {
    use rerun::log::{Chunk, ChunkId};
    let row_ids = consecutive_row_ids(time.num_rows(), ids);
    let components: rerun::log::ChunkComponents = columns.into_iter().map(|c| (c.descriptor, c.list_array)).collect();
    let timelines = std::iter::once((*time.timeline().name(), time)).collect();
    rec.send_chunk(Chunk::new(ChunkId::new(), entity.into(), Some(true), row_ids, timelines, components)?);
    Ok(())
}

/// `rows` consecutive row ids from a new one (`RowId::new`, then `next`), as the Arrow column a
/// chunk keeps them in: each id's 16 bytes big-endian, its time then its counter. Written straight
/// into the column rather than through Rerun's generic serialization (`RowId::arrow_from_slice`),
/// which walked every id through optional values and cost a tenth of this recorder's thread.
fn consecutive_row_ids(rows: usize, pool: &ColumnPool<[u8; 16]>) -> rerun::external::arrow::array::FixedSizeBinaryArray {
    let first = rerun::log::RowId::new();
    let (time, counter) = (first.nanos_since_epoch().to_be_bytes(), first.inc());
    let mut ids = pool.take(rows);
    ids.extend((0..rows).map(|i| {
        let mut id = [0u8; 16];
        id[..8].copy_from_slice(&time);
        id[8..].copy_from_slice(&counter.wrapping_add(i as u64).to_be_bytes());
        id
    }));
    rerun::external::arrow::array::FixedSizeBinaryArray::new(16, pool.buffer(ids), None)
}

#[cfg(test)]
mod tests {
    use rerun::log::RowId;

    #[test]
    fn a_strips_column_built_straight_is_the_one_rerun_would_make() {
        let strips = vec![vec![[0.0, 1.0, 2.0], [3.0, 4.0, 5.5]], vec![], vec![[-1.0, 0.25, 9.0]]];
        let pool = super::ColumnPool::default();
        let mut built = super::Strips::default();
        for strip in &strips {
            built.push(strip.iter().copied(), &pool);
        }
        let ours = built.take_column(&pool);
        assert!(built.is_empty());
        let mut rerun_s: Vec<_> = rerun::LineStrips3D::update_fields().with_strips(strips.iter().cloned()).columns_of_unit_batches().unwrap().collect();
        assert_eq!(rerun_s.len(), 1);
        let theirs = rerun_s.remove(0);
        assert_eq!(ours.descriptor, theirs.descriptor);
        assert_eq!(ours.list_array, theirs.list_array);
    }

    #[test]
    fn row_ids_written_straight_are_the_column_rerun_would_make() {
        let column = super::consecutive_row_ids(5, &super::ColumnPool::default());
        let ids = RowId::slice_from_arrow(&column);
        assert_eq!(ids.len(), 5);
        for pair in ids.windows(2) {
            assert_eq!(pair[1], pair[0].next(), "consecutive, as `next` makes them");
        }
        assert_eq!(RowId::arrow_from_slice(ids), column, "Rerun's own serialization of the same ids");
        assert_eq!(rerun::external::arrow::array::Array::data_type(&column), &<RowId as rerun::Loggable>::arrow_datatype());
    }
}
