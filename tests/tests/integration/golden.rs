//! Golden images, shared by the rendering and screen tests (and included by the CLI's tests with
//! `#[path]`).
//!
//! Golden images live in `tests/golden/`. On a mismatch the test writes `NAME-actual.png` and
//! `NAME-difference.png` beside the golden image (git-ignored). `PHANTOGRAM_BLESS=1` rewrites the
//! golden images from the current output; look at them before committing.

use std::path::PathBuf;

/// `tests/golden/NAME.png` of the workspace, from whichever of its crates includes this file.
pub fn path(name: &str) -> PathBuf {
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let root = manifest
        .ancestors()
        .find(|p| p.join("tests/golden").is_dir())
        .unwrap_or(&manifest);
    root.join("tests/golden").join(format!("{name}.png"))
}

/// Compares `pixels` (`width × height` RGBA8) with `tests/golden/NAME.png`: fails if more than
/// `max_fraction` of the pixels differ by more than `tolerance` in any channel; writes actual and
/// difference images on failure.
pub fn check(name: &str, width: u32, height: u32, pixels: &[u8], tolerance: u8, max_fraction: f64) {
    let path = path(name);
    let save =
        |p: &PathBuf, data: &[u8]| image::save_buffer(p, data, width, height, image::ExtendedColorType::Rgba8).unwrap();
    if std::env::var_os("PHANTOGRAM_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        save(&path, pixels);
        return;
    }
    let golden = image::open(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (run with PHANTOGRAM_BLESS=1 to create it)", path.display()))
        .to_rgba8();
    assert_eq!(golden.dimensions(), (width, height), "{name}: golden image size");
    let mut diff = vec![0u8; pixels.len()];
    let mut bad = 0usize;
    for (i, (a, b)) in pixels.chunks(4).zip(golden.as_raw().chunks(4)).enumerate() {
        let d = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
        if d > tolerance {
            bad += 1;
        }
        let v = d.saturating_mul(8);
        diff[i * 4..i * 4 + 4].copy_from_slice(&[v, v, v, 255]);
    }
    let fraction = bad as f64 / (width * height) as f64;
    if fraction > max_fraction {
        let stem = path.with_extension("");
        save(&PathBuf::from(format!("{}-actual.png", stem.display())), pixels);
        save(&PathBuf::from(format!("{}-difference.png", stem.display())), &diff);
        panic!(
            "{name}: {bad} pixels ({:.3} %) differ by more than {tolerance} (allowed {:.3} %); see {}-actual.png and -difference.png",
            fraction * 100.0,
            max_fraction * 100.0,
            stem.display()
        );
    }
}
