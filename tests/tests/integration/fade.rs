//! Cross-fades between a part's levels (issue 22): while a part changes level both are drawn,
//! the new one on the fraction of pixels the fade says and the old one on exactly the others —
//! polygons to polygons and impostor to polygons. (When a fade begins and how it grows:
//! `phantogram_detail::fade`'s tests.)

use phantogram::FrameView;
use phantogram::glam::Vec3;
use phantogram::model::{LevelFade, Lod, Model};
use phantogram::render::{FrameInput, Gpu, IMPOSTOR_LEVEL, ImpostorBox, Renderer};

fn gpu() -> Option<Gpu> {
    phantogram_integration::gpu_or_skip()
}

const W: u32 = 360;
const H: u32 = 800;

fn oblique_view() -> FrameView {
    phantogram_integration::held_view(35.0, 0.1)
}

/// The amphora with a second level for its first primitive that is plainly different: the
/// first half of its triangles only.
fn amphora_with_a_half_level() -> Model {
    let mut model = phantogram::artifact::default_model();
    let p = &mut model.primitives[0];
    let half = p.mesh.indices.len() / 6 * 3;
    p.lods = vec![Lod {
        indices: p.mesh.indices[..half].to_vec(),
        error_m: 0.001,
    }];
    model
}

/// Of the pixels where `new` and `old` differ, the fraction `faded` shows `new`; and whether
/// every pixel of `faded` is `new`'s or `old`'s.
fn share_of_new(faded: &[u8], new: &[u8], old: &[u8]) -> (f64, usize, bool) {
    let (mut differ, mut shows_new, mut every) = (0usize, 0usize, true);
    for ((f, n), o) in faded.chunks_exact(4).zip(new.chunks_exact(4)).zip(old.chunks_exact(4)) {
        let close = |a: &[u8], b: &[u8]| a.iter().zip(b).all(|(x, y)| x.abs_diff(*y) <= 2);
        every &= close(f, n) || close(f, o);
        if !close(n, o) {
            differ += 1;
            if close(f, n) {
                shows_new += 1;
            }
        }
    }
    (shows_new as f64 / differ.max(1) as f64, differ, every)
}

#[test]
fn a_cross_fade_shows_each_level_on_its_share_of_the_pixels() {
    let Some(gpu) = gpu() else { return };
    let model = amphora_with_a_half_level();
    let mut renderer = Renderer::new(gpu, &model).unwrap();
    renderer.lighting.shadows = false;
    let view = oblique_view();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    let at = |levels: &[u8], fades: &[LevelFade], r: &mut Renderer| {
        let i = FrameInput { levels, fades, ..input };
        r.render_single(&view.left, &i, W, H).unwrap()
    };
    let full = at(&[0], &[], &mut renderer);
    let half = at(&[1], &[], &mut renderer);
    for shown in [0.1f32, 0.5, 0.9] {
        let fade = [LevelFade {
            primitive: 0,
            from: 1,
            shown,
        }];
        let faded = at(&[0], &fade, &mut renderer);
        let (share, differ, every) = share_of_new(&faded, &full, &half);
        println!("shown {shown}: {share:.3} of {differ} differing pixels at the new level");
        assert!(differ > 2_000, "{differ}");
        assert!(every, "shown {shown}: a pixel that is neither level's");
        assert!((share - f64::from(shown)).abs() < 0.03, "shown {shown}: {share}");
    }
    // The impostor fades into the polygons the same way.
    let bounds = ImpostorBox::around(
        model.primitives[0].mesh.vertices.iter().map(|v| Vec3::from(v.position)),
        128,
    )
    .expect("a box");
    renderer.bake_impostors(&[(0, bounds)]).unwrap();
    let relief = at(&[IMPOSTOR_LEVEL], &[], &mut renderer);
    let fade = [LevelFade {
        primitive: 0,
        from: IMPOSTOR_LEVEL,
        shown: 0.4,
    }];
    let faded = at(&[0], &fade, &mut renderer);
    let (share, differ, every) = share_of_new(&faded, &full, &relief);
    println!("impostor → polygons at 0.4: {share:.3} of {differ} differing pixels");
    assert!(
        differ > 500 && every && (share - 0.4).abs() < 0.05,
        "{share} {differ} {every}"
    );
}
