//! Reading and writing through the guards, on real files and devices.

use phantogram_testkit::Scratch;

use std::path::Path;

use crate::{AtomicFile, read_regular_file};

#[test]
fn devices_and_folders_are_neither_read_nor_replaced() {
    let dir = Scratch::new("storage-devices");
    for path in ["/dev/zero", "/dev/null"] {
        let p = Path::new(path);
        if p.exists() {
            assert!(read_regular_file(p, 1 << 20).is_err(), "{path} read");
            assert!(AtomicFile::create(p).is_err(), "{path} would be replaced");
        }
    }
    assert!(read_regular_file(&dir, 10).is_err());
    assert!(AtomicFile::create(&dir).is_err());
}

#[test]
fn reads_are_bounded_and_writes_are_whole() {
    let dir = Scratch::new("storage-atomic");
    let path = dir.join("f.txt");
    std::fs::write(&path, b"old").unwrap();
    // An uncommitted write leaves the old file and no partial one.
    {
        let mut f = AtomicFile::create(&path).unwrap();
        std::io::Write::write_all(f.file(), b"half").unwrap();
    }
    assert_eq!(std::fs::read(&path).unwrap(), b"old");
    assert_eq!(std::fs::read_dir(&*dir).unwrap().count(), 1);
    let mut f = AtomicFile::create(&path).unwrap();
    std::io::Write::write_all(f.file(), b"new data").unwrap();
    f.commit().unwrap();
    assert_eq!(read_regular_file(&path, 8).unwrap(), b"new data");
    let err = read_regular_file(&path, 7).unwrap_err();
    assert!(err.to_string().contains("limit of 7"), "{err}");
}

#[cfg(unix)]
#[test]
fn a_link_to_a_file_keeps_the_link() {
    let dir = Scratch::new("storage-link");
    let real = dir.join("real.txt");
    let link = dir.join("link.txt");
    std::fs::write(&real, b"old").unwrap();
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let mut f = AtomicFile::create(&link).unwrap();
    std::io::Write::write_all(f.file(), b"new").unwrap();
    f.commit().unwrap();
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert_eq!(std::fs::read(&real).unwrap(), b"new");
}
