//! Reading files from outside: regular files only, within a size bound.

use std::fs;
use std::io;
use std::path::Path;

/// Opens `path` for reading only if it is a regular file (after following symbolic links):
/// a device (`/dev/zero`), a pipe or a socket would block or never end, and a folder is not
/// data. The kind check comes before the open, which on a FIFO would already block.
pub fn open_regular_file(path: &Path) -> io::Result<fs::File> {
    let meta = fs::metadata(path)?;
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            if meta.is_dir() {
                "is a folder, not a file"
            } else {
                "is not a regular file (a device, pipe or socket)"
            },
        ));
    }
    fs::File::open(path)
}

/// Reads a whole regular file ([`open_regular_file`]) of at most `max_bytes`; a larger one is an
/// error naming the limit, before anything is allocated for it.
pub fn read_regular_file(path: &Path, max_bytes: u64) -> io::Result<Vec<u8>> {
    use io::Read as _;
    let file = open_regular_file(path)?;
    let len = file.metadata()?.len();
    if len > max_bytes {
        return Err(io::Error::new(
            io::ErrorKind::FileTooLarge,
            format!("is {len} bytes, over the limit of {max_bytes}"),
        ));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    // `take`: the file may grow while it is read.
    file.take(max_bytes.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(io::Error::new(
            io::ErrorKind::FileTooLarge,
            format!("grew over the limit of {max_bytes} bytes while it was read"),
        ));
    }
    Ok(bytes)
}
