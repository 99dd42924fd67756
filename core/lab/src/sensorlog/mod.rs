//! Sensor logs: the project's own recording format, its streaming reader and writer, and importers
//! for real exports ([`import`]).
//!
//! ## Format, version 1
//!
//! UTF-8 text, one record per line, optionally gzip-compressed (detected from the gzip magic
//! bytes, whatever the file name). Line-oriented so that it streams (a recorder appends, a reader
//! needs no index), diffs, and survives truncation up to the last complete line.
//!
//! ```text
//! phantogram-sensor-log 1
//! # comment lines and blank lines are ignored
//! meta source Thibaud_Nexus5_NoDist_AR
//! acc 282310596 -0.45986938 4.028183 8.463165
//! gyr 438408008 -0.7108307 1.4732819 1.0360565
//! rot 641014209 0.07790387 0.121515125 -0.11503918 0.9828179
//! ```
//!
//! * Line 1 names the format and its version; a reader refuses versions it does not know.
//! * `meta KEY VALUE…` lines (only before the first event) carry free-form provenance.
//! * Event lines: a tag, the time stamp in integer nanoseconds, then the values in the crate's
//!   device frame and units. Tags: `acc` accelerometer (m/s², with gravity), `gyr` gyroscope
//!   (rad/s), `mag` magnetometer (µT), `lin` linear acceleration (m/s², gravity removed), each with
//!   `x y z`; `rot` platform rotation vector and `gt` ground-truth orientation, device → world
//!   quaternions as `x y z w`. Values may be `NaN` or `inf`: a log records what the sensor said,
//!   and the consumer ([`phantogram_sensing::sensors::SensorInbox`]) rejects and counts them.
//! * Events are written in time order; readers do not reorder.
//!
//! Errors name the file and the 1-based line.

pub mod import;

use std::fs::File;
use std::io::{self, BufRead, BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use flate2::Compression;
use flate2::read::MultiGzDecoder;
use flate2::write::GzEncoder;
use thiserror::Error;

use phantogram_files::text::{excerpt, strip_bom};
use phantogram_files::{AtomicFile, open_regular_file};
use phantogram_sensing::sensors::{SensorEvent, SensorKind};

/// First word of line 1.
pub const MAGIC: &str = "phantogram-sensor-log";
/// The version this crate writes and reads.
pub const VERSION: u32 = 1;

#[derive(Debug, Error)]
pub enum LogError {
    /// The I/O error is part of the message and deliberately not a `source()`: chain printers
    /// (`anyhow`'s `{:#}`) would show it twice, and the shells show the message alone.
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: io::Error },
    #[error("{}:{line}: {message}", path.display())]
    Parse { path: PathBuf, line: u64, message: String },
    #[error("{}: {message}", path.display())]
    Format { path: PathBuf, message: String },
}

