//! A small pool of worker threads for independent, seeded jobs: the papers of one
//! reproduction, the trainings of the KFU-LSTM fair test.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Applies `f` to every item on up to `workers` threads (at least one), which take the items
/// in the order given (put the longest first), and returns the results in that order. A job
/// that panics makes this panic once the other workers have stopped (as
/// [`std::thread::scope`] does). Each job must carry its own seed, so that results do not
/// depend on which worker ran it.
pub fn map_in_parallel<T, R, F>(items: &[T], workers: usize, f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    F: Fn(&T) -> R + Sync,
{
    let next = AtomicUsize::new(0);
    let slots: Mutex<Vec<Option<R>>> = Mutex::new((0..items.len()).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..workers.clamp(1, items.len().max(1)) {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(item) = items.get(i) else { break };
                    let r = f(item);
                    if let Ok(mut g) = slots.lock() {
                        g[i] = Some(r);
                    }
                }
            });
        }
    });
    // no job panicked (the scope would have), so every slot is filled
    slots
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .flatten()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::map_in_parallel;

    #[test]
    fn results_come_back_in_the_order_of_the_items() {
        let items: Vec<u64> = (0..50).collect();
        for workers in [0, 1, 2, 7, 100] {
            let out = map_in_parallel(&items, workers, |&x| x * x);
            let want: Vec<u64> = items.iter().map(|&x| x * x).collect();
            assert_eq!(out, want, "{workers} workers");
        }
        assert!(map_in_parallel(&[] as &[u8], 2, |&x| x).is_empty());
    }
}
