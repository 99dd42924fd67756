//! `phantogram check-artifacts FOLDER`: a museum's scans loaded exactly as a phone will load
//! them (the artifact library's bundled entries, the phone budget), before they are built into
//! the apps (`cargo xtask android|ios --artifacts FOLDER` runs it). Prints one line per
//! artifact; fails naming every one that would not open, and every entry the library would not
//! list (a folder holding no model, a file of another kind).

use std::path::Path;

use anyhow::{Result, bail};
use phantogram::budget::ResourceBudget;
use phantogram::library::{Library, MODEL_FILE_TYPES, Origin};
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
                "{name}: not a model file ({MODEL_FILE_TYPES}), nor a folder holding one or a \
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
                    "ok {}: {} ({} triangles, {} images{}){}",
                    e.id.key,
                    e.title,
                    m.triangle_count(),
                    m.images.len(),
                    if m.annotations.is_empty() {
                        String::new()
                    } else {
                        format!(", {} annotations", m.annotations.len())
                    },
                    m.bounds_of(|p| !p.is_floor)
                        .map(|b| format!(", {} as in the file", size_text(b.max - b.min)))
                        .unwrap_or_default()
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

/// A model's extent (metres, glTF's frame: +x right, +y up, +z towards the viewer) as a curator
/// reads it, width × height × depth, in millimetres up to 10 m and in metres beyond: a scan read
/// in the wrong unit shows at once (a vase of 1 070 mm that should be 330).
fn size_text(extent_m: phantogram::glam::Vec3) -> String {
    if extent_m.max_element() >= 10.0 {
        format!(
            "{:.1} × {:.1} × {:.1} m wide, tall and deep",
            extent_m.x, extent_m.y, extent_m.z
        )
    } else {
        let mm = extent_m * 1000.0;
        let precision = if mm.max_element() < 10.0 { 1 } else { 0 };
        format!(
            "{:.precision$} × {:.precision$} × {:.precision$} mm wide, tall and deep",
            mm.x, mm.y, mm.z
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_in_millimetres_or_metres() {
        assert_eq!(
            size_text(phantogram::glam::Vec3::new(0.33, 0.5204, 0.1)),
            "330 × 520 × 100 mm wide, tall and deep"
        );
        assert_eq!(
            size_text(phantogram::glam::Vec3::new(0.0042, 0.001, 0.0)),
            "4.2 × 1.0 × 0.0 mm wide, tall and deep"
        );
        assert_eq!(
            size_text(phantogram::glam::Vec3::new(1500.0, 12.34, 300.0)),
            "1500.0 × 12.3 × 300.0 m wide, tall and deep"
        );
    }
}
