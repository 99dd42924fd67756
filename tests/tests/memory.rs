//! Switching artifacts a hundred times through the engine leaves resident memory flat.
//!
//! A test binary of its own: resident memory is the process's, so nothing else may run beside
//! it (the other engine tests are in `tests/tests/integration`).

use std::time::Duration;

use phantogram::engine::{Engine, EngineConfig};
use phantogram::library::ArtifactId;
use phantogram_integration::drawn_frame;
use phantogram_testkit::{Scratch, tetrahedron_glb};

const W: u32 = 180;
const H: u32 = 400;
const WAIT: Duration = Duration::from_secs(60);

fn engine(library: &Scratch) -> Option<Engine> {
    phantogram_integration::engine_or_skip(EngineConfig {
        library_dir: Some(library.to_path_buf()),
        ..EngineConfig::default()
    })
}

/// Resident memory of this process, bytes (Linux), after glibc has handed its free pages back.
///
/// Without the trim the figure counts what the allocator keeps for reuse: models are allocated on
/// the loader thread and freed on this one, and how much of that glibc keeps in its per-thread
/// arenas varies from run to run (one CI run: +40 MiB over 80 switches with nothing leaked; 400
/// switches here stayed within 177–193 MiB). Trimmed, the same 400 switches stay within
/// 153–160 MiB, the spread of which artifact happens to be shown, so a leak stands out.
fn resident_bytes() -> Option<u64> {
    trim_allocator();
    phantogram_testkit::resident_bytes()
}

/// Returns the free memory of every glibc arena to the system (elsewhere: nothing to do).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn trim_allocator() {
    unsafe extern "C" {
        /// glibc's `int malloc_trim(size_t pad)` (malloc.h).
        fn malloc_trim(pad: usize) -> i32;
    }
    // SAFETY: malloc_trim takes a plain integer and only releases memory the allocator holds
    // free; it is thread-safe (it locks each arena) and invalidates no live allocation.
    unsafe {
        malloc_trim(0);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn trim_allocator() {}

#[test]
fn a_hundred_switches_leave_resident_memory_flat() {
    let dir = Scratch::new("engine-switches");
    let Some(mut e) = engine(&dir) else { return };
    e.resume_offscreen(W, H).unwrap();
    e.import_artifact("tetra.glb", tetrahedron_glb(0.2, ""));
    assert!(e.wait_for_artifact(WAIT));
    // The artifacts loaded from the library (the Diorama is made, not loaded: it has its own
    // tests in diorama.rs).
    let ids: Vec<ArtifactId> = e
        .artifacts()
        .into_iter()
        .map(|a| a.id)
        .filter(|id| id.to_string() != phantogram::diorama::DIORAMA_ID)
        .collect();
    assert_eq!(ids.len(), 4);
    let mut after_warm_up = None;
    for i in 0..100 {
        e.select_artifact(ids[i % ids.len()].clone());
        assert!(e.wait_for_artifact(WAIT), "switch {i}: {:?}", e.loading_status());
        drawn_frame(&mut e);
        if i == 19 {
            after_warm_up = resident_bytes();
        }
    }
    let (Some(before), Some(after)) = (after_warm_up, resident_bytes()) else {
        eprintln!("no /proc/self/statm: resident memory not measured");
        return;
    };
    let growth_mib = (after as f64 - before as f64) / f64::from(1 << 20);
    eprintln!(
        "resident after 20 switches {} MiB, after 100 {} MiB",
        before >> 20,
        after >> 20
    );
    // Each switch allocates a model of 1 to 5 MiB on the loader thread; a leak of a sixteenth
    // of one per switch is 24+ MiB over 80 (a leaked model per switch: +266 MiB). Measured after
    // a trim (see resident_bytes) the 20th and 100th switches, which show the same artifact,
    // differ by under 7 MiB.
    assert!(
        growth_mib < 24.0,
        "resident memory grew {growth_mib:.1} MiB over 80 switches"
    );
}
