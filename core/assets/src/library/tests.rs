use std::io::Write;

use phantogram_testkit::{Scratch, tetrahedron_glb};

use super::*;

fn zip_of(files: &[(&str, &[u8])]) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    {
        let mut w = zip::ZipWriter::new(&mut out);
        let opts = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        for (name, bytes) in files {
            w.start_file(*name, opts).unwrap();
            w.write_all(bytes).unwrap();
        }
        w.finish().unwrap();
    }
    out.into_inner()
}

fn budget() -> ResourceBudget {
    ResourceBudget::PHONE
}

#[test]
fn built_in_artifacts_are_listed_first_and_load_placed() {
    let lib = Library::new(None, None);
    let list = lib.list();
    let keys: Vec<String> = list.iter().map(|e| e.id.to_string()).collect();
    assert_eq!(keys, ["builtin:amphora", "builtin:medal", "builtin:tablet"]);
    let loaded = lib.load(&list[1].id, budget(), &Progress::new()).unwrap();
    assert!(loaded.placed && loaded.model.triangle_count() > 1000);
    assert_eq!(loaded.entry.title, "Bronze medal");
    assert!(matches!(lib.remove(&list[0].id), Err(LibraryError::ReadOnly { .. })));
    assert!(matches!(
        lib.import("x.glb", &tetrahedron_glb(0.1, ""), budget(), &Progress::new()),
        Err(LibraryError::NoStorage)
    ));
}

