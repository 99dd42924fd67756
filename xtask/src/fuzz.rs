//! `cargo xtask fuzz [TARGET…] [--seconds N] [--runs N] [--workers N] [--record]`: the
//! cargo-fuzz targets in `fuzz/`, each seeded and run with the project's limits, and a table of
//! what each run did.
//!
//! * Targets: `gltf` (models and Voyager scenes), `import` (every sensor-log importer), `replay`
//!   (a log through a session), `calibration`, `environment` (HDR/EXR through the guards) and
//!   `c_abi` (random call sequences through the C ABI; it links the whole engine and needs a
//!   GPU adapter such as lavapipe), `jni` (the same through the JNI bridge, driven by
//!   `android/tests/java/RandomCalls.java` in a JVM inside the fuzzer's process; also needs a
//!   JDK, and leaves `SIGSEGV`, `SIGBUS`, `SIGFPE` and `SIGILL` to the JVM). All of them when
//!   none is named.
//! * Limits: 1 GiB of Rust heap per input (counted by each target's allocator,
//!   `fuzz/fuzz_targets/heap_limit.rs`: an input that grows the heap by more is a finding),
//!   resident memory 2 GiB plus twice the corpus on disk as a backstop (`-rss_limit_mb`: the
//!   process also holds libFuzzer's copy of the corpus, which grows during a run, and memory
//!   that is not Rust heap, such as lavapipe's and the JVM's), 10 s per input (`-timeout=10`: an
//!   input that runs longer is a finding), each target for `--seconds` (default 30), or until it
//!   has made `--runs` executions if that comes first (issue 17's long runs: `--runs 10000000
//!   --seconds 14400`, 10⁷ executions or 4 h). The table gives the seconds the run took.
//! * `--workers N` (default 1): N fuzzing processes at once, in libFuzzer's fork mode
//!   (`-fork=N`): a parent hands each worker a sample of the corpus for up to 300 s at a time,
//!   merges what it found and counts the executions of all of them; a timeout, an out-of-memory or
//!   a crash in any worker stops the run as a finding (`-ignore_timeouts=0 -ignore_ooms=0`: fork
//!   mode's defaults would go on). Each worker holds only its sample of the corpus, not all of it.
//!   Peak memory is not reported in this mode (the workers' logs go with their temporary folder).
//! * Seeds: small inputs written here (valid files and the hostile cases that were once bugs),
//!   plus, when `PHANTOGRAM_DATA` is set, the shared models, recordings and environments,
//!   copied into the corpus folder under `target/fuzz/corpus/TARGET` (never into the
//!   repository). The corpus grows across runs; findings go to `target/fuzz/artifacts/TARGET`.
//! * Runs on the stable toolchain without a sanitizer (`--sanitizer none`): safe Rust needs none
//!   to find panics, hangs and runaway memory. Needs `cargo install cargo-fuzz --locked`.
//! * Scratch files (the targets that write each input to a file for the code under test to
//!   open) go to a folder made for the run (`PHANTOGRAM_FUZZ_SCRATCH`, read by
//!   `fuzz/fuzz_targets/scratch.rs`; the build keeps the usual `TMPDIR`) and removed after it: on
//!   `/dev/shm` where that is writable, else in the temporary folder. They are rewritten for
//!   every input, and on a RAM-backed folder no input waits on the disk (`import` ran 1644
//!   executions a second with them on this machine's disk, 2087 on `/dev/shm`, 45 s each).
//! * `--record` puts each target's row into `benchmarks/fuzz.md` (replacing that target's older
//!   row, keeping the others').

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::workspace_root;

#[path = "../../android/tests/support/jdk.rs"]
mod jdk;

/// (name, the longest input it is given, the cargo feature it needs).
const TARGETS: [(&str, usize, Option<&str>); 7] = [
    ("gltf", 1 << 20, None),
    ("import", 64 << 10, None),
    ("replay", 64 << 10, None),
    ("calibration", 4 << 10, None),
    ("environment", 1 << 20, None),
    ("c_abi", 4 << 10, Some("ffi")),
    ("jni", 4 << 10, Some("java")),
];

/// A new folder for one run's scratch files: on `/dev/shm` (RAM-backed) where this system lets
/// us make one there, else in the temporary folder.
fn scratch_folder(target: &str) -> Result<PathBuf> {
    let name = format!("phantogram-xtask-fuzz-{target}-{}", std::process::id());
    let shm = Path::new("/dev/shm").join(&name);
    if std::fs::create_dir_all(&shm).is_ok() {
        return Ok(shm);
    }
    let tmp = std::env::temp_dir().join(name);
    std::fs::create_dir_all(&tmp).with_context(|| format!("creating {}", tmp.display()))?;
    Ok(tmp)
}

