//! The generated assets in `assets/` match their generators (`cargo xtask assets`), so the default
//! replay cannot drift from the code that documents it.

use std::path::PathBuf;

use phantogram::synthetic::{ImuSpec, tilt_sweep};
use phantogram_lab::sensorlog::LogReader;

fn asset(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets").join(path)
}

#[test]
fn synthetic_tilt_log_matches_its_generator() {
    let path = asset("logs/tilt-sweep.pglog");
    let reader = LogReader::open(&path).unwrap_or_else(|e| panic!("{e} (run `cargo xtask assets`)"));
    assert!(
        reader
            .meta()
            .iter()
            .any(|(k, v)| k == "note" && v.contains("SYNTHETIC")),
        "the log must say it is synthetic"
    );
    let stored: Vec<_> = reader.collect::<Result<_, _>>().unwrap();
    let fresh = tilt_sweep(&ImuSpec::default());
    assert_eq!(stored.len(), fresh.len(), "stale asset: run `cargo xtask assets`");
    for (a, b) in stored.iter().zip(&fresh) {
        assert_eq!((a.t_ns, a.kind), (b.t_ns, b.kind));
        for (x, y) in a.value.iter().zip(b.value) {
            // Shortest round-trip formatting makes this exact on one platform; allow libm
            // differences in the last bits elsewhere.
            assert!(
                (x - y).abs() <= 1e-5 * y.abs().max(1.0),
                "stale asset at {} ns: {x} vs {y}",
                a.t_ns
            );
        }
    }
}
