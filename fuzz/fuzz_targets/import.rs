//! Every sensor-log importer on any bytes: the first byte picks the layout (the project's log,
//! gzipped or not; a BROAD CSV; an Android raw dump's `accelerometer.txt` with a `mocap.csv`; a
//! Sensor Logger or phyphox `Accelerometer.csv`), the rest is the file. Detection and import may
//! fail, never panic, hang or hold more than the import budget.
#![no_main]

#[path = "scratch.rs"]
mod scratch;

use libfuzzer_sys::fuzz_target;
use phantogram_lab::sensorlog::import::import;

/// Counts the Rust heap (its own global allocator): one input may not grow it by more than 1 GiB.
#[path = "heap_limit.rs"]
mod heap_limit;

fuzz_target!(|data: &[u8]| {
    heap_limit::input_begins();
    let Some((&layout, body)) = data.split_first() else {
        return;
    };
    let root = scratch::dir("import");
    let path = match layout % 5 {
        0 => scratch::write(root, "log.pglog", body),
        1 => scratch::write(root, "trial.csv", body),
        layout => {
            let dir = root.join("folder");
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).expect("scratch folder");
            match layout {
                2 => {
                    // Split at the first NUL: the stream, then the motion capture.
                    let (acc, mocap) = body.split_at(body.iter().position(|&b| b == 0).unwrap_or(body.len()));
                    scratch::write(&dir, "accelerometer.txt", acc);
                    scratch::write(&dir, "mocap.csv", mocap.get(1..).unwrap_or_default());
                    scratch::write(&dir, "timeAlignment.txt", b"0.5\n");
                }
                3 => {
                    scratch::write(&dir, "Accelerometer.csv", body);
                }
                _ => {
                    scratch::write(&dir, "Accelerometer.csv", b"time,seconds_elapsed,z,y,x\n1,0,9.8,0,0\n");
                    scratch::write(&dir, "Orientation.csv", body);
                }
            }
            dir
        }
    };
    let _ = import(&path);
});
