//! A bounded, evenly thinned record of a stream of points: what a recording draws as "everything so
//! far" (a tool path over an hour) without growing with the run.

/// Keeps every `stride`-th point pushed, at most `capacity` (+1); when full, every other point is
/// dropped and the stride doubles, so the points stay evenly spaced over the whole stream.
#[derive(Clone, Debug)]
pub struct Overview<T> {
    points: Vec<T>,
    capacity: usize,
    stride: usize,
    seen: usize,
}

impl<T: Clone> Overview<T> {
    pub fn new(capacity: usize) -> Self {
        Self { points: Vec::new(), capacity: capacity.max(2), stride: 1, seen: 0 }
    }

    pub fn push(&mut self, p: T) {
        if self.seen.is_multiple_of(self.stride) {
            self.points.push(p);
            if self.points.len() > self.capacity {
                // keep every other point: then every (2·stride)-th point of the stream
                let mut index = 0;
                self.points.retain(|_| {
                    index += 1;
                    index % 2 == 1
                });
                self.stride *= 2;
            }
        }
        self.seen += 1;
    }

    /// The points kept, oldest first.
    pub fn points(&self) -> &[T] {
        &self.points
    }
}

#[cfg(test)]
mod tests {
    use super::Overview;

    #[test]
    fn stays_within_its_capacity_evenly_spaced_from_the_first_point() {
        let mut o = Overview::new(100);
        for i in 0..100_000u32 {
            o.push(i);
        }
        let p = o.points();
        assert!(p.len() <= 101 && p.len() > 50, "{}", p.len());
        assert_eq!(p[0], 0);
        let step = p[1] - p[0];
        assert!(p.windows(2).all(|w| w[1] - w[0] == step), "evenly spaced");
        assert!(*p.last().unwrap() >= 100_000 - step, "reaches the end of the stream");
    }

    #[test]
    fn keeps_everything_below_its_capacity() {
        let mut o = Overview::new(10);
        (0..10).for_each(|i| o.push(i));
        assert_eq!(o.points(), &(0..10).collect::<Vec<_>>()[..]);
    }
}
