//! `phantogram check-artifacts FOLDER`: a museum's scans loaded exactly as a phone will load
//! them (the artifact library's bundled entries, the phone budget), before they are built into
//! the apps (`cargo xtask android|ios --artifacts FOLDER` runs it). Prints one line per
//! artifact; fails naming every one that would not open, and every entry the library would not
//! list (a folder holding no model, a file of another kind).

use std::path::Path;

use anyhow::{Result, bail};
use phantogram::budget::ResourceBudget;
use phantogram::library::{Library, Origin};
use phantogram::progress::Progress;

use crate::output::outln;

pub fn check_artifacts_command(folder: &Path) -> Result<()> {
    if !folder.is_dir() {
        bail!("{}: not a folder", folder.display());
    }
    let library = Library::new(None, Some(folder.to_path_buf()));
    let entries: Vec<_> = library
        .list()
        .into_iter()
        .filter(|e| e.id.origin == Origin::Bundled)
        .collect();
    let mut problems = Vec::new();
    // What the library does not list: a curator expects every entry of the folder to show.
    let mut names: Vec<String> = std::fs::read_dir(folder)?
        .flatten()
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| !n.starts_with('.'))
        .collect();
    names.sort();
    for name in names {
        if !entries.iter().any(|e| e.id.key == name) {
            problems.push(format!(
                "{name}: not a model file (.glb, .gltf, .stl, .ply, .obj), nor a folder holding one or a \
                 Voyager scene (a model with files beside it, such as an .obj with its .mtl and \
                 textures, goes in a folder of its own)"
            ));
        }
    }
    for e in &entries {
        match library.load(&e.id, ResourceBudget::PHONE, &Progress::new()) {
            Ok(loaded) => {
                let m = &loaded.model;
                outln!(
                    "ok {}: {} ({} triangles, {} images{})",
                    e.id.key,
                    e.title,
                    m.triangle_count(),
                    m.images.len(),
                    if m.annotations.is_empty() {
                        String::new()
                    } else {
                        format!(", {} annotations", m.annotations.len())
                    }
                );
                for w in &m.warnings {
                    outln!("   warning: {w}");
                }
            }
            Err(err) => problems.push(format!("{}: {err}", e.id.key)),
        }
    }
    if !problems.is_empty() {
        bail!(
            "{}: {} would not show on a phone:\n  {}",
            folder.display(),
            if problems.len() == 1 {
                "one entry".to_owned()
            } else {
                format!("{} entries", problems.len())
            },
            problems.join("\n  ")
        );
    }
    Ok(())
}