/// The files directly in `dir` (none if it cannot be read).
fn folder_files(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .collect()
}

/// The size of the files directly in `dir`, MiB (rounded up).
fn folder_mb(dir: &Path) -> u64 {
    let bytes: u64 = folder_files(dir)
        .iter()
        .filter_map(|p| std::fs::metadata(p).ok())
        .map(|m| m.len())
        .sum();
    bytes.div_ceil(1 << 20)
}

/// What one run did, from libFuzzer's final statistics.
struct Outcome {
    target: &'static str,
    seconds: u64,
    executions: u64,
    coverage: u64,
    corpus: u64,
    /// `None` in fork mode (`--workers` above 1), whose parent does not report it.
    peak_rss_mb: Option<u64>,
    finding: Option<String>,
}

/// A flag's value: a whole number, at least 1, of `what`.
fn count<T: std::str::FromStr + PartialOrd + From<u8>>(value: Option<&&str>, flag: &str, what: &str) -> Result<T> {
    value
        .and_then(|s| s.parse().ok())
        .filter(|n| *n >= T::from(1))
        .with_context(|| format!("{flag} needs a whole number of {what}, at least 1"))
}

pub fn fuzz(args: &[&str]) -> Result<()> {
    let mut seconds = 30u64;
    let mut runs: Option<u64> = None;
    let mut workers = 1u32;
    let mut record = false;
    let mut chosen = Vec::new();
    let mut rest = args.iter();
    while let Some(&arg) = rest.next() {
        match arg {
            "--seconds" => seconds = count(rest.next(), "--seconds", "seconds")?,
            "--runs" => runs = Some(count(rest.next(), "--runs", "executions")?),
            "--workers" => workers = count(rest.next(), "--workers", "processes")?,
            "--record" => record = true,
            name => match TARGETS.iter().find(|t| t.0 == name) {
                Some(t) => chosen.push(*t),
                None => bail!(
                    "unknown fuzz target {name:?}; the targets: {}",
                    TARGETS.map(|t| t.0).join(", ")
                ),
            },
        }
    }
    // Where the jni target looks for a JDK (it starts a JVM).
    let jdk_found = jdk::java_homes().next().is_some();
    if chosen.is_empty() {
        chosen = TARGETS.to_vec();
        // All targets: the ones this machine can run (named, jni without a JDK is an error).
        if !jdk_found {
            eprintln!("no JDK found (set JAVA_HOME): the jni target is left out");
            chosen.retain(|t| t.0 != "jni");
        }
    }
    let version = Command::new("cargo").args(["fuzz", "--version"]).output();
    if !version.is_ok_and(|o| o.status.success()) {
        bail!("cargo-fuzz is not installed: `cargo install cargo-fuzz --locked` (about a minute)");
    }
    // Without a JDK the jni target could only fail, which is not a finding.
    if chosen.iter().any(|t| t.0 == "jni") && !jdk_found {
        bail!(
            "the jni target needs a JDK (javac and libjvm): set JAVA_HOME, or install one \
             (Debian: openjdk-17-jdk-headless)"
        );
    }
    let root = workspace_root();
    let mut outcomes = Vec::new();
    for (target, max_len, feature) in chosen {
        let corpus = root.join("target/fuzz/corpus").join(target);
        let artifacts = root.join("target/fuzz/artifacts").join(target);
        std::fs::create_dir_all(&corpus).with_context(|| format!("creating {}", corpus.display()))?;
        std::fs::create_dir_all(&artifacts).with_context(|| format!("creating {}", artifacts.display()))?;
        seed(target, &corpus, max_len)?;
        match runs {
            Some(n) => println!(
                "fuzzing {target} for {n} executions or {seconds} s (corpus {})",
                corpus.display()
            ),
            None => println!("fuzzing {target} for {seconds} s (corpus {})", corpus.display()),
        }
        let mut command = Command::new("cargo");
        command.args(["fuzz", "run", "--sanitizer", "none", "--release"]);
        if let Some(feature) = feature {
            command.args(["--features", feature]);
        }
        command
            .arg(target)
            .arg(&corpus)
            .arg("--")
            .arg(format!("-max_total_time={seconds}"))
            .arg(format!("-rss_limit_mb={}", 2048 + 2 * folder_mb(&corpus)))
            .arg("-timeout=10")
            .arg(format!("-max_len={max_len}"))
            .arg("-print_final_stats=1")
            .arg(format!("-artifact_prefix={}/", artifacts.display()))
            .current_dir(&root);
        if let Some(runs) = runs {
            command.arg(format!("-runs={runs}"));
        }
        if workers > 1 {
            command.args([
                &format!("-fork={workers}"),
                "-ignore_timeouts=0",
                "-ignore_ooms=0",
                "-ignore_crashes=0",
            ]);
        }
        if target == "jni" {
            // The JVM in that process uses these signals itself (null checks, safepoints) and
            // reports its own crashes.
            command.args(["-handle_segv=0", "-handle_bus=0", "-handle_fpe=0", "-handle_ill=0"]);
        }
        let run_began = std::time::SystemTime::now();
        let scratch = scratch_folder(target)?;
        command.env("PHANTOGRAM_FUZZ_SCRATCH", &scratch);
        let started = std::time::Instant::now();
        let output = command.output();
        let wall_s = started.elapsed().as_secs();
        let _ = std::fs::remove_dir_all(&scratch);
        let output = output.with_context(|| format!("running cargo fuzz for {target}"))?;
        let log = String::from_utf8_lossy(&output.stderr);
        let stat = |name: &str| {
            log.lines()
                .find_map(|l| l.strip_prefix(&format!("stat::{name}:")))
                .and_then(|v| v.trim().parse::<u64>().ok())
        };
        // The last progress line: `#N  DONE  cov: C ft: F corp: K/…`.
        let field = |name: &str| {
            log.lines().rev().find_map(|l| {
                l.split(name)
                    .nth(1)?
                    .split_whitespace()
                    .next()?
                    .split('/')
                    .next()?
                    .parse()
                    .ok()
            })
        };
        // `-Xcheck:jni` (the jni target's JVM) reports misuse it can go on from — such as a JNI
        // call made with an exception pending — as a warning on the JVM's standard output, not
        // as a crash: a finding all the same, though no single input is saved for it.
        let jvm_output = String::from_utf8_lossy(&output.stdout);
        let jni_warning = [&*jvm_output, &*log]
            .into_iter()
            .flat_map(str::lines)
            .find(|l| l.contains("WARNING in native method") || l.contains("WARNING: JNI local refs"));
        // Every input libFuzzer saved is a finding, whatever the exit status: fork mode's parent
        // drops an input of the corpus that crashes while it merges the corpus (saving it) and
        // goes on. Told by time, not name: an input an earlier run saved is saved again under the
        // same name.
        let saved: Vec<PathBuf> = folder_files(&artifacts)
            .into_iter()
            .filter(|p| {
                std::fs::metadata(p)
                    .and_then(|m| m.modified())
                    .is_ok_and(|t| t >= run_began)
            })
            .collect();
        let finding = if !output.status.success() {
            Some(
                log.lines()
                    .find(|l| l.contains("Test unit written to") || l.contains("panicked at"))
                    .unwrap_or("the run failed; see its log")
                    .trim()
                    .to_owned(),
            )
        } else if let Some(first) = saved.first() {
            Some(format!("{} input(s) saved, e.g. {}", saved.len(), first.display()))
        } else {
            jni_warning.map(|l| format!("-Xcheck:jni: {}", l.trim()))
        };
        if let Some(f) = &finding {
            // The whole log, for the one that failed.
            eprintln!("{jvm_output}{log}");
            eprintln!("{target}: FINDING: {f}");
        }
        let executions = if workers > 1 {
            fork_executions(&log)
        } else {
            stat("number_of_executed_units")
        };
        let Some(executions) = executions else {
            bail!("{target}: no statistics from libFuzzer (did it build?):\n{log}");
        };
        // libFuzzer's own count of seconds; else the wall time, build included.
        let took_s = libfuzzer_seconds(&log).unwrap_or(wall_s).max(1);
        outcomes.push(Outcome {
            target,
            seconds: took_s,
            executions,
            coverage: field("cov: ").unwrap_or(0),
            corpus: field("corp: ").unwrap_or(0),
            peak_rss_mb: if workers > 1 { None } else { stat("peak_rss_mb") },
            finding,
        });
    }
    let rows: Vec<String> = outcomes.iter().map(row).collect();
    println!("{TABLE_HEAD}{}", rows.concat());
    if record {
        let path = root.join("benchmarks/fuzz.md");
        // A target's row is replaced by its newest run; the other targets' rows stay.
        let old = std::fs::read_to_string(&path).unwrap_or_default();
        let mut kept: Vec<String> = old
            .lines()
            .filter(|l| l.starts_with("| ") && !l.starts_with("| target"))
            .filter(|l| !outcomes.iter().any(|o| l.starts_with(&format!("| {} |", o.target))))
            .map(|l| format!("{l}\n"))
            .collect();
        kept.extend(rows);
        kept.sort_by_key(|l| TARGETS.iter().position(|t| l.starts_with(&format!("| {} |", t.0))));
        // Notes written under the table stay.
        let notes: String = old
            .lines()
            .skip_while(|l| !l.starts_with('|'))
            .skip_while(|l| l.starts_with('|'))
            .map(|l| format!("{l}\n"))
            .collect();
        let text = format!(
            "# Fuzzing\n\nEach row is the newest `cargo xtask fuzz TARGET --seconds N [--runs N] \
             [--workers N] --record` of its target (`PHANTOGRAM_DATA` set for the seeds; the corpus \
             under `target/fuzz` kept from earlier runs): stable Rust, no sanitizer, 1 GiB of heap per \
             input, 10 s per input, on this project's shared 2-core machine (peak RSS `-`: a run with \
             `--workers`, libFuzzer's fork mode, which does not report it). Coverage is libFuzzer's \
             `cov:` (edges reached); corpus, the inputs kept; findings, the inputs that panicked, hung \
             or ran out of memory (each fixed and kept as a regression test).\n\n{TABLE_HEAD}{}{notes}",
            kept.concat()
        );
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    let found: Vec<&str> = outcomes
        .iter()
        .filter(|o| o.finding.is_some())
        .map(|o| o.target)
        .collect();
    if !found.is_empty() {
        bail!("findings in: {} (inputs under target/fuzz/artifacts)", found.join(", "));
    }
    Ok(())
}

/// The executions of all workers in fork mode, whose parent prints no final statistics: the last
/// of its progress lines `#N: cov: C ft: F corp: K exec/s: … time: Ts …`.
fn fork_executions(log: &str) -> Option<u64> {
    log.lines()
        .rev()
        .find_map(|l| l.strip_prefix('#')?.split(": cov: ").next()?.parse().ok())
}

/// The seconds libFuzzer says the run took: `Done N runs in S second(s)`, or in fork mode
/// `INFO: exiting: CODE time: Ss`.
fn libfuzzer_seconds(log: &str) -> Option<u64> {
    log.lines().rev().find_map(|l| {
        let after = match l.strip_prefix("Done ") {
            Some(done) => done.split(" runs in ").nth(1)?,
            None => l.strip_prefix("INFO: exiting: ")?.split(" time: ").nth(1)?,
        };
        after.split(|c: char| !c.is_ascii_digit()).next()?.parse().ok()
    })
}

const TABLE_HEAD: &str = "| target | date | seconds | executions | exec/s | coverage (edges) | corpus | peak RSS (MB) | findings |\n|---|---|---:|---:|---:|---:|---:|---:|---|\n";

fn row(o: &Outcome) -> String {
    let date = Command::new("date")
        .arg("+%Y-%m-%d")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
        .unwrap_or_default();
    format!(
        "| {} | {date} | {} | {} | {} | {} | {} | {} | {} |\n",
        o.target,
        o.seconds,
        o.executions,
        o.executions / o.seconds.max(1),
        o.coverage,
        o.corpus,
        o.peak_rss_mb.map_or("-".to_owned(), |mb| mb.to_string()),
        o.finding.as_deref().unwrap_or("0")
    )
}

/// Writes the target's seeds into its corpus folder (overwriting earlier seeds of the same name,
/// leaving what the fuzzer added).
fn seed(target: &str, corpus: &Path, max_len: usize) -> Result<()> {
    let put = |name: &str, bytes: &[u8]| -> Result<()> {
        let bytes = &bytes[..bytes.len().min(max_len)];
        std::fs::write(corpus.join(format!("seed-{name}")), bytes).with_context(|| format!("writing seed {name}"))
    };
    let data = std::env::var_os("PHANTOGRAM_DATA").map(PathBuf::from);
    let shared = |sub: &str, extensions: &[&str]| -> Vec<PathBuf> {
        let mut found = Vec::new();
        if let Some(dir) = &data {
            files_under(&dir.join(sub), &mut found);
        }
        found.retain(|p| {
            let name = p.to_string_lossy().to_lowercase();
            extensions.iter().any(|e| name.ends_with(e))
        });
        found.sort();
        found
    };
    let seed_name = |p: &Path| p.to_string_lossy().replace(['/', ' '], "_");
    let tri_gltf = r#"{"asset":{"version":"2.0"},"buffers":[{"byteLength":36,"uri":"tri.bin"}],"bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],"images":[{"uri":"tex.png"}],"textures":[{"source":0}],"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0}"#;
    match target {
        "gltf" => {
            put("triangle.gltf", tri_gltf.as_bytes())?;
            put(
                "outside.gltf",
                tri_gltf.replace("tri.bin", "../../etc/passwd").as_bytes(),
            )?;
            put(
                "zero-filled.gltf",
                br#"{"asset":{"version":"2.0"},"accessors":[{"componentType":5126,"count":22000000,"type":"VEC3"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}},{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]}"#,
            )?;
            put(
                "scene.svx.json",
                br#"{"models":[{"rotation":[0,0,0,1],"derivatives":[{"usage":"Web3D","quality":"High","assets":[{"uri":"model.glb"}]}]}]}"#,
            )?;
            // Strips and fans, and a specular-glossiness material over a WebP-only texture.
            put(
                "strip.gltf",
                tri_gltf
                    .replace(r#""material":0"#, r#""material":0,"mode":5"#)
                    .as_bytes(),
            )?;
            put(
                "fan.gltf",
                tri_gltf
                    .replace(r#""material":0"#, r#""material":0,"mode":6"#)
                    .as_bytes(),
            )?;
            put(
                "spec-gloss-webp.gltf",
                tri_gltf
                    .replace(
                        r#""textures":[{"source":0}]"#,
                        r#""textures":[{"extensions":{"EXT_texture_webp":{"source":0}}}]"#,
                    )
                    .replace(
                        r#""pbrMetallicRoughness":{"baseColorTexture":{"index":0}}"#,
                        r#""extensions":{"KHR_materials_pbrSpecularGlossiness":{"diffuseTexture":{"index":0},"specularGlossinessTexture":{"index":0},"glossinessFactor":0.5}}"#,
                    )
                    .as_bytes(),
            )?;
            // The triangle with a morph target (its own positions, at half weight).
            put(
                "morph.gltf",
                tri_gltf
                    .replace(
                        r#""attributes":{"POSITION":0},"material":0"#,
                        r#""attributes":{"POSITION":0},"targets":[{"POSITION":0}],"material":0"#,
                    )
                    .replace(r#""nodes":[{"mesh":0}]"#, r#""nodes":[{"mesh":0,"weights":[0.5]}]"#)
                    .as_bytes(),
            )?;
            // The triangle in amber glass (with a sheen): every material extension `model::layers` reads.
            put(
                "glass.gltf",
                tri_gltf
                    .replace(
                        r#""materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}]"#,
                        r#""materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}},"extensions":{"KHR_materials_transmission":{"transmissionFactor":1,"transmissionTexture":{"index":0}},"KHR_materials_volume":{"thicknessFactor":0.1,"thicknessTexture":{"index":0,"texCoord":1},"attenuationDistance":0.2,"attenuationColor":[0.9,0.5,0.1]},"KHR_materials_ior":{"ior":1.54},"KHR_materials_specular":{"specularFactor":0.8,"specularColorFactor":[1,0.9,0.8]},"KHR_materials_clearcoat":{"clearcoatFactor":0.5,"clearcoatRoughnessFactor":0.1,"clearcoatTexture":{"index":0},"clearcoatNormalTexture":{"index":0,"scale":0.5}},"KHR_materials_sheen":{"sheenColorFactor":[0.3,0.2,0.1],"sheenRoughnessFactor":0.6,"sheenColorTexture":{"index":0,"texCoord":1}},"KHR_materials_dispersion":{"dispersion":0.4},"KHR_materials_diffuse_transmission":{"diffuseTransmissionFactor":0.25,"diffuseTransmissionTexture":{"index":0}},"KHR_materials_anisotropy":{"anisotropyStrength":0.6,"anisotropyRotation":1.57,"anisotropyTexture":{"index":0}},"KHR_materials_iridescence":{"iridescenceFactor":1,"iridescenceIOR":1.8,"iridescenceThicknessTexture":{"index":0}}}}]"#,
                    )
                    .as_bytes(),
            )?;
            // A skinned triangle over the target's `tri.bin` (joints and weights read from its
            // bytes).
            put(
                "skinned.gltf",
                br#"{"asset":{"version":"2.0"},"buffers":[{"byteLength":36,"uri":"tri.bin"}],"bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},{"bufferView":0,"componentType":5121,"count":3,"type":"VEC4"},{"bufferView":0,"byteOffset":12,"componentType":5121,"normalized":true,"count":3,"type":"VEC4"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0,"JOINTS_0":1,"WEIGHTS_0":2}}]}],"skins":[{"joints":[1]}],"nodes":[{"mesh":0,"skin":0},{"translation":[0,1,0]}],"scenes":[{"nodes":[0,1]}],"scene":0}"#,
            )?;
            // The triangle drawn twice by `EXT_mesh_gpu_instancing` (the instances' translations
            // read from `tri.bin`'s first two vertices).
            put(
                "instanced.gltf",
                tri_gltf
                    .replace(
                        r#""nodes":[{"mesh":0}]"#,
                        r#""nodes":[{"mesh":0,"extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"TRANSLATION":1}}}}]"#,
                    )
                    .replace(
                        r#""type":"VEC3","min":[0,0,0],"max":[1,1,0]}]"#,
                        r#""type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"bufferView":0,"componentType":5126,"count":2,"type":"VEC3"}]"#,
                    )
                    .as_bytes(),
            )?;
            put(
                "triangle.glb",
                &glb(tri_gltf.replace(r#","uri":"tri.bin""#, "").as_bytes(), &triangle_bin()),
            )?;
            // The triangle textured by each KTX 2.0 / Basis Universal test texture (ETC1S with
            // mips, UASTC under Zstandard), embedded after the positions.
            for name in ["pattern-rgba-etc1s.ktx2", "pattern-rgb-uastc.ktx2"] {
                let ktx2 = std::fs::read(workspace_root().join("core/assets/tests/data/ktx2").join(name))
                    .with_context(|| format!("reading the test texture {name}"))?;
                let mut bin = triangle_bin();
                bin.extend_from_slice(&ktx2);
                let json = tri_gltf
                    .replace(r#","uri":"tri.bin""#, "")
                    .replace(
                        r#""buffers":[{"byteLength":36}]"#,
                        &format!(r#""buffers":[{{"byteLength":{}}}]"#, bin.len()),
                    )
                    .replace(
                        r#""bufferViews":[{"buffer":0,"byteLength":36}]"#,
                        &format!(
                            r#""bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":{}}}]"#,
                            ktx2.len()
                        ),
                    )
                    .replace(r#""images":[{"uri":"tex.png"}]"#, r#""images":[{"bufferView":1,"mimeType":"image/ktx2"}]"#)
                    .replace(
                        r#""textures":[{"source":0}]"#,
                        r#""extensionsRequired":["KHR_texture_basisu"],"textures":[{"extensions":{"KHR_texture_basisu":{"source":0}}}]"#,
                    );
                put(&format!("{name}.glb"), &glb(json.as_bytes(), &bin))?;
            }
            // A laser scan: 50 points as LAZ (`core/assets/tests/data/las`), and its header marked
            // uncompressed over 50 point records of zeros, as plain LAS.
            let laz = std::fs::read(workspace_root().join("core/assets/tests/data/las/sphere-50.laz"))
                .context("reading the test cloud sphere-50.laz")?;
            put("sphere-50.laz", &laz)?;
            let mut las = laz.clone();
            if let Some(format) = las.get_mut(104) {
                *format &= 0x3f; // the compression bits cleared
            }
            let offset = las
                .get(96..100)
                .and_then(|b| b.try_into().ok())
                .map_or(0, |b: [u8; 4]| u32::from_le_bytes(b) as usize);
            las.truncate(offset);
            las.resize(offset + 50 * 26, 0);
            put("zeros-50.las", &las)?;
            // A LAZ of several variable-sized chunks (`model::laz_chunks`), and files other
            // programs wrote: a layered LAZ (point format 7, by the reference LASzip:
            // `model::laz_layers`), and scans naming their coordinate system as PROJ
            // writes it: WKT2 of a compound system (in feet; LAZ) and GeoTIFF keys (in degrees;
            // LAS) (`model::las_crs`).
            for name in [
                "chunked-60.laz",
                "reference-sphere-200.laz",
                "reference-sphere-200-feet.laz",
                "reference-sphere-200-degrees.las",
            ] {
                let bytes = std::fs::read(workspace_root().join("core/assets/tests/data/las").join(name))
                    .with_context(|| format!("reading the test cloud {name}"))?;
                put(name, &bytes)?;
            }
            // And as E57: two scans, each placed by its pose (`core/assets/tests/data/e57`).
            let e57 = std::fs::read(workspace_root().join("core/assets/tests/data/e57/sphere-50.e57"))
                .context("reading the test scan sphere-50.e57")?;
            put("sphere-50.e57", &e57)?;
            // The same by the reference library, libE57Format (its own section layout).
            let e57 = std::fs::read(workspace_root().join("core/assets/tests/data/e57/reference-sphere-200.e57"))
                .context("reading the test scan reference-sphere-200.e57")?;
            put("reference-sphere-200.e57", &e57)?;
            // USD by Pixar's own library (`core/assets/tests/data/usd`): a package (a referenced
            // layer and a texture inside), its root layer alone in the binary format, the
            // referenced layer in the text format, a material placing its textures through
            // transforms and named primvars, a point cloud in the binary format, and one prim of
            // each primitive shape.
            for (name, file) in [
                ("reference-box.usdz", "reference-box.usdz"),
                ("reference-box.usdc", "loose/reference-box.usdc"),
                ("knob.usda", "loose/parts/knob.usda"),
                ("texture-coordinates.usda", "coords/texture-coordinates.usda"),
                ("points.usdc", "points.usdc"),
                ("shapes.usda", "shapes.usda"),
            ] {
                let bytes = std::fs::read(workspace_root().join("core/assets/tests/data/usd").join(file))
                    .with_context(|| format!("reading the test stage {file}"))?;
                put(name, &bytes)?;
            }
            // A tetrahedron as binary STL (its header begins "solid", as many do), as ASCII STL,
            // and as binary PLY with a colour per vertex.
            let corners = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            let faces = [[0usize, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
            let mut stl = b"solid tetrahedron".to_vec();
            stl.resize(80, b' ');
            stl.extend(4u32.to_le_bytes());
            let mut ascii = String::from("solid tetrahedron\n");
            for f in faces {
                stl.extend([0u8; 12]);
                ascii += "facet normal 0 0 0\nouter loop\n";
                for &i in &f {
                    stl.extend(corners[i].iter().flat_map(|c| c.to_le_bytes()));
                    ascii += &format!("vertex {} {} {}\n", corners[i][0], corners[i][1], corners[i][2]);
                }
                stl.extend([0u8; 2]);
                ascii += "endloop\nendfacet\n";
            }
            put("tetrahedron-binary.stl", &stl)?;
            put("tetrahedron-ascii.stl", format!("{ascii}endsolid\n").as_bytes())?;
            let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
            for c in corners {
                ply.extend(c.iter().flat_map(|v| v.to_le_bytes()));
                ply.extend([200u8, 120, 40]);
            }
            for f in faces {
                ply.push(3);
                ply.extend(f.iter().flat_map(|&i| (i as i32).to_le_bytes()));
            }
            put("tetrahedron.ply", &ply)?;
            // Its corners alone, with normals: a point cloud.
            let mut cloud = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n".to_vec();
            for c in corners {
                cloud.extend(c.iter().chain(c.iter()).flat_map(|v| v.to_le_bytes()));
            }
            put("tetrahedron-points.ply", &cloud)?;
            // The same as OBJ with a material whose texture is the target's `tex.png`.
            put(
                "tetrahedron.obj",
                b"mtllib tex.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 3/3 2/2\nf 1/1 2/2 4/3\nf 1 4 3\nf 2 3 4\n",
            )?;
            for p in shared("models", &[".glb", ".gltf", ".svx.json"]) {
                if std::fs::metadata(&p).is_ok_and(|m| m.len() as usize <= max_len) {
                    put(&seed_name(&p), &std::fs::read(&p)?)?;
                }
            }
        }
        "import" => {
            let log = b"phantogram-sensor-log 1\nmeta source seed\nacc 1000000 0 0 9.81\ngyr 2000000 0.1 0 0\nmag 3000000 20 0 -40\nrot 4000000 0 0 0 1\n";
            put("log", &[&[0u8][..], log].concat())?;
            put(
                "broad",
                &[&[1u8][..], b"t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,mag_x,mag_y,mag_z,gt_qw,gt_qx,gt_qy,gt_qz,movement\n0.01,0.1,0.2,9.8,0,0,0,20,0,-40,1,0,0,0,0\n0.02,0.1,0.2,9.8,0,0,0,20,0,-40,1,0,0,0,1\n"].concat(),
            )?;
            put(
                "android-raw",
                &[&[2u8][..], b"0.5 0 0 9.81\n0.51 0 0.1 9.8\n\0t_mocap_s,r00,r01,r02,r10,r11,r12,r20,r21,r22,up_x,up_y,up_z\n1.2,1,0,0,0,1,0,0,0,1,0,0,1\n"].concat(),
            )?;
            put(
                "phyphox",
                &[
                    &[3u8][..],
                    b"\"Time (s)\",\"X (m/s^2)\",\"Y (m/s^2)\",\"Z (m/s^2)\"\n0.5,0,0,9.81\n",
                ]
                .concat(),
            )?;
            put(
                "sensor-logger",
                &[&[4u8][..], b"time,seconds_elapsed,qz,qy,qx,qw\n1000,0,0,0,0,1\n"].concat(),
            )?;
            for p in shared("imu", &[".csv", ".csv.gz", ".txt", ".txt.gz", ".pglog", ".pglog.gz"]) {
                let name = p.to_string_lossy().to_lowercase();
                let layout = if name.ends_with(".pglog") || name.ends_with(".pglog.gz") {
                    0
                } else if name.contains("accelerometer.txt") {
                    2
                } else if name.contains("accelerometer.csv") {
                    3
                } else {
                    1
                };
                let bytes = std::fs::read(&p)?;
                put(
                    &seed_name(&p),
                    &[&[layout][..], &bytes[..bytes.len().min(max_len - 1)]].concat(),
                )?;
            }
        }
        "replay" => {
            let log = std::fs::read(workspace_root().join("assets/logs/tilt-sweep.pglog"))
                .context("reading the default log")?;
            put("tilt-sweep", &log)?;
            put(
                "centuries",
                b"phantogram-sensor-log 1\nacc -4611686018427387903 0 0 9.81\nacc 4611686018427387903 0 0 9.81\n",
            )?;
        }
        "calibration" => {
            put(
                "full",
                b"phantogram-calibration 1\nipd_m 0.064\nhead_offset_m 0.01 -0.02\nviewing_distance_m 0.3\ndensity_dpi 420 421\nflat_up_device 0 0.5 0.86\n",
            )?;
        }
        "environment" => {
            // A 4 × 2 Radiance HDR (flat scanlines: narrower than RLE's minimum of 8).
            let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n".to_vec();
            for i in 0..8u8 {
                hdr.extend([100 + i, 90, 80, 128]);
            }
            put("tiny.hdr", &hdr)?;
            for p in shared("env", &[".hdr", ".exr"]) {
                if std::fs::metadata(&p).is_ok_and(|m| m.len() as usize <= max_len) {
                    put(&seed_name(&p), &std::fs::read(&p)?)?;
                }
            }
        }
        "c_abi" => {
            // resume_offscreen 54×120, an accelerometer sample, a draw, a read-back, stats.
            let mut calls = vec![10u8, 54, 0, 120, 0];
            calls.push(0);
            for v in [0.01f64, 0.0, 0.0, 9.81] {
                calls.extend(v.to_le_bytes());
            }
            calls.push(13);
            calls.extend(0.02f64.to_le_bytes());
            calls.extend([14, 0xff, 0xff, 15]);
            put("lifecycle", &calls)?;
        }
        "jni" => {
            // The driver draws every choice from the bytes (`RandomCalls.BytesRandom`): a few
            // streams of pseudo-random bytes give it a start across all the methods.
            for (seed, len) in [(1u64, 256usize), (2, 1024), (3, 4096)] {
                let mut x = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15);
                let bytes: Vec<u8> = (0..len)
                    .map(|_| {
                        // xorshift64
                        x ^= x << 13;
                        x ^= x >> 7;
                        x ^= x << 17;
                        (x >> 24) as u8
                    })
                    .collect();
                put(&format!("stream-{seed}"), &bytes)?;
            }
        }
        _ => {}
    }
    Ok(())
}

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            files_under(&path, out);
        } else {
            out.push(path);
        }
    }
}

fn triangle_bin() -> Vec<u8> {
    [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect()
}

/// A GLB container: header, JSON chunk, BIN chunk (each padded to four bytes).
fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |b: &[u8], with: u8| {
        let mut v = b.to_vec();
        while !v.len().is_multiple_of(4) {
            v.push(with);
        }
        v
    };
    let (json, bin) = (pad(json, b' '), pad(bin, 0));
    // The buffer without a URI is the BIN chunk.
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(&bin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_single_process_run_is_read_from_its_final_lines() {
        // As libFuzzer 0.4.13 prints them (the per-unit progress lines have no ": cov:").
        let log = "#4096\tpulse  cov: 1811 ft: 9000 corp: 2003/40Mb exec/s: 1474 rss: 65Mb\n\
                   Done 10000000 runs in 6784 second(s)\n\
                   stat::number_of_executed_units: 10000000\n";
        assert_eq!(libfuzzer_seconds(log), Some(6784));
        assert_eq!(fork_executions(log), None);
    }

    #[test]
    fn a_fork_mode_run_counts_every_workers_executions() {
        let log = "INFO: -fork=2: 1360 seed inputs, starting to fuzz in /tmp/x\n\
                   #1491: cov: 2425 ft: 7014 corp: 1367 exec/s: 745 oom/timeout/crash: 0/0/0 time: 26s job: 1 dft_time: 0\n\
                   #27756: cov: 3086 ft: 9100 corp: 1749 exec/s: 816 oom/timeout/crash: 0/0/0 time: 33s job: 4 dft_time: 0\n\
                   INFO: fuzzed for 33 seconds, wrapping up soon\n\
                   INFO: exiting: 0 time: 34s\n";
        assert_eq!(fork_executions(log), Some(27756));
        assert_eq!(libfuzzer_seconds(log), Some(34));
    }
}
