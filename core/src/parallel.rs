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
