//! `cargo bench -p phantogram-render --bench prefilter` (or `cargo xtask bench ibl`, after the CPU
//! figures): what one update of the image-based light costs where the specular levels are
//! convolved on the GPU ([`GpuPrefilter`]), for 1024-, 2048- and 4096-wide maps as in the tabletop
//! paper's table (`benchmarks/ibl.md`):
//!
//! * SH9 on the CPU, every core ([`IrradianceSh::from_environment`]; the renderer's path);
//! * level 0 resampled on the CPU at the renderer's 256-texel base ([`prefilter_base`]);
//! * its halvings packed as `f16` rows for upload ([`PrefilterUpload::new`]; the room-light
//!   worker's share beside SH9 and level 0; timed with a copy of level 0 the worker does not make);
//! * the convolution of levels 1… on the GPU at that base, from timestamp queries (GPU time
//!   only), the render thread's share of [`GpuPrefilter::run_upload`] (writing the packed
//!   bytes, recording, submitting; not waited for) and the whole run waited for;
//! * the same convolution at the map's own width (level 0 = the map), the paper's setting.
//!
//! Medians of several runs after a warm-up. On a machine without a GPU the adapter is a software
//! one (lavapipe): the figures then say nothing about a GPU, and the adapter is printed first.

use std::time::Instant;

use phantogram_assets::ibl::PrefilterSources;
use phantogram_assets::ibl::{Environment, IrradianceSh, prefilter_base};
use phantogram_render::prefilter_gpu::{GpuPrefilter, PrefilterUpload};
use phantogram_render::{Gpu, PREFILTERED_BASE_WIDTH as BASE_WIDTH};

fn median(mut samples: Vec<f64>) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

/// Median wall milliseconds of `runs` calls of `f` after one warm-up call.
fn wall_ms<R>(runs: usize, mut f: impl FnMut() -> R) -> f64 {
    std::hint::black_box(f());
    median(
        (0..runs)
            .map(|_| {
                let start = Instant::now();
                std::hint::black_box(f());
                start.elapsed().as_secs_f64() * 1e3
            })
            .collect(),
    )
}

/// Median wall milliseconds of `run` alone (a [`GpuPrefilter`] run, not waited for) over `runs`
/// runs, the GPU drained after each: what the render thread spends on an update.
fn submit_ms(
    gpu: &Gpu,
    prefilter: &mut GpuPrefilter,
    runs: usize,
    mut run_once: impl FnMut(&mut GpuPrefilter) -> Result<phantogram_render::wgpu::Texture, phantogram_render::RenderError>,
) -> f64 {
    let mut wall = Vec::new();
    for run in 0..=runs {
        let start = Instant::now();
        if let Err(e) = run_once(prefilter) {
            eprintln!("the GPU prefilter failed: {e}");
            std::process::exit(1);
        }
        if run > 0 {
            wall.push(start.elapsed().as_secs_f64() * 1e3);
        }
        let _ = gpu.device.poll(phantogram_render::wgpu::PollType::wait_indefinitely());
    }
    median(wall)
}

/// Median wall milliseconds of submitting an empty command buffer, the GPU drained after each: the
/// floor under any submission's cost on the render thread.
fn empty_submit_ms(gpu: &Gpu, runs: usize) -> f64 {
    let mut wall = Vec::new();
    for run in 0..=runs {
        let encoder = gpu.device.create_command_encoder(&Default::default());
        let start = Instant::now();
        gpu.queue.submit([encoder.finish()]);
        if run > 0 {
            wall.push(start.elapsed().as_secs_f64() * 1e3);
        }
        let _ = gpu.device.poll(phantogram_render::wgpu::PollType::wait_indefinitely());
    }
    median(wall)
}

/// Median GPU milliseconds of the convolution and median wall milliseconds of the whole run, over
/// `runs` runs after a warm-up; `None` for the GPU time where the device has no timestamps.
fn prefilter_ms(gpu: &Gpu, prefilter: &mut GpuPrefilter, base: &Environment, runs: usize) -> (Option<f64>, f64) {
    let mut gpu_ms = Vec::new();
    let mut wall = Vec::new();
    for run in 0..=runs {
        let start = Instant::now();
        let (_, ms) = match prefilter.run_timed(gpu, base) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("the GPU prefilter failed: {e}");
                std::process::exit(1);
            }
        };
        if run > 0 {
            wall.push(start.elapsed().as_secs_f64() * 1e3);
            gpu_ms.extend(ms);
        }
    }
    let gpu_ms = (gpu_ms.len() == runs).then(|| median(gpu_ms));
    (gpu_ms, median(wall))
}

fn main() {
    let gpu = match Gpu::headless() {
        Ok(gpu) => gpu,
        Err(e) => {
            println!("no GPU adapter ({e}): skipping the GPU prefilter benchmark");
            return;
        }
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!("adapter: {}; CPU: {cores} cores", gpu.describe());
    let Some(mut prefilter) = GpuPrefilter::new(&gpu) else {
        println!("this adapter has no compute shaders or Rgba16Float storage: the renderer keeps the CPU path");
        return;
    };
    println!(
        "an empty submission: {:.3} ms on this thread",
        empty_submit_ms(&gpu, 51)
    );
    let shown = |ms: Option<f64>| ms.map_or("no timestamps".to_string(), |ms| format!("{ms:.3}"));
    println!("median of several runs, ms\n");
    println!(
        "| map | SH9 (CPU, {cores} cores) | level 0 at {BASE_WIDTH} (CPU) | halvings packed (CPU) | levels on the GPU, {BASE_WIDTH} base | render thread, {BASE_WIDTH} base: from the upload / from level 0 | whole run at {BASE_WIDTH}, waited | update total | levels on the GPU at the map's width | whole run at the map's width, waited |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for width in [1024, 2048, 4096] {
        let env = Environment::benchmark_sky(width);
        let runs = (4096 / width) * 10 + 5;
        let sh = wall_ms(runs * 4, || IrradianceSh::from_environment(&env));
        let resample = wall_ms(runs, || prefilter_base(&env, BASE_WIDTH));
        let base = prefilter_base(&env, BASE_WIDTH);
        let pack = wall_ms(runs, || PrefilterUpload::new(PrefilterSources::new(base.clone())));
        let upload = match PrefilterUpload::new(PrefilterSources::new(base.clone())) {
            Ok(upload) => upload,
            Err(e) => {
                eprintln!("level 0 could not be packed: {e}");
                std::process::exit(1);
            }
        };
        let (small_gpu, small_wall) = prefilter_ms(&gpu, &mut prefilter, &base, runs);
        // The render thread's share: from the worker's upload (the live room light), and from
        // level 0 alone (a still environment set on the render thread: halvings and packing
        // there too).
        let submit = submit_ms(&gpu, &mut prefilter, runs, |p| p.run_upload(&gpu, &upload));
        let submit_base = submit_ms(&gpu, &mut prefilter, runs, |p| p.run(&gpu, &base));
        let full = prefilter_base(&env, width);
        let (full_gpu, full_wall) = prefilter_ms(&gpu, &mut prefilter, &full, runs.min(11));
        // One update as the engine makes it: SH9, level 0 and the packing on the room light's
        // worker, the convolution on the GPU.
        let total = small_gpu.map(|g| sh + resample + pack + g);
        println!(
            "| {width}×{} | {sh:.3} | {resample:.3} | {pack:.3} | {} | {submit:.3} / {submit_base:.3} | {small_wall:.3} | {} | {} | {full_wall:.2} |",
            width / 2,
            shown(small_gpu),
            shown(total),
            shown(full_gpu),
        );
    }
}