#[test]
fn a_glb_opened_from_bytes_is_kept_listed_loaded_and_removed() {
    let dir = Scratch::new("library-glb");
    let lib = Library::new(Some(dir.to_path_buf()), None);
    let glb = tetrahedron_glb(0.05, r#""copyright":"(c) A Museum","extras":{"title":"Votive figure"}"#);
    let imported = lib.import("figure_01.glb", &glb, budget(), &Progress::new()).unwrap();
    assert_eq!(imported.entry.title, "Votive figure");
    assert_eq!(imported.entry.credit.as_deref(), Some("(c) A Museum"));
    assert!(!imported.placed);
    assert_eq!(imported.model.triangle_count(), 4);
    assert_eq!(imported.model.name, "figure-01");
    let id = imported.entry.id.clone();
    assert_eq!(id.origin, Origin::Imported);
    // Listed after the built-in ones; a new library on the same folder sees it too.
    let again = Library::new(Some(dir.to_path_buf()), None);
    let list = again.list();
    assert_eq!(list.len(), 4);
    assert_eq!(list[3].id, id);
    // The id round-trips through its text (what the settings store).
    assert_eq!(id.to_string().parse::<ArtifactId>().unwrap(), id);
    let loaded = again.load(&id, budget(), &Progress::new()).unwrap();
    assert_eq!(loaded.model.triangle_count(), 4);
    // The same file again is the same artifact, not a copy.
    let twice = again.import("renamed.glb", &glb, budget(), &Progress::new()).unwrap();
    assert_eq!(twice.entry.id, id);
    assert_eq!(again.list().len(), 4);
    again.remove(&id).unwrap();
    assert_eq!(again.list().len(), 3);
    assert!(matches!(again.remove(&id), Err(LibraryError::NotFound { .. })));
    assert!(matches!(
        again.load(&id, budget(), &Progress::new()),
        Err(LibraryError::NotFound { .. })
    ));
}

#[test]
fn a_damaged_or_foreign_file_is_an_error_and_leaves_nothing_behind() {
    let dir = Scratch::new("library-bad");
    let lib = Library::new(Some(dir.to_path_buf()), None);
    let mut glb = tetrahedron_glb(0.05, "");
    glb.truncate(glb.len() - 20);
    let e = lib.import("broken.glb", &glb, budget(), &Progress::new()).unwrap_err();
    assert!(matches!(e, LibraryError::Invalid { .. }), "{e}");
    assert!(
        e.to_string().starts_with("broken.glb: "),
        "named as the user knows it: {e}"
    );
    let e = lib
        .import("photo.png", b"\x89PNG\r\n\x1a\n", budget(), &Progress::new())
        .unwrap_err();
    assert!(
        e.to_string().contains("photo.png") && e.to_string().contains(".glb"),
        "{e}"
    );
    let e = lib
        .import("x.zip", b"PK\x03\x04garbage", budget(), &Progress::new())
        .unwrap_err();
    assert!(matches!(e, LibraryError::Archive { .. }), "{e}");
    assert_eq!(lib.list().len(), 3);
    let leftovers: Vec<_> = std::fs::read_dir(dir.join(IMPORTED)).unwrap().flatten().collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn a_cancelled_import_is_cancelled_and_leaves_nothing_behind() {
    let dir = Scratch::new("library-cancel");
    let lib = Library::new(Some(dir.to_path_buf()), None);
    let progress = Progress::new();
    progress.cancel();
    let e = lib
        .import("a.glb", &tetrahedron_glb(0.05, ""), budget(), &progress)
        .unwrap_err();
    assert!(e.is_cancelled(), "{e}");
    assert_eq!(lib.list().len(), 3);
}

#[test]
fn a_zip_holding_one_model_or_a_voyager_download_is_imported() {
    let dir = Scratch::new("library-zip");
    let lib = Library::new(Some(dir.to_path_buf()), None);
    let glb = tetrahedron_glb(0.05, "");
    let one = zip_of(&[("readme.txt", b"hello"), ("scan/thing.glb", &glb)]);
    let a = lib.import("thing.zip", &one, budget(), &Progress::new()).unwrap();
    assert_eq!(a.model.triangle_count(), 4);
    assert_eq!(a.entry.title, "Thing");
    // A Voyager download: its scene names the scan and carries the credit.
    let scene = br#"{"asset":{"copyright":"(c) Smithsonian"},"metas":[{"collection":{"title":"Hawksbill turtle"}}],
        "models":[{"derivatives":[{"usage":"Web3D","quality":"High","assets":[{"uri":"t-high.glb"}]}]}]}"#;
    let big = tetrahedron_glb(0.07, "");
    let voyager = zip_of(&[("turtle/scene.svx.json", scene), ("turtle/t-high.glb", &big)]);
    let v = lib.import("turtle.zip", &voyager, budget(), &Progress::new()).unwrap();
    assert_eq!(v.entry.title, "Hawksbill turtle");
    assert_eq!(v.entry.credit.as_deref(), Some("(c) Smithsonian"));
    assert!(
        v.entry.model_path.as_ref().unwrap().is_dir(),
        "the Voyager folder is the model"
    );
    assert_eq!(lib.list().len(), 5);
    // Two models and no scene: the user is asked to choose.
    let two = zip_of(&[("a.glb", &glb), ("b.glb", &big)]);
    let e = lib.import("two.zip", &two, budget(), &Progress::new()).unwrap_err();
    assert!(e.to_string().contains("a.glb, b.glb"), "{e}");
    let none = zip_of(&[("notes.txt", b"no model")]);
    assert!(matches!(
        lib.import("none.zip", &none, budget(), &Progress::new()),
        Err(LibraryError::NoModel { .. })
    ));
}

#[test]
fn a_zip_cannot_write_outside_its_folder_or_past_the_budget() {
    let dir = Scratch::new("library-zip-hostile");
    let lib = Library::new(Some(dir.to_path_buf()), None);
    let glb = tetrahedron_glb(0.05, "");
    let escape = zip_of(&[("../../evil.glb", &glb)]);
    let e = lib
        .import("escape.zip", &escape, budget(), &Progress::new())
        .unwrap_err();
    assert!(e.to_string().contains("outside"), "{e}");
    assert!(!dir.join("evil.glb").exists() && !dir.parent().unwrap().join("evil.glb").exists());
    // 8 MiB of zeros inflates from a few kilobytes: stopped at a 1 MiB budget as it is written.
    let zeros = vec![0u8; 8 << 20];
    let bomb = zip_of(&[("a.glb", &glb), ("zeros.bin", &zeros)]);
    assert!(bomb.len() < 64 << 10, "{}", bomb.len());
    let small = ResourceBudget {
        memory_bytes: 1 << 20,
        ..ResourceBudget::PHONE
    };
    let e = lib.import("bomb.zip", &bomb, small, &Progress::new()).unwrap_err();
    assert!(matches!(e, LibraryError::TooLarge { .. }), "{e}");
    assert_eq!(lib.list().len(), 3);
}

#[test]
fn bundled_files_and_folders_are_listed_read_only() {
    let dir = Scratch::new("library-bundled");
    std::fs::write(dir.join("b_vase.glb"), tetrahedron_glb(0.05, "")).unwrap();
    std::fs::create_dir(dir.join("a_folder")).unwrap();
    std::fs::write(
        dir.join("a_folder/x.glb"),
        tetrahedron_glb(0.06, r#""extras":{"title":"Alabaster jar"}"#),
    )
    .unwrap();
    std::fs::write(dir.join("notes.txt"), "not a model").unwrap();
    let lib = Library::new(None, Some(dir.to_path_buf()));
    let list = lib.list();
    let titles: Vec<&str> = list.iter().skip(3).map(|e| e.title.as_str()).collect();
    assert_eq!(titles, ["Alabaster jar", "B vase"]);
    assert!(list[3..].iter().all(|e| e.id.origin == Origin::Bundled));
    assert!(matches!(lib.remove(&list[3].id), Err(LibraryError::ReadOnly { .. })));
    let loaded = lib.load(&list[4].id, budget(), &Progress::new()).unwrap();
    assert_eq!(loaded.model.triangle_count(), 4);
}

#[test]
fn ids_are_plain_names_only() {
    for bad in [
        "",
        "amphora",
        "builtin:",
        "imported:../x",
        "imported:.staging-x",
        "other:x",
        "bundled:a/b",
    ] {
        assert!(bad.parse::<ArtifactId>().is_err(), "{bad}");
    }
    assert_eq!(
        "bundled:turtle.glb".parse::<ArtifactId>().unwrap(),
        ArtifactId {
            origin: Origin::Bundled,
            key: "turtle.glb".into()
        }
    );
}

#[test]
fn a_damaged_record_still_lists_the_artifact() {
    let dir = Scratch::new("library-record");
    let lib = Library::new(Some(dir.to_path_buf()), None);
    let a = lib
        .import("jar.glb", &tetrahedron_glb(0.05, ""), budget(), &Progress::new())
        .unwrap();
    let folder = dir.join(IMPORTED).join(&a.entry.id.key);
    std::fs::write(folder.join(RECORD), "{ not json").unwrap();
    let list = lib.list();
    assert_eq!(list.len(), 4);
    assert_eq!(list[3].title, metadata::title_from_name(&a.entry.id.key));
    assert!(lib.load(&a.entry.id, budget(), &Progress::new()).is_ok());
}

#[test]
fn a_voyager_folder_offers_its_lightest_scan_as_a_preview() {
    let dir = Scratch::new("library-preview");
    let bundled = dir.join("bundled");
    let turtle = bundled.join("turtle");
    std::fs::create_dir_all(&turtle).unwrap();
    let scene = br#"{"models":[{"derivatives":[
        {"usage":"Web3D","quality":"Thumb","assets":[{"uri":"t-thumb.glb"}]},
        {"usage":"Web3D","quality":"High","assets":[{"uri":"t-high.glb"}]},
        {"usage":"Web3D","quality":"Low","assets":[{"uri":"t-low.glb"}]}]}]}"#;
    std::fs::write(turtle.join("scene.svx.json"), scene).unwrap();
    std::fs::write(turtle.join("t-high.glb"), tetrahedron_glb(0.07, "")).unwrap();
    std::fs::write(turtle.join("t-thumb.glb"), tetrahedron_glb(0.05, "")).unwrap();
    let lib = Library::new(None, Some(bundled.clone()));
    let id: ArtifactId = "bundled:turtle".parse().unwrap();
    // The best present (High) is the artifact; the lightest present (Thumb; Low is absent) its
    // preview.
    let full = lib.load(&id, budget(), &Progress::new()).unwrap();
    assert_eq!(full.model.name, "t-high");
    let preview = lib.load_preview(&id, budget(), &Progress::new()).unwrap().unwrap();
    assert_eq!(preview.model.name, "t-thumb");
    assert_eq!(preview.entry.id, id);
    // One scan present: nothing lighter to show first.
    std::fs::remove_file(turtle.join("t-thumb.glb")).unwrap();
    assert!(lib.load_preview(&id, budget(), &Progress::new()).is_none());
    // Built-in artifacts are generated at once: no preview.
    assert!(
        lib.load_preview(&"builtin:medal".parse().unwrap(), budget(), &Progress::new())
            .is_none()
    );
}

/// Every kind of file the messages name is one the library opens, whatever its case; others
/// are not.
#[test]
fn the_model_file_types_named_are_those_opened() {
    let named: Vec<&str> = MODEL_FILE_TYPES
        .split([',', ' '])
        .filter(|word| word.starts_with('.'))
        .collect();
    assert_eq!(named.len(), 14, "{MODEL_FILE_TYPES}");
    for extension in named {
        assert!(is_model_name(&format!("scan{extension}")), "{extension}");
        assert!(
            is_model_name(&format!("SCAN{}", extension.to_uppercase())),
            "{extension}"
        );
    }
    for other in ["notes.txt", "scan.fbx", "scan.zip", "glb", "scan.glb.bak"] {
        assert!(!is_model_name(other), "{other}");
    }
}
