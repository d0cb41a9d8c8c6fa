//! Data parallelism with or without rayon.
//!
//! With the `parallel` feature (default) [`prelude`] is rayon's: the blocks
//! of a sampling run and the points of a study run on all cores. Without it
//! the same calls (`par_iter`, `into_par_iter`, `map_init`) run in order on
//! the calling thread, so a library user who does not want rayon's thread
//! pool (and its crates) gets the same results: every random stream is keyed
//! by case and block, never by thread, and block sums are added in block
//! order either way.

#[cfg(feature = "parallel")]
pub(crate) use rayon::prelude;

/// The serial stand-ins for the rayon entry points this crate uses.
#[cfg(not(feature = "parallel"))]
pub(crate) mod prelude {
    /// `par_iter()` on slices: the ordinary slice iterator.
    pub(crate) trait IntoParallelRefIterator<'a> {
        /// The iterator over references.
        type Iter: Iterator;
        /// Iterates in order.
        fn par_iter(&'a self) -> Self::Iter;
    }

    impl<'a, T: 'a> IntoParallelRefIterator<'a> for [T] {
        type Iter = std::slice::Iter<'a, T>;
        fn par_iter(&'a self) -> Self::Iter {
            self.iter()
        }
    }

    impl<'a, T: 'a> IntoParallelRefIterator<'a> for Vec<T> {
        type Iter = std::slice::Iter<'a, T>;
        fn par_iter(&'a self) -> Self::Iter {
            self.iter()
        }
    }

    /// `into_par_iter()`: the ordinary `into_iter()`.
    pub(crate) trait IntoParallelIterator: IntoIterator + Sized {
        /// Iterates in order.
        fn into_par_iter(self) -> Self::IntoIter {
            self.into_iter()
        }
    }

    impl<I: IntoIterator> IntoParallelIterator for I {}

    /// rayon's `map_init` on an ordinary iterator: one `init` value for the
    /// whole (single-threaded) run.
    pub(crate) trait MapInit: Iterator + Sized {
        /// Maps every item with `f(&mut state, item)`, `state = init()`.
        fn map_init<T, R, INIT, F>(self, init: INIT, mut f: F) -> impl Iterator<Item = R>
        where
            INIT: FnOnce() -> T,
            F: FnMut(&mut T, Self::Item) -> R,
        {
            let mut state = init();
            self.map(move |item| f(&mut state, item))
        }
    }

    impl<I: Iterator> MapInit for I {}

    /// `par_chunks_mut()` on slices: the ordinary `chunks_mut()`.
    pub(crate) trait ParallelSliceMut<T> {
        /// Iterates over chunks of `size` in order.
        fn par_chunks_mut(&mut self, size: usize) -> std::slice::ChunksMut<'_, T>;
    }

    impl<T> ParallelSliceMut<T> for [T] {
        fn par_chunks_mut(&mut self, size: usize) -> std::slice::ChunksMut<'_, T> {
            self.chunks_mut(size)
        }
    }
}

/// The number of worker threads (1 without the `parallel` feature): the
/// width of the batches of the samplers' stopping rules (their results do
/// not depend on it).
pub(crate) fn threads() -> usize {
    #[cfg(feature = "parallel")]
    {
        rayon::current_num_threads()
    }
    #[cfg(not(feature = "parallel"))]
    {
        1
    }
}

/// Runs `f` on a worker of the thread pool while the calling thread waits
/// (`rayon::scope`), so that the parallel loops inside `f` fork and join
/// within the pool: from a thread outside it every loop would be injected
/// and waited for anew (a wake-up per loop; subset simulation has about 70
/// per run). Without the `parallel` feature, `f()`.
pub(crate) fn in_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    #[cfg(feature = "parallel")]
    {
        rayon::scope(|_| f())
    }
    #[cfg(not(feature = "parallel"))]
    {
        f()
    }
}

#[cfg(all(test, not(feature = "parallel")))]
mod tests {
    use super::prelude::*;

    #[test]
    fn serial_stand_ins_keep_order_and_state() {
        let v = vec![1, 2, 3];
        let doubled: Vec<i32> = v.par_iter().map(|x| x * 2).collect();
        assert_eq!(doubled, [2, 4, 6]);
        let counted: Vec<(usize, u64)> = (0..3u64)
            .into_par_iter()
            .map_init(
                || 0usize,
                |calls, x| {
                    *calls += 1;
                    (*calls, x)
                },
            )
            .collect();
        assert_eq!(counted, [(1, 0), (2, 1), (3, 2)]);
    }
}