impl LogError {
    pub fn io(path: &Path, error: io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            error,
        }
    }

    pub fn parse(path: &Path, line: u64, message: impl Into<String>) -> Self {
        Self::Parse {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    pub fn format(path: &Path, message: impl Into<String>) -> Self {
        Self::Format {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    /// The 1-based line an error points at, if any.
    pub fn line(&self) -> Option<u64> {
        match self {
            Self::Parse { line, .. } => Some(*line),
            _ => None,
        }
    }

    pub fn path(&self) -> &Path {
        match self {
            Self::Io { path, .. } | Self::Parse { path, .. } | Self::Format { path, .. } => path,
        }
    }
}

fn tag(kind: SensorKind) -> &'static str {
    match kind {
        SensorKind::Accelerometer => "acc",
        SensorKind::Gyroscope => "gyr",
        SensorKind::Magnetometer => "mag",
        SensorKind::RotationVector => "rot",
        SensorKind::LinearAcceleration => "lin",
        SensorKind::GroundTruth => "gt",
    }
}

fn kind_of_tag(t: &str) -> Option<SensorKind> {
    SensorKind::ALL.into_iter().find(|k| tag(*k) == t)
}

/// Opens a file for reading, transparently gunzipping it when it starts with the gzip magic.
pub fn open_maybe_gz(path: &Path) -> Result<Box<dyn BufRead>, LogError> {
    // Regular files only: a pipe or a device would block or never end.
    let mut file = BufReader::new(open_regular_file(path).map_err(|e| LogError::io(path, e))?);
    let head = file.fill_buf().map_err(|e| LogError::io(path, e))?;
    if head.starts_with(&[0x1f, 0x8b]) {
        Ok(Box::new(BufReader::new(MultiGzDecoder::new(file))))
    } else {
        Ok(Box::new(file))
    }
}

/// The longest line [`Lines`] reads: far above any sensor export's row, far below what a file
/// that is not text (or a gzip stream that inflates to gigabytes without a line break) would make
/// it hold in memory.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Most `meta` lines a log's header holds, and most bytes of them together: provenance notes,
/// not data. (Each line is also under [`MAX_LINE_BYTES`].)
pub const MAX_META_LINES: usize = 1024;
pub const MAX_META_BYTES: usize = 64 << 10;

/// Most events a log is read into memory with ([`read_all`]): 2²³, 256 MiB of events, an hour
/// and a half of three sensors at 500 Hz. Replays that stream a log hold none of them.
pub const MAX_EVENTS_IN_MEMORY: usize = 1 << 23;

/// Collects `events` (from [`LogReader`] or an importer), failing at the first error or beyond
/// [`MAX_EVENTS_IN_MEMORY`] events, before the memory is taken.
pub fn read_all(
    path: &Path,
    events: impl IntoIterator<Item = Result<SensorEvent, LogError>>,
) -> Result<Vec<SensorEvent>, LogError> {
    let mut out = Vec::new();
    for event in events {
        if out.len() == MAX_EVENTS_IN_MEMORY {
            return Err(too_many_events(path));
        }
        out.push(event?);
    }
    Ok(out)
}

/// The error for a log beyond [`MAX_EVENTS_IN_MEMORY`].
fn too_many_events(path: &Path) -> LogError {
    LogError::format(path, too_many_events_message())
}

/// Why a log beyond [`MAX_EVENTS_IN_MEMORY`] is refused, whether read ([`read_all`]) or imported.
fn too_many_events_message() -> String {
    format!("more than {MAX_EVENTS_IN_MEMORY} events, more than is read into memory; split the recording")
}

/// Reads numbered lines, naming the file in every error.
pub struct Lines {
    path: PathBuf,
    reader: Box<dyn BufRead>,
    line_no: u64,
    buf: String,
}

impl Lines {
    pub fn open(path: &Path) -> Result<Self, LogError> {
        Ok(Self::new(path, open_maybe_gz(path)?))
    }

    pub fn new(path: &Path, reader: Box<dyn BufRead>) -> Self {
        Self {
            path: path.to_path_buf(),
            reader,
            line_no: 0,
            buf: String::new(),
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn line_no(&self) -> u64 {
        self.line_no
    }

    /// Moves to the next line; `false` at the end. Read it with [`Self::current`].
    pub fn advance(&mut self) -> Result<bool, LogError> {
        self.buf.clear();
        let n = (&mut self.reader)
            .take(MAX_LINE_BYTES as u64 + 1)
            .read_line(&mut self.buf)
            .map_err(|e| {
                if e.kind() == io::ErrorKind::InvalidData {
                    LogError::parse(&self.path, self.line_no + 1, "not valid UTF-8 text")
                } else {
                    LogError::io(&self.path, e)
                }
            })?;
        if n == 0 {
            return Ok(false);
        }
        self.line_no += 1;
        if n > MAX_LINE_BYTES {
            return Err(self.error(format!(
                "a line longer than {} MiB: not a sensor log?",
                MAX_LINE_BYTES >> 20
            )));
        }
        Ok(true)
    }

    /// The current line without its line ending.
    pub fn current(&self) -> &str {
        self.buf.trim_end_matches(['\n', '\r'])
    }

    /// The next line, owned; `None` at the end. For headers, not for the bulk of a file.
    pub fn next_owned(&mut self) -> Result<Option<String>, LogError> {
        Ok(self.advance()?.then(|| self.current().to_owned()))
    }

    pub fn error(&self, message: impl Into<String>) -> LogError {
        LogError::parse(&self.path, self.line_no, message)
    }
}

/// Parses a float the way sensor exports write them (also `NaN`, `inf`).
pub fn parse_f64(field: &str) -> Result<f64, String> {
    let f = field.trim().trim_matches('"');
    f.parse::<f64>()
        .map_err(|_| format!("expected a number, found {}", excerpt(field)))
}

/// Seconds (as exported) to integer nanoseconds; refuses non-finite or absurd times.
pub fn seconds_to_ns(t_s: f64) -> Result<i64, String> {
    if !t_s.is_finite() || t_s.abs() * 1e9 > phantogram_sensing::sensors::MAX_ABS_T_NS as f64 {
        return Err(format!("time stamp {t_s} s is not usable"));
    }
    Ok((t_s * 1e9).round() as i64)
}

/// Streaming reader of the project's format.
pub struct LogReader {
    lines: Lines,
    meta: Vec<(String, String)>,
    pending: Option<SensorEvent>,
    failed: bool,
}

impl LogReader {
    pub fn open(path: &Path) -> Result<Self, LogError> {
        Self::from_lines(Lines::open(path)?)
    }

    /// Reads from any byte source; `name` is used in error messages.
    pub fn from_reader(name: &Path, reader: impl Read + 'static) -> Result<Self, LogError> {
        Self::from_lines(Lines::new(name, Box::new(BufReader::new(reader))))
    }

    fn from_lines(mut lines: Lines) -> Result<Self, LogError> {
        let Some(header) = lines.next_owned()? else {
            return Err(LogError::format(
                lines.path(),
                "empty file, not a phantogram sensor log",
            ));
        };
        let mut words = strip_bom(&header).split_whitespace();
        if words.next() != Some(MAGIC) {
            return Err(lines.error(format!(
                "not a phantogram sensor log (line 1 should start with {MAGIC:?})"
            )));
        }
        match words.next().map(str::parse::<u32>) {
            Some(Ok(VERSION)) => {}
            Some(Ok(v)) => {
                return Err(lines.error(format!(
                    "format version {v} is not supported (this build reads {VERSION})"
                )));
            }
            _ => return Err(lines.error("missing or malformed format version")),
        }
        let mut reader = Self {
            lines,
            meta: Vec::new(),
            pending: None,
            failed: false,
        };
        // Read the header block (meta lines) up to the first event.
        let mut meta_bytes = 0usize;
        loop {
            match reader.read_record(true)? {
                Record::Meta(k, v) => {
                    meta_bytes += k.len() + v.len();
                    if reader.meta.len() >= MAX_META_LINES || meta_bytes > MAX_META_BYTES {
                        return Err(reader.lines.error(format!(
                            "more meta lines than a log holds ({MAX_META_LINES} lines or {} KiB at most)",
                            MAX_META_BYTES >> 10
                        )));
                    }
                    reader.meta.push((k, v));
                }
                Record::Event(e) => {
                    reader.pending = Some(e);
                    break;
                }
                Record::End => break,
            }
        }
        Ok(reader)
    }

    pub fn meta(&self) -> &[(String, String)] {
        &self.meta
    }

    pub fn path(&self) -> &Path {
        self.lines.path()
    }

    fn read_record(&mut self, meta_allowed: bool) -> Result<Record, LogError> {
        loop {
            if !self.lines.advance()? {
                return Ok(Record::End);
            }
            let line = self.lines.current().trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let (first, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
            if first == "meta" {
                if !meta_allowed {
                    return Err(self.lines.error("meta line after the first event"));
                }
                let rest = rest.trim();
                let (k, v) = rest.split_once(char::is_whitespace).unwrap_or((rest, ""));
                if k.is_empty() {
                    return Err(self.lines.error("meta line without a key"));
                }
                return Ok(Record::Meta(k.to_owned(), v.trim().to_owned()));
            }
            let event = parse_event(first, rest).map_err(|m| self.lines.error(m))?;
            return Ok(Record::Event(event));
        }
    }
}

enum Record {
    Meta(String, String),
    Event(SensorEvent),
    End,
}

fn parse_event(tag: &str, rest: &str) -> Result<SensorEvent, String> {
    let kind = kind_of_tag(tag).ok_or_else(|| format!("unknown record type {}", excerpt(tag)))?;
    let mut fields = rest.split_whitespace();
    let t_ns = fields
        .next()
        .ok_or("missing time stamp")?
        .parse::<i64>()
        .ok()
        .filter(|&t| phantogram_sensing::sensors::time_in_range(t))
        .ok_or("time stamp is not an integer number of nanoseconds within ±(2^62 - 1)")?;
    let n = if kind.is_orientation() { 4 } else { 3 };
    let mut value = [0f32; 4];
    for (i, slot) in value.iter_mut().take(n).enumerate() {
        let f = fields.next().ok_or_else(|| format!("expected {n} values, found {i}"))?;
        *slot = parse_f64(f)? as f32;
    }
    if fields.next().is_some() {
        return Err(format!("expected {n} values, found more"));
    }
    Ok(SensorEvent { t_ns, kind, value })
}

impl Iterator for LogReader {
    type Item = Result<SensorEvent, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        if let Some(e) = self.pending.take() {
            return Some(Ok(e));
        }
        if self.failed {
            return None;
        }
        match self.read_record(false) {
            Ok(Record::Event(e)) => Some(Ok(e)),
            Ok(Record::End) => None,
            Ok(Record::Meta(..)) => unreachable!("read_record refuses meta after the header"),
            Err(e) => {
                self.failed = true;
                Some(Err(e))
            }
        }
    }
}

/// Streaming writer of the project's format. Gzip-compresses when the path ends in `.gz`.
///
/// The events go to a hidden file beside the target, renamed over it by [`LogWriter::finish`]:
/// a log that was there is replaced only by a complete one, never left half-written by a full
/// disk or an interrupted import (a writer dropped unfinished removes its partial file).
pub struct LogWriter {
    path: PathBuf,
    /// `None` once finished.
    file: Option<AtomicFile>,
    sink: Option<Sink>,
}

enum Sink {
    Plain(BufWriter<File>),
    /// Boxed: the encoder's state is eight times the plain writer's.
    Gzip(Box<GzEncoder<BufWriter<File>>>),
}

impl LogWriter {
    /// Only a regular file (or nothing) is replaced: see [`AtomicFile`].
    pub fn create(path: &Path, meta: &[(String, String)]) -> Result<Self, LogError> {
        let mut atomic = AtomicFile::create(path).map_err(|e| LogError::io(path, e))?;
        let file = BufWriter::new(atomic.file().try_clone().map_err(|e| LogError::io(path, e))?);
        let sink = if path.extension().is_some_and(|e| e == "gz") {
            Sink::Gzip(Box::new(GzEncoder::new(file, Compression::default())))
        } else {
            Sink::Plain(file)
        };
        let mut w = Self {
            path: path.to_path_buf(),
            file: Some(atomic),
            sink: Some(sink),
        };
        let mut header = format!("{MAGIC} {VERSION}\n");
        for (k, v) in meta {
            // Keys are single words; values end at the line.
            let k = k.split_whitespace().collect::<Vec<_>>().join("_");
            let v = v.replace(['\n', '\r'], " ");
            header.push_str(&format!("meta {k} {v}\n"));
        }
        w.write_text(&header)?;
        Ok(w)
    }

    fn write_text(&mut self, text: &str) -> Result<(), LogError> {
        let result = match &mut self.sink {
            Some(Sink::Plain(f)) => f.write_all(text.as_bytes()),
            Some(Sink::Gzip(gz)) => gz.write_all(text.as_bytes()),
            None => Err(io::Error::other("the log was already finished")),
        };
        result.map_err(|e| LogError::io(&self.path, e))
    }

    pub fn write(&mut self, e: &SensorEvent) -> Result<(), LogError> {
        let v = e.value;
        let line = if e.kind.is_orientation() {
            format!("{} {} {} {} {} {}\n", tag(e.kind), e.t_ns, v[0], v[1], v[2], v[3])
        } else {
            format!("{} {} {} {} {}\n", tag(e.kind), e.t_ns, v[0], v[1], v[2])
        };
        self.write_text(&line)
    }

    /// Flushes and closes the file and puts it in place; without it nothing is written (a writer
    /// dropped unfinished removes its partial file, and whatever was there stays).
    pub fn finish(mut self) -> Result<(), LogError> {
        let flushed = match self.sink.take() {
            Some(Sink::Plain(f)) => f.into_inner().map_err(|e| e.into_error()).map(drop),
            Some(Sink::Gzip(gz)) => gz
                .finish()
                .and_then(|f| f.into_inner().map_err(|e| e.into_error()))
                .map(drop),
            None => Err(io::Error::other("the log was already finished")),
        };
        let file = self.file.take();
        flushed
            .and_then(|()| {
                file.map_or(
                    Err(io::Error::other("the log was already finished")),
                    AtomicFile::commit,
                )
            })
            .map_err(|e| LogError::io(&self.path, e))
    }
}

/// Writes a whole log.
pub fn write_log(path: &Path, meta: &[(String, String)], events: &[SensorEvent]) -> Result<(), LogError> {
    let mut w = LogWriter::create(path, meta)?;
    for e in events {
        w.write(e)?;
    }
    w.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Quat, Vec3};

    use phantogram_testkit::Scratch;

    fn sample_events() -> Vec<SensorEvent> {
        vec![
            SensorEvent::accelerometer(1_000, Vec3::new(0.1, -0.2, 9.81)),
            SensorEvent::gyroscope(1_500, Vec3::new(1e-7, 3.25, -0.5)),
            SensorEvent::magnetometer(2_000, Vec3::new(f32::NAN, 20.0, -40.0)),
            SensorEvent::orientation(SensorKind::RotationVector, 2_500, Quat::from_rotation_x(0.3)),
            SensorEvent::vector(SensorKind::LinearAcceleration, 3_000, Vec3::ONE),
            SensorEvent::orientation(SensorKind::GroundTruth, 3_500, Quat::from_rotation_y(-1.0)),
        ]
    }

    fn same(a: &SensorEvent, b: &SensorEvent) -> bool {
        a.t_ns == b.t_ns
            && a.kind == b.kind
            && a.value
                .iter()
                .zip(b.value)
                .all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()))
    }

    #[test]
    fn round_trips_exactly_plain_and_gzip() {
        let events = sample_events();
        let meta = vec![("source".to_owned(), "unit test".to_owned())];
        let dir = Scratch::new("unit-log-round-trip");
        for name in ["rt.pglog", "rt.pglog.gz"] {
            let path = dir.join(name);
            write_log(&path, &meta, &events).unwrap();
            let r = LogReader::open(&path).unwrap();
            assert_eq!(r.meta(), &meta[..]);
            let back: Vec<_> = r.collect::<Result<_, _>>().unwrap();
            assert_eq!(back.len(), events.len());
            for (a, b) in events.iter().zip(&back) {
                assert!(same(a, b), "{a:?} != {b:?}");
            }
        }
    }

    #[test]
    fn errors_name_file_and_line() {
        let cases = [
            ("nope 1\n", 1, "not a phantogram"),
            ("phantogram-sensor-log 2\n", 1, "version 2"),
            ("phantogram-sensor-log 1\nacc 10 1 2\n", 2, "expected 3 values"),
            ("phantogram-sensor-log 1\n# c\n\nacc 10 1 2 x\n", 4, "expected a number"),
            ("phantogram-sensor-log 1\nacc 1.5 1 2 3\n", 2, "nanoseconds"),
            (
                "phantogram-sensor-log 1\nacc -9223372036854775808 1 2 3\n",
                2,
                "within ±(2^62 - 1)",
            ),
            ("phantogram-sensor-log 1\nacc 1 1 2 3\nmeta a b\n", 3, "meta line after"),
            ("phantogram-sensor-log 1\nzzz 1 1 2 3\n", 2, "unknown record"),
            ("phantogram-sensor-log 1\nrot 1 1 2 3 4 5\n", 2, "found more"),
        ];
        let dir = Scratch::new("unit-log-errors");
        for (i, (text, line, needle)) in cases.into_iter().enumerate() {
            let path = dir.join(format!("bad{i}.pglog"));
            std::fs::write(&path, text).unwrap();
            let err = match LogReader::open(&path) {
                Err(e) => e,
                Ok(r) => r.filter_map(Result::err).next().expect("an error"),
            };
            assert_eq!(err.line(), Some(line), "{text:?}: {err}");
            let shown = err.to_string();
            assert!(shown.contains(&format!("bad{i}.pglog:{line}:")), "{shown}");
            assert!(shown.contains(needle), "{shown}");
        }
    }

    #[test]
    fn a_line_without_end_is_an_error_not_a_gigabyte() {
        let dir = Scratch::new("unit-log-long-line");
        // Gzip makes it small on disk: 2 MiB of digits without a line break.
        let path = dir.join("long.pglog.gz");
        let mut gz = GzEncoder::new(File::create(&path).unwrap(), Compression::fast());
        gz.write_all(b"phantogram-sensor-log 1\nacc 1 0 0 ").unwrap();
        gz.write_all(&vec![b'9'; 2 << 20]).unwrap();
        gz.finish().unwrap();
        let err = LogReader::open(&path)
            .and_then(|r| r.collect::<Result<Vec<_>, _>>())
            .unwrap_err();
        assert_eq!(err.line(), Some(2), "{err}");
        assert!(err.to_string().contains("a line longer than 1 MiB"), "{err}");
        // A line of exactly the limit is still read (the importers' CSV headers can be long).
        let mut lines = Lines::new(
            &path,
            Box::new(std::io::Cursor::new(format!("{}\n", "x".repeat(MAX_LINE_BYTES - 1)))),
        );
        assert!(lines.advance().unwrap());
        assert_eq!(lines.current().len(), MAX_LINE_BYTES - 1);
    }

    #[test]
    fn empty_and_missing_files_are_clear_errors() {
        let dir = Scratch::new("unit-log-empty");
        let path = dir.join("empty.pglog");
        std::fs::write(&path, "").unwrap();
        assert!(LogReader::open(&path).err().unwrap().to_string().contains("empty file"));
        let missing = dir.join("missing.pglog");
        assert!(matches!(LogReader::open(&missing), Err(LogError::Io { .. })));
    }

    #[test]
    fn a_log_is_replaced_only_by_a_finished_one() {
        let dir = Scratch::new("unit-log-atomic");
        let path = dir.join("kept.pglog.gz");
        let events = sample_events();
        write_log(&path, &[], &events).unwrap();
        let before = std::fs::read(&path).unwrap();
        // An import that fails half-way: the old log stays whole, and nothing else is left.
        {
            let mut w = LogWriter::create(&path, &[]).unwrap();
            w.write(&events[0]).unwrap();
        }
        assert_eq!(std::fs::read(&path).unwrap(), before);
        let names: Vec<_> = std::fs::read_dir(&*dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["kept.pglog.gz"]);
        // A finished one replaces it.
        write_log(&path, &[], &events[..1]).unwrap();
        let back: Vec<_> = LogReader::open(&path).unwrap().collect::<Result<_, _>>().unwrap();
        assert_eq!(back.len(), 1);
        // A folder is not a log file.
        let err = LogWriter::create(&dir, &[]).err().unwrap();
        assert!(err.to_string().contains("is a folder"), "{err}");
    }

    #[test]
    fn truncated_gzip_is_an_error_not_a_panic() {
        let dir = Scratch::new("unit-log-truncated");
        let path = dir.join("trunc.pglog.gz");
        let events: Vec<_> = (0..2000)
            .map(|i| SensorEvent::accelerometer(i, Vec3::splat(i as f32)))
            .collect();
        write_log(&path, &[], &events).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        let result: Result<Vec<_>, _> = LogReader::open(&path).and_then(|r| r.collect());
        assert!(result.is_err());
    }

    /// 3,000 one-megabyte `meta` lines would be 3 GB of header: refused at the budget.
    #[test]
    fn meta_lines_are_bounded_in_number_and_bytes() {
        let dir = Scratch::new("unit-log-meta");
        let many = dir.join("many.pglog");
        let mut text = "phantogram-sensor-log 1\n".to_owned();
        for i in 0..MAX_META_LINES + 1 {
            text.push_str(&format!("meta k{i} v\n"));
        }
        std::fs::write(&many, &text).unwrap();
        let err = LogReader::open(&many).err().expect("refused");
        assert!(err.to_string().contains("meta lines"), "{err}");
        let big = dir.join("big.pglog");
        let line = format!("meta note {}\n", "x".repeat(20 << 10));
        std::fs::write(&big, format!("phantogram-sensor-log 1\n{}", line.repeat(4))).unwrap();
        let err = LogReader::open(&big).err().expect("refused");
        assert_eq!(err.line(), Some(5), "{err}");
        // The limits leave room for real provenance.
        std::fs::write(
            &big,
            format!("phantogram-sensor-log 1\n{}acc 1 0 0 9.8\n", line.repeat(3)),
        )
        .unwrap();
        assert_eq!(LogReader::open(&big).unwrap().meta().len(), 3);
    }

    /// A 1 MB tag is quoted in a few dozen characters, control characters escaped.
    #[test]
    fn unknown_tags_are_quoted_as_short_excerpts() {
        let dir = Scratch::new("unit-log-tag");
        let path = dir.join("tag.pglog");
        std::fs::write(
            &path,
            format!("phantogram-sensor-log 1\n{}\u{1b}[2J 1 0 0 9.8\n", "a".repeat(1 << 19)),
        )
        .unwrap();
        let err = LogReader::open(&path).err().expect("refused").to_string();
        assert!(
            err.len() < 200 && err.contains("unknown record type"),
            "{} bytes: {}",
            err.len(),
            &err[..200.min(err.len())]
        );
    }

    /// The writer replaces only a regular file: a pipe (or `/dev/full`) stays what it was.
    #[cfg(unix)]
    #[test]
    fn a_log_is_never_written_over_a_device_or_a_pipe() {
        let dir = Scratch::new("unit-log-fifo");
        let fifo = dir.join("out.pglog");
        if std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success())
        {
            let err = write_log(&fifo, &[], &sample_events()).unwrap_err();
            assert!(err.to_string().contains("not a regular file"), "{err}");
            use std::os::unix::fs::FileTypeExt as _;
            assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
        }
    }
}
