//! `cargo bench -p phantogram-assets --bench ibl` (or `cargo xtask bench ibl`): time to update the
//! image-based light from a changed environment map on this machine's CPU, release build — the
//! nine irradiance SH coefficients ([`IrradianceSh::from_environment`], on every core) beside a
//! plain texel-by-texel loop on one thread, and the specular levels ([`prefiltered_levels`] at the
//! renderer's 256-texel base) — for 1024-, 2048- and 4096-wide maps, as in the tabletop paper's
//! table; and the renderer's start-up tables (the split-sum table and the sheen's albedo table,
//! 64 × 64 each, made once per process on a background thread); and finding a room's sun
//! ([`phantogram_assets::ibl::sun::Sun::find`], once when a room is loaded). Each figure is the median of
//! several runs; the machine is shared and noisy, so compare
//! figures of one run only. Prints a Markdown table.

use std::time::Instant;

use phantogram_assets::ibl::sh::reference_projection;
use phantogram_assets::ibl::{
    Environment, IrradianceSh, brdf_lut, prefiltered_levels, sheen_albedo_table, ward_albedo_table,
};

/// The renderer's prefiltered base width (`phantogram_render`'s `PREFILTERED_BASE_WIDTH`).
const PREFILTERED_BASE_WIDTH: usize = 256;

/// Median milliseconds of `runs` calls of `f`, after one warm-up call.
fn median_ms<R>(runs: usize, mut f: impl FnMut() -> R) -> f64 {
    std::hint::black_box(f());
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            std::hint::black_box(f());
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[runs / 2]
}

/// Median milliseconds of `runs` calls of `f`, each on a fresh `input` made outside the timing
/// (and its result dropped outside it).
fn median_ms_of_each<I, R>(runs: usize, mut input: impl FnMut() -> I, mut f: impl FnMut(I) -> R) -> f64 {
    let mut t: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let given = input();
            let start = Instant::now();
            let out = std::hint::black_box(f(given));
            let ms = start.elapsed().as_secs_f64() * 1e3;
            drop(out);
            ms
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn main() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!("CPU: {cores} cores; median of several runs, ms\n");
    println!(
        "| map | SH9 (ours, {cores} cores) | SH9 texel by texel (1 core) | ratio | specular levels (256 base) | its sun found and taken out (1 core, the map not copied) |"
    );
    println!("|---|---|---|---|---|---|");
    for width in [1024, 2048, 4096] {
        let env = Environment::benchmark_sky(width);
        let runs = (4096 / width) * 10 + 5;
        let fast = median_ms(runs * 4, || IrradianceSh::from_environment(&env));
        let naive = median_ms(runs.min(9), || reference_projection(&env));
        let prefilter = median_ms(5, || prefiltered_levels(&env, PREFILTERED_BASE_WIDTH));
        let sun = median_ms_of_each(runs.min(9), || env.clone(), phantogram_assets::ibl::sun::Sun::take_out);
        println!(
            "| {width}×{} | {fast:.3} | {naive:.2} | {:.1}× | {prefilter:.1} | {sun:.1} |",
            width / 2,
            naive / fast
        );
    }
    // The renderer's `BRDF_LUT_SIZE`.
    let split_sum = median_ms(5, || brdf_lut(64));
    let sheen = median_ms(5, || sheen_albedo_table(64));
    let ward = median_ms(5, || ward_albedo_table(64));
    let stretched = median_ms(5, phantogram_assets::ibl::anisotropic_albedo::anisotropic_albedo_table);
    let sheen_direction = median_ms(5, phantogram_assets::ibl::sheen_direction::sheen_direction_table);
    println!(
        "\nstart-up tables, 64 × 64: split-sum {split_sum:.1} ms, sheen albedo {sheen:.1} ms, Ward albedo {ward:.1} ms, stretched lobes {stretched:.1} ms, sheen's mean directions (16 × 16) {sheen_direction:.1} ms ({cores} cores each)"
    );
}
