//! Writing files whole or not at all.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

/// A file written whole or not at all: the data go to a hidden file beside the target, which
/// [`AtomicFile::commit`] flushes to the disk (`fsync`) and renames over the target. A file that
/// was there is replaced only by a complete one, never left half-written by a full disk or a
/// crash; dropping an uncommitted `AtomicFile` removes the partial file.
///
/// Only a regular file (or nothing) may be replaced: renaming over `/dev/null` or a pipe would
/// replace the device node itself. A symbolic link to a regular file is followed: its target is
/// replaced and the link stays.
pub struct AtomicFile {
    target: PathBuf,
    partial: PathBuf,
    file: Option<fs::File>,
}

impl AtomicFile {
    pub fn create(path: &Path) -> io::Result<Self> {
        let target = match fs::metadata(path) {
            Ok(meta) if meta.is_file() => fs::canonicalize(path)?,
            Ok(meta) => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    if meta.is_dir() {
                        "is a folder, not a file to write"
                    } else {
                        "is not a regular file (a device, pipe or socket): write to a new path"
                    },
                ));
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => path.to_path_buf(),
            Err(e) => return Err(e),
        };
        let name = target
            .file_name()
            .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "not a file name"))?;
        let partial = target.with_file_name(format!(".{}.{}.partial", name.to_string_lossy(), std::process::id()));
        let file = fs::OpenOptions::new()
            .write(true)
            .create(true)
            .truncate(true)
            .open(&partial)?;
        Ok(Self {
            target,
            partial,
            file: Some(file),
        })
    }

    /// The partial file, to write to.
    pub fn file(&mut self) -> &mut fs::File {
        self.file.as_mut().expect("present until commit, which consumes self")
    }

    /// Flushes the data to the disk and puts the file in place.
    pub fn commit(mut self) -> io::Result<()> {
        let file = self.file.take().expect("present until commit");
        file.sync_all()?;
        drop(file);
        fs::rename(&self.partial, &self.target)?;
        // The rename itself survives a power cut once the folder is synced (best effort: not
        // every file system lets a folder be opened for it).
        if let Some(dir) = self.target.parent().filter(|d| !d.as_os_str().is_empty())
            && let Ok(dir) = fs::File::open(dir)
        {
            let _ = dir.sync_all();
        }
        Ok(())
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            let _ = fs::remove_file(&self.partial);
        }
    }
}
