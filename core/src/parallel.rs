//! Work spread over the cores, with results that do not depend on how it
//! was spread: the light engine's rays, the year's hours, the patch mesh's
//! surfaces.

/// Maps `f` over `0..count` on `threads` threads (all cores when `None`);
/// the result does not depend on how the work is split. Threads take
/// blocks of indices as they finish the last, so uneven costs (sunrise and
/// noon hours, patches in the open and in corners) keep every core busy.
pub(crate) fn par_map<T: Send>(threads: Option<usize>, count: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = thread_count(threads).min(count.max(1));
    if threads == 1 {
        return (0..count).map(f).collect();
    }
    // About 16 blocks per thread: small enough to even out, large enough
    // that taking one costs nothing.
    let block = count.div_ceil(threads * 16).max(1);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let (f, next) = (&f, &next);
    let mut blocks: Vec<(usize, Vec<T>)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(move || {
                    let mut mine = Vec::new();
                    loop {
                        let start = next.fetch_add(block, std::sync::atomic::Ordering::Relaxed);
                        if start >= count {
                            return mine;
                        }
                        mine.push((start, (start..(start + block).min(count)).map(f).collect::<Vec<T>>()));
                    }
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("worker thread panicked")).collect()
    });
    blocks.sort_unstable_by_key(|(start, _)| *start);
    blocks.into_iter().flat_map(|(_, values)| values).collect()
}

/// Maps `f` over `items` in slices of `size` (the last shorter), side by
/// side as [`par_map`] does: for work that keeps a buffer or a running
/// state across a slice.
pub(crate) fn par_chunks<T: Sync, R: Send>(threads: Option<usize>, items: &[T], size: usize, f: impl Fn(&[T]) -> R + Sync) -> Vec<R> {
    par_map(threads, items.len().div_ceil(size), |k| f(&items[k * size..((k + 1) * size).min(items.len())]))
}

/// Numbers `count` items so that those with equal `key`s, and only those,
/// share a number: two threads, each numbering the keys its hash picks in
/// a map of its own (a map of all of a large model's corners was the most
/// of finding its surfaces and shells). The numbers do not depend on how
/// many threads ran.
pub(crate) fn number_alike<K: std::hash::Hash + Eq>(count: usize, key: impl Fn(usize) -> K + Sync) -> Vec<u32> {
    use std::hash::Hasher;
    let half = |which: u32| {
        let mut numbers: rustc_hash::FxHashMap<K, u32> = rustc_hash::FxHashMap::default();
        (0..count)
            .map(|k| {
                let key = key(k);
                let mut hash = rustc_hash::FxHasher::default();
                key.hash(&mut hash);
                if hash.finish() as u32 & 1 != which {
                    return u32::MAX;
                }
                let next = 2 * numbers.len() as u32 + which;
                *numbers.entry(key).or_insert(next)
            })
            .collect::<Vec<u32>>()
    };
    let (evens, odds) = par_join(None, || half(0), || half(1));
    evens.into_iter().zip(odds).map(|(even, odd)| even.min(odd)).collect()
}

/// Runs `a` and `b` side by side where `threads` allows two (all cores
/// when `None`), else one after the other.
pub(crate) fn par_join<A: Send, B>(threads: Option<usize>, a: impl FnOnce() -> A + Send, b: impl FnOnce() -> B) -> (A, B) {
    if thread_count(threads) < 2 {
        return (a(), b());
    }
    std::thread::scope(|scope| {
        let a = scope.spawn(a);
        let b = b();
        (a.join().expect("worker thread panicked"), b)
    })
}

/// The threads `threads` asks for: all cores when `None`, at least one.
fn thread_count(threads: Option<usize>) -> usize {
    // Asked once: the standard library reads the cgroup files at every call,
    // and hours of a year call this thousands of times.
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    threads.unwrap_or_else(|| *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Equal keys share a number and different keys never do; slices cover
    /// the items in order, the last one shorter.
    #[test]
    fn alike_items_share_a_number_and_slices_cover_the_items() {
        let keys: Vec<u64> = (0..1000).map(|k| k * 7919 % 113).collect();
        let numbers = number_alike(keys.len(), |k| keys[k]);
        for a in 0..keys.len() {
            for b in 0..keys.len() {
                assert_eq!(numbers[a] == numbers[b], keys[a] == keys[b], "items {a} and {b}");
            }
        }
        let sums = par_chunks(None, &keys, 64, |slice| slice.len());
        assert_eq!(sums.len(), 16);
        assert_eq!(sums.iter().sum::<usize>(), 1000);
        assert_eq!(sums[15], 1000 - 15 * 64);
    }
}
