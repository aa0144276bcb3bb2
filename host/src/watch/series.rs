//! A bounded time series for a stream of unknown length: once it holds
//! its capacity, every other point is dropped and the sampling stride
//! doubles, so memory stays constant over a run of hours while the whole
//! history stays drawable at an even density.

use serde::Serialize;

/// At most `cap` evenly spaced points of everything pushed, plus the
/// latest point.
#[derive(Debug, Clone, Serialize)]
pub struct Decimated<T> {
    /// The kept points, oldest first: every `stride`-th one pushed.
    pub points: Vec<T>,
    /// Keep one point in this many.
    pub stride: u64,
    /// Points pushed so far.
    pub pushed: u64,
    /// The last point pushed (also drawn when the stride skipped it).
    pub last: Option<T>,
    #[serde(skip)]
    cap: usize,
}

impl<T: Clone> Decimated<T> {
    /// An empty series keeping at most `cap` points (at least 2).
    pub fn new(cap: usize) -> Self {
        Decimated {
            points: Vec::new(),
            stride: 1,
            pushed: 0,
            last: None,
            cap: cap.max(2),
        }
    }

    /// Adds a point.
    pub fn push(&mut self, p: T) {
        if self.pushed % self.stride == 0 {
            self.points.push(p.clone());
            if self.points.len() > self.cap {
                // Point i was pushed as number i·stride; keeping the even
                // ones leaves numbers that are multiples of 2·stride.
                let mut i = 0;
                self.points.retain(|_| {
                    i += 1;
                    (i - 1) % 2 == 0
                });
                self.stride *= 2;
            }
        }
        self.pushed += 1;
        self.last = Some(p);
    }

    /// The kept points followed by the latest one if it was not kept.
    pub fn with_last(&self) -> impl Iterator<Item = &T> {
        let last_kept = self.pushed > 0 && (self.pushed - 1) % self.stride == 0;
        self.points
            .iter()
            .chain(self.last.iter().filter(move |_| !last_kept))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stays_bounded_evenly_spaced_and_ends_at_the_latest_point() {
        let mut s = Decimated::new(8);
        for i in 0..1000u64 {
            s.push(i);
            assert!(s.points.len() <= 8, "{} points after {i}", s.points.len());
        }
        // Evenly spaced from the first point.
        for (k, &p) in s.points.iter().enumerate() {
            assert_eq!(p, k as u64 * s.stride);
        }
        assert_eq!(s.pushed, 1000);
        assert_eq!(s.with_last().last(), Some(&999));
        assert!(s.points.len() >= 4, "{:?}", s.points);
    }

    #[test]
    fn short_series_keep_every_point_once() {
        let mut s = Decimated::new(8);
        for i in 0..5u64 {
            s.push(i);
        }
        assert_eq!(s.with_last().copied().collect::<Vec<_>>(), [0, 1, 2, 3, 4]);
    }
}
