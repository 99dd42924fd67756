//! Order-preserving parallel map on scoped threads, for the independent pieces of loading a model
//! (decoding its images, building their mip chains): phones have six to eight cores and the user
//! waits for the first frame.
//!
//! **Threading**: [`map`] takes up to one thread per core (`std::thread::available_parallelism`),
//! each pulling the next item until none is left, and returns when all are done; with one item or
//! one core it runs on the caller's thread. **Panics**: a panic in `f` is propagated to the caller
//! once every thread has stopped, as `std::thread::scope` does.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// `items.iter().map(f).collect()`, computed on several threads; results in the items' order.
pub fn map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len());
    if threads <= 1 {
        return items.iter().map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<R>>> = Mutex::new(items.iter().map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(item) = items.get(i) else { break };
                    let r = f(item);
                    // A poisoned lock means another worker panicked; the scope re-raises that
                    // panic, so this result is not needed.
                    if let Ok(mut results) = results.lock() {
                        results[i] = Some(r);
                    }
                }
            });
        }
    });
    results
        .into_inner()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
        .into_iter()
        .map(|r| r.expect("every index below items.len() was taken by exactly one worker"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_order_and_computes_every_item() {
        let items: Vec<u64> = (0..1000).collect();
        // Uneven work, so that workers finish out of order.
        let squares = map(&items, |&x| {
            if x % 7 == 0 {
                std::thread::sleep(std::time::Duration::from_micros(50));
            }
            x * x
        });
        assert_eq!(squares, items.iter().map(|x| x * x).collect::<Vec<_>>());
        assert!(map(&[] as &[u8], |&x| x).is_empty());
        assert_eq!(map(&[3u8], |&x| x + 1), vec![4]);
    }

    #[test]
    fn a_panicking_item_reaches_the_caller() {
        let caught =
            std::panic::catch_unwind(|| map(&[1, 2, 3, 4], |&x: &i32| if x == 3 { panic!("item 3") } else { x }));
        assert!(caught.is_err());
    }
}
