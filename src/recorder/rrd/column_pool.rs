//! Memory for the `.rrd`'s Arrow columns that comes back when Rerun is done with it.
//!
//! The Rerun recorder fills a block's columns (~4 MB for 4096 steps) and hands them to Rerun, which
//! encodes and drops them on its own thread. Freed there, that memory went back to the system
//! (the allocator purges within 1 ms) and the next block's columns were new pages, each faulted
//! in and zeroed by the kernel: a third of the recorder thread's time, and as much again where
//! they were freed. Here a column's memory is a `Vec` the pool lent: Arrow's buffer owns it,
//! and when Rerun drops the buffer the `Vec` returns to the pool, its pages still mapped, for a
//! later block. The values are moved into Arrow, not copied.

use rerun::external::arrow::buffer::Buffer;
use std::ptr::NonNull;
use std::sync::{Arc, Mutex};

/// Vectors kept for reuse at most: a block of the box model's recording lends ~50.
const KEPT: usize = 256;

/// Vectors of `T` to fill and hand to Arrow.
pub struct ColumnPool<T> {
    free: Arc<Mutex<Vec<Vec<T>>>>,
}

impl<T> Default for ColumnPool<T> {
    fn default() -> Self {
        Self { free: Arc::new(Mutex::new(Vec::new())) }
    }
}

/// A lent vector inside an Arrow buffer; back to the pool when the buffer is dropped.
struct Lent<T> {
    values: Vec<T>,
    pool: Arc<Mutex<Vec<Vec<T>>>>,
}

impl<T> Drop for Lent<T> {
    fn drop(&mut self) {
        let mut values = std::mem::take(&mut self.values);
        values.clear();
        let mut free = self.pool.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if free.len() < KEPT {
            free.push(values);
        }
    }
}

impl<T: Copy + Send + Sync + std::panic::RefUnwindSafe + 'static> ColumnPool<T> {
    /// An empty vector with room for at least `capacity` values (a returned one when there is).
    pub fn take(&self, capacity: usize) -> Vec<T> {
        let returned = self.free.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).pop();
        let mut values = returned.unwrap_or_default();
        values.reserve(capacity);
        values
    }

    /// `values` as an Arrow buffer of their bytes, without copying them; the vector comes back to
    /// the pool when the buffer (every clone and slice of it) is dropped.
    pub fn buffer(&self, values: Vec<T>) -> Buffer {
        let bytes = std::mem::size_of_val(values.as_slice());
        let start = NonNull::new(values.as_ptr() as *mut u8).expect("a vector's pointer is never null");
        let owner = Arc::new(Lent { values, pool: self.free.clone() });
        // SAFETY: `start` points at the vector's `bytes` initialized bytes; the vector is owned by
        // `owner`, which the buffer keeps alive, and is neither grown nor touched until `owner`
        // is dropped, so its memory stays where it is and unchanged for the buffer's whole life.
        unsafe { Buffer::from_custom_allocation(start, bytes, owner) }
    }

    /// Vectors waiting to be lent again.
    #[cfg(test)]
    pub fn kept(&self) -> usize {
        self.free.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).len()
    }
}

#[cfg(test)]
mod tests {
    use super::ColumnPool;
    use rerun::external::arrow::array::Float64Array;
    use rerun::external::arrow::buffer::ScalarBuffer;

    #[test]
    fn a_column_holds_the_values_uncopied_and_its_memory_comes_back_when_dropped() {
        let pool = ColumnPool::<f64>::default();
        let mut values = pool.take(4);
        values.extend_from_slice(&[1.0, -2.5, 3.25]);
        let address = values.as_ptr();
        let column = Float64Array::new(ScalarBuffer::new(pool.buffer(values), 0, 3), None);
        assert_eq!(column.values().as_ref(), &[1.0, -2.5, 3.25]);
        assert_eq!(column.values().as_ptr(), address, "the column is the vector's memory, not a copy");
        let slice = column.slice(1, 2);
        drop(column);
        assert_eq!(pool.kept(), 0, "still lent while a slice of the column lives");
        assert_eq!(slice.value(0), -2.5);
        drop(slice);
        assert_eq!(pool.kept(), 1);
        let again = pool.take(3);
        assert!(again.is_empty(), "lent again empty");
        assert_eq!(again.as_ptr(), address, "the same memory");
    }
}
