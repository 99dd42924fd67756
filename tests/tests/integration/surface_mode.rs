//! Surface mode (`Placement::Surface`): the procedural medal at its true size with its front in
//! the plane of the glass, as a coin lying on the phone. Both eyes then see its face in the same
//! place (at most a pixel apart), and the frame matches its golden image. (How loaded models are
//! turned, sized and placed in surface mode: `phantogram_assets`' model tests.)

use crate::golden;

use phantogram::anaglyph::Method;
use phantogram::engine::{EngineConfig, Snapshot};
use phantogram::model::{DioramaFit, Placement};

const SIZE: (u32, u32) = (180, 400);

/// The disparity (pixels) between the eyes' images of the coin's face, and the mono frame.
fn disparity(placement: Placement) -> Option<(usize, Vec<u8>)> {
    let config = EngineConfig {
        method: Method::Mono,
        artifact: Some("builtin:medal".parse().expect("id")),
        fit: DioramaFit {
            placement,
            ..DioramaFit::default()
        },
        ..EngineConfig::default()
    };
    let mut e = phantogram_integration::engine_or_skip(config)?;
    e.resume_offscreen(SIZE.0, SIZE.1).expect("offscreen");
    e.draw(Some(0)).expect("draw");
    let mono = e.last_frame().expect("frame").2.to_vec();
    let (w, h, pair) = e.snapshot(Snapshot::SideBySide).expect("pair");
    assert_eq!((w, h), (2 * SIZE.0, SIZE.1));
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    // The horizontal shift (pixels) that best aligns the right eye's image of the coin's middle
    // with the left eye's: the disparity of what is there.
    let luma = |x: usize, y: usize| {
        let p = &pair[(y * 2 * w + x) * 4..][..3];
        i32::from(p[0]) + i32::from(p[1]) + i32::from(p[2])
    };
    let mut best = (i64::MAX, 0i32);
    for shift in -12i32..=12 {
        let mut sad = 0i64;
        for y in h / 3..2 * h / 3 {
            for x in w / 4..3 * w / 4 {
                let xr = (x as i32 + shift) as usize;
                sad += i64::from((luma(x, y) - luma(w + xr, y)).abs());
            }
        }
        best = best.min((sad, shift));
    }
    let differing = best.1.unsigned_abs() as usize;
    Some((differing, mono))
}

#[test]
fn the_coin_lies_in_the_glass_and_matches_its_golden_frame() {
    let Some((surface, frame)) = disparity(Placement::Surface) else {
        return;
    };
    println!("disparity between the eyes: {surface} px");
    // Its rim in the glass, its field 1.2 mm behind: at most a pixel apart.
    assert!(
        surface <= 1,
        "in the glass, both eyes see the face in one place: {surface} px apart"
    );
    golden::check("surface-medal", SIZE.0, SIZE.1, &frame, 3, 0.003);
}
