//! `cargo xtask <task>`: build automation that needs more than one cargo command.
//!
//! * `assets` — regenerate what the project generates itself into `assets/` (the synthetic tilt
//!   log). Deterministic: running it twice gives identical files.
//! * `bench core` — run the core benchmark (ns per sensor update and per frame).
//! * `ci` — what `.ci/run` runs after installing packages: fmt check, clippy, tests.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    match args.as_slice() {
        ["assets"] => assets(),
        ["bench", "core"] | ["bench"] => cargo(&["bench", "-p", "phantogram", "--bench", "core"]),
        ["ci"] => {
            cargo(&["fmt", "--all", "--check"])?;
            cargo(&["clippy", "--workspace", "--all-targets", "--", "-D", "warnings"])?;
            cargo(&["test", "--workspace"])
        }
        [] | ["help"] | ["--help"] => {
            println!("usage: cargo xtask <assets | bench core | ci>");
            Ok(())
        }
        other => bail!("unknown task {other:?}; try `cargo xtask help`"),
    }
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn cargo(args: &[&str]) -> Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(&cargo)
        .args(args)
        .current_dir(workspace_root())
        .status()
        .with_context(|| format!("could not run {cargo}"))?;
    if !status.success() {
        bail!("`cargo {}` failed ({status})", args.join(" "));
    }
    Ok(())
}

fn assets() -> Result<()> {
    use phantogram::synthetic::{ImuSpec, tilt_sweep, tilt_sweep_meta};
    let dir = workspace_root().join("assets/logs");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let path = dir.join("tilt-sweep.pglog");
    let events = tilt_sweep(&ImuSpec::default());
    phantogram::sensorlog::write_log(&path, &tilt_sweep_meta(), &events)?;
    println!("wrote {} ({} events)", path.display(), events.len());
    Ok(())
}
