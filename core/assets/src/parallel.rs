//! Order-preserving parallel map for the independent pieces of loading a model (decoding its
//! images, building their mip chains) and of reducing an environment (SH9 rows, box filtering):
//! phones have six to eight cores and the user waits for the first frame.
//!
//! **Threading**: [`map`] runs on the rayon pool it is called from: inside a pool's `install`
//! (the engine's loaders run in a pool of background priority, `phantogram::background`) that
//! pool, else rayon's global pool (one thread per core, started on first use and kept for the
//! process). Threads steal items until none is left; the call returns when all are done. Threads are not spawned per call: on a 16-core machine, spawning sixteen threads
//! cost more than the 1024 × 512 SH9 they shared (1.2–2.2 ms, against 0.43 ms on 2 cores;
//! `benchmarks/ibl.md`). **Panics**: a panic in `f` is propagated to the caller once the other
//! items have stopped, as rayon does.

use rayon::prelude::*;

/// `items.iter().map(f).collect()`, computed on several threads; results in the items' order.
pub fn map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    // A reference to `f` is `Send` where `f` is `Sync`, as rayon's workers need.
    let f = &f;
    items.par_iter().map(f).collect()
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
