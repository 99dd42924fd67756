//! Importers for real sensor exports, each into time-ordered [`SensorEvent`]s in the crate's device
//! frame and units. Which one applies is detected from the path ([`import`]):
//!
//! | source | looks like | notes |
//! |---|---|---|
//! | project log | file starting `phantogram-sensor-log` | see [`super`] |
//! | Android raw dump | folder with `accelerometer.txt[.gz]` | `t x y z` per line, phone-clock seconds; `gyroscope[-calibrated]`, `magnetometer[-calibrated]`, `rotation-vector` (`t x y z w [accuracy]`) optional; `mocap.csv.gz` + `timeAlignment.txt` become ground truth |
//! | Sensor Logger | folder with `Accelerometer.csv` whose header has `seconds_elapsed` | `time` in ns, columns named `x y z` in any order; the accelerometer (with gravity) is `TotalAcceleration.csv` (Android), else `AccelerometerUncalibrated.csv` (an iPhone's in g with the opposite sign, told by gravity's magnitude and converted); without either, `Accelerometer.csv` (gravity removed) becomes linear acceleration; `Orientation.csv` (`qx qy qz qw`) as the rotation vector |
//! | phyphox | folder with `Accelerometer.csv` whose header has `"Time (s)"` | seconds, Android frame, accelerometer with gravity; any of its CSV exports (comma, tab or semicolon between fields, a decimal point or comma), axis columns named `X` or `… x`, `NaN` cells (no data) skipped |
//! | BROAD | CSV (gzip or not) with header `t_s,acc_x,…` | one row per sample with all three sensors and the ground-truth quaternion; rows with NaN ground truth simply have none |
//!
//! All of Android, phyphox and BROAD already use (or, for BROAD's IMU, define) a right-handed
//! sensor frame, taken as the device frame unchanged.
//!
//! Errors name the file and the 1-based line. Files that are part of a folder but not sensor
//! streams (licences, `record.properties`, derived outputs such as Sensor Logger's
//! `imu_orientation.csv` whose angle convention is undocumented) are not read; the log's meta lists
//! what was read.

use std::path::{Path, PathBuf};

use glam::{Mat3, Quat, Vec3};

use super::{Lines, LogError, LogReader, MAX_EVENTS_IN_MEMORY, MAX_LINE_BYTES, parse_f64, seconds_to_ns};
use phantogram_files::text::{excerpt, strip_bom};
use phantogram_sensing::sensors::{SensorEvent, SensorKind};

/// Adds an imported event, refusing beyond [`MAX_EVENTS_IN_MEMORY`] (an import holds the whole
/// recording, to sort it), before the memory is taken.
fn push(events: &mut Vec<SensorEvent>, event: SensorEvent) -> Result<(), String> {
    if events.len() >= MAX_EVENTS_IN_MEMORY {
        return Err(super::too_many_events_message());
    }
    events.push(event);
    Ok(())
}

/// A whole imported recording.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImportedLog {
    pub meta: Vec<(String, String)>,
    /// Sorted by time stamp (stable: equal times keep file order).
    pub events: Vec<SensorEvent>,
}

impl ImportedLog {
    fn note(&mut self, key: &str, value: impl Into<String>) {
        self.meta.push((key.to_owned(), value.into()));
    }

    fn finish(mut self) -> Self {
        self.events.sort_by_key(|e| e.t_ns);
        self
    }

    pub fn count(&self, kind: SensorKind) -> usize {
        self.events.iter().filter(|e| e.kind == kind).count()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SourceFormat {
    Phantogram,
    AndroidRaw,
    SensorLogger,
    Phyphox,
    Broad,
}

impl SourceFormat {
    pub fn name(self) -> &'static str {
        match self {
            Self::Phantogram => "phantogram",
            Self::AndroidRaw => "android-raw",
            Self::SensorLogger => "sensor-logger",
            Self::Phyphox => "phyphox",
            Self::Broad => "broad",
        }
    }
}

/// The first line, without a byte-order mark.
fn first_line(path: &Path) -> Result<String, LogError> {
    let line = Lines::open(path)?.next_owned()?.unwrap_or_default();
    Ok(strip_bom(&line).to_owned())
}

/// `dir/base` or `dir/base.gz`, whichever exists.
fn find(dir: &Path, base: &str) -> Option<PathBuf> {
    [dir.join(base), dir.join(format!("{base}.gz"))]
        .into_iter()
        .find(|p| p.is_file())
}

pub fn detect(path: &Path) -> Result<SourceFormat, LogError> {
    if path.is_dir() {
        if find(path, "accelerometer.txt").is_some() {
            return Ok(SourceFormat::AndroidRaw);
        }
        // Sensor Logger writes no Accelerometer.csv on phones that cannot take gravity out.
        let acc = find(path, "Accelerometer.csv").or_else(|| find(path, "TotalAcceleration.csv"));
        if let Some(acc) = acc {
            let line = first_line(&acc)?;
            let header: Vec<String> = line
                .split(char::from(sniff_delimiter(&line)))
                .map(header_name)
                .collect();
            if header.iter().any(|h| h == "seconds_elapsed") {
                return Ok(SourceFormat::SensorLogger);
            }
            if header.first().is_some_and(|h| h == "time") {
                return Ok(SourceFormat::Phyphox);
            }
            return Err(LogError::parse(
                &acc,
                1,
                "unrecognised CSV header (expected Sensor Logger's or phyphox's)",
            ));
        }
        return Err(LogError::format(
            path,
            "unrecognised folder: expected an Android raw dump (accelerometer.txt[.gz]) or a Sensor Logger / phyphox export (Accelerometer.csv or TotalAcceleration.csv)",
        ));
    }
    let line = first_line(path)?;
    if line.starts_with(super::MAGIC) {
        Ok(SourceFormat::Phantogram)
    } else if line.starts_with("t_s,acc_x") {
        Ok(SourceFormat::Broad)
    } else if !path.exists() {
        Err(LogError::io(path, std::io::ErrorKind::NotFound.into()))
    } else {
        Err(LogError::parse(
            path,
            1,
            "unrecognised file: expected a phantogram sensor log or a BROAD CSV (or pass a recording folder)",
        ))
    }
}

/// Imports any supported source, detected from `path`.
pub fn import(path: &Path) -> Result<ImportedLog, LogError> {
    match detect(path)? {
        SourceFormat::Phantogram => {
            let reader = LogReader::open(path)?;
            let meta = reader.meta().to_vec();
            let events = super::read_all(path, reader)?;
            Ok(ImportedLog { meta, events })
        }
        SourceFormat::AndroidRaw => import_android_raw(path),
        SourceFormat::SensorLogger => import_sensor_logger(path),
        SourceFormat::Phyphox => import_phyphox(path),
        SourceFormat::Broad => import_broad(path),
    }
}

fn display_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

fn started(format: SourceFormat, path: &Path) -> ImportedLog {
    let mut log = ImportedLog::default();
    log.note("source", display_name(path));
    log.note("importer", format.name());
    log
}

/// Whitespace-separated numeric rows: `t x y z [w [more…]]`, `min..=max` columns.
fn read_whitespace_rows(
    path: &Path,
    min_cols: usize,
    max_cols: usize,
    mut row: impl FnMut(&[f64]) -> Result<(), String>,
) -> Result<(), LogError> {
    let mut lines = Lines::open(path)?;
    let mut values = Vec::with_capacity(max_cols);
    while lines.advance()? {
        let line = lines.current().trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        values.clear();
        for f in line.split_whitespace() {
            values.push(parse_f64(f).map_err(|m| lines.error(m))?);
        }
        if values.len() < min_cols || values.len() > max_cols {
            let m = format!("expected {min_cols}..={max_cols} columns, found {}", values.len());
            return Err(lines.error(m));
        }
        row(&values).map_err(|m| lines.error(m))?;
    }
    Ok(())
}

/// Header names, normalised: quotes and units in parentheses dropped, lower case
/// (`"X (m/s^2)"` → `x`).
fn header_name(h: &str) -> String {
    let h = strip_bom(h).trim().trim_matches('"');
    let h = h.split(" (").next().unwrap_or(h);
    h.trim().to_lowercase()
}

/// The field separator of a CSV, from its header line: a tab or a semicolon outside quotes, else
/// a comma. phyphox offers all three ("CSV (Tabulator, decimal comma)", "CSV (Semicolon, decimal
/// point)", …), and spreadsheets in locales whose decimal mark is a comma write semicolons.
/// Column names have neither, so one occurrence decides.
fn sniff_delimiter(header: &str) -> u8 {
    let mut quoted = false;
    let (mut tab, mut semicolon) = (false, false);
    for c in header.chars() {
        match c {
            '"' => quoted = !quoted,
            '\t' if !quoted => tab = true,
            ';' if !quoted => semicolon = true,
            _ => {}
        }
    }
    if tab {
        b'\t'
    } else if semicolon {
        b';'
    } else {
        b','
    }
}

/// The column that stands for `wanted` (a header name as [`header_name`] gives it): the one
/// named exactly so, else the only one whose last word it is ("acceleration x" for `x`, as
/// phyphox's single-sensor experiments name their columns).
fn column_index(names: &[String], wanted: &str) -> Result<usize, String> {
    if let Some(i) = names.iter().position(|n| n == wanted) {
        return Ok(i);
    }
    let suffix = format!(" {wanted}");
    let mut by_last_word = names.iter().enumerate().filter(|(_, n)| n.ends_with(&suffix));
    match (by_last_word.next(), by_last_word.next()) {
        (Some((i, _)), None) => Ok(i),
        (Some((_, a)), Some((_, b))) => Err(format!(
            "CSV header has more than one column for {wanted:?} ({a:?}, {b:?})"
        )),
        _ => Err(format!("CSV header lacks column {wanted:?}")),
    }
}

/// A CSV with a header row: calls `row` with the raw fields of the `wanted` columns, in that order.
///
/// Read by the `csv` crate (RFC 4180: quoted fields, CRLF, a byte-order mark): every row must have
/// as many fields as the header. The separator is the header's ([`sniff_delimiter`]); where it is
/// a tab or a semicolon, a comma in a field is a decimal comma and is handed on as a point. With
/// comma-separated fields a row with more fields than the header is how a decimal comma shows up
/// (`0,5` read as two fields): it is an error naming its line, never data shifted into the next
/// column. A line longer than [`MAX_LINE_BYTES`] is an error before it is held in memory.
fn read_csv(path: &Path, wanted: &[&str], mut row: impl FnMut(&[&str]) -> Result<(), String>) -> Result<(), LogError> {
    let mut input = super::open_maybe_gz(path)?;
    // The header as far as the first read holds it (a header is far shorter), peeked, not
    // consumed: the file is opened once.
    let head = input.fill_buf().map_err(|e| LogError::io(path, e))?;
    let header = head.split(|&b| b == b'\n').next().unwrap_or_default();
    let delimiter = sniff_delimiter(&String::from_utf8_lossy(header));
    let reader = LineLengthGuard::new(input);
    let mut csv = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(false)
        .delimiter(delimiter)
        .from_reader(reader);
    let csv_error = |e: csv::Error| -> LogError {
        let line = e.position().map_or(0, |p| p.line());
        let message = match e.kind() {
            csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
                format!("{len} fields where the header has {expected_len} (a decimal comma, or a damaged row?)")
            }
            csv::ErrorKind::Io(io) => io.to_string(),
            csv::ErrorKind::Utf8 { .. } => "not UTF-8 text".to_owned(),
            _ => e.to_string(),
        };
        if line > 0 {
            LogError::parse(path, line, message)
        } else {
            LogError::format(path, message)
        }
    };
    let names: Vec<String> = csv.headers().map_err(csv_error)?.iter().map(header_name).collect();
    if names.iter().all(String::is_empty) {
        return Err(LogError::format(path, "empty file: expected a CSV header"));
    }
    let mut index = Vec::with_capacity(wanted.len());
    for w in wanted {
        index.push(column_index(&names, w).map_err(|m| LogError::parse(path, 1, m))?);
    }
    let mut record = csv::StringRecord::new();
    loop {
        match csv.read_record(&mut record) {
            Ok(true) => {}
            Ok(false) => return Ok(()),
            Err(e) => return Err(csv_error(e)),
        }
        let line = record.position().map_or(0, |p| p.line());
        // A blank line (a trailing newline pair) is no row.
        if record.len() == 1 && record[0].trim().is_empty() {
            continue;
        }
        let picked: Vec<std::borrow::Cow<str>> = index
            .iter()
            .map(|&i| {
                let f = &record[i];
                if delimiter != b',' && f.contains(',') {
                    f.replace(',', ".").into()
                } else {
                    f.into()
                }
            })
            .collect();
        let picked: Vec<&str> = picked.iter().map(|f| f.as_ref()).collect();
        row(&picked).map_err(|m| LogError::parse(path, line, m))?;
    }
}

/// Passes bytes through, failing once a line grows past [`MAX_LINE_BYTES`]: what the CSV reader
/// would otherwise hold of a file that is not text, or of a gzip stream inflating to gigabytes
/// without a line break.
struct LineLengthGuard<R> {
    inner: R,
    run: usize,
}

impl<R: std::io::Read> LineLengthGuard<R> {
    fn new(inner: R) -> Self {
        Self { inner, run: 0 }
    }
}

impl<R: std::io::Read> std::io::Read for LineLengthGuard<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        for &b in &buf[..n] {
            self.run = if b == b'\n' { 0 } else { self.run + 1 };
            if self.run > MAX_LINE_BYTES {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    format!("a line longer than {} MiB: not a sensor export", MAX_LINE_BYTES >> 20),
                ));
            }
        }
        Ok(n)
    }
}

fn vec3(v: &[f64]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

fn parse_fields(fields: &[&str]) -> Result<Vec<f64>, String> {
    fields.iter().map(|f| parse_f64(f)).collect()
}

// ---------------------------------------------------------------------------------------------
// Android raw dumps (Inria benchmarks-attitude-smartphones layout)

pub fn import_android_raw(dir: &Path) -> Result<ImportedLog, LogError> {
    let mut log = started(SourceFormat::AndroidRaw, dir);
    let acc = find(dir, "accelerometer.txt")
        .ok_or_else(|| LogError::format(dir, "no accelerometer.txt[.gz] in this folder"))?;
    let streams = [
        (Some(acc), SensorKind::Accelerometer),
        (
            find(dir, "gyroscope-calibrated.txt").or_else(|| find(dir, "gyroscope.txt")),
            SensorKind::Gyroscope,
        ),
        (
            find(dir, "magnetometer-calibrated.txt").or_else(|| find(dir, "magnetometer.txt")),
            SensorKind::Magnetometer,
        ),
        (find(dir, "rotation-vector.txt"), SensorKind::RotationVector),
    ];
    for (path, kind) in streams {
        let Some(path) = path else { continue };
        let (min, max) = if kind.is_orientation() { (5, 6) } else { (4, 4) };
        let events = &mut log.events;
        read_whitespace_rows(&path, min, max, |v| {
            let t_ns = seconds_to_ns(v[0])?;
            push(
                events,
                if kind.is_orientation() {
                    // Android's rotation vector: x y z w (w present on API ≥ 18).
                    let q = Quat::from_xyzw(v[1] as f32, v[2] as f32, v[3] as f32, v[4] as f32);
                    SensorEvent::orientation(kind, t_ns, q)
                } else {
                    SensorEvent::vector(kind, t_ns, vec3(&v[1..4]))
                },
            )?;
            Ok(())
        })?;
        log.note("read", display_name(&path));
    }
    if let Some(mocap) = find(dir, "mocap.csv") {
        match find(dir, "timeAlignment.txt") {
            Some(align) => {
                let offset_s = read_time_alignment(&align)?;
                import_mocap(&mocap, offset_s, &mut log.events)?;
                log.note("read", display_name(&mocap));
                log.note("read", display_name(&align));
                log.note(
                    "ground_truth",
                    "mocap rotation; heading is the motion-capture room's, not north",
                );
            }
            None => log.note(
                "skipped",
                "mocap.csv: no timeAlignment.txt to put it on the phone clock",
            ),
        }
    }
    Ok(log.finish())
}

fn read_time_alignment(path: &Path) -> Result<f64, LogError> {
    let mut offset = None;
    read_whitespace_rows(path, 1, 1, |v| {
        if offset.replace(v[0]).is_some() {
            return Err("expected a single number".into());
        }
        if !v[0].is_finite() {
            return Err("time alignment is not finite".into());
        }
        Ok(())
    })?;
    offset.ok_or_else(|| LogError::format(path, "empty time alignment file"))
}

/// `t_mocap_s, r00…r22, up…`: `R` maps world vectors into the body (its third column is world up
/// in the body frame), so device → world is `Rᵀ`. Phone time = mocap time − alignment.
fn import_mocap(path: &Path, align_s: f64, out: &mut Vec<SensorEvent>) -> Result<(), LogError> {
    let cols = [
        "t_mocap_s",
        "r00",
        "r01",
        "r02",
        "r10",
        "r11",
        "r12",
        "r20",
        "r21",
        "r22",
    ];
    read_csv(path, &cols, |f| {
        let v = parse_fields(f)?;
        if v[1..].iter().any(|x| !x.is_finite()) {
            return Ok(()); // tracking lost
        }
        let row = |i: usize| Vec3::new(v[1 + 3 * i] as f32, v[2 + 3 * i] as f32, v[3 + 3 * i] as f32);
        // Columns of Rᵀ are the rows of R.
        let m = Mat3::from_cols(row(0), row(1), row(2));
        let det = m.determinant();
        if (det - 1.0).abs() > 0.05 {
            return Err(format!("rotation matrix is not a rotation (determinant {det})"));
        }
        let t_ns = seconds_to_ns(v[0] - align_s)?;
        push(
            out,
            SensorEvent::orientation(SensorKind::GroundTruth, t_ns, Quat::from_mat3(&m).normalize()),
        )
    })
}

// ---------------------------------------------------------------------------------------------
// Sensor Logger

pub fn import_sensor_logger(dir: &Path) -> Result<ImportedLog, LogError> {
    let mut log = started(SourceFormat::SensorLogger, dir);
    // The accelerometer with gravity, best first (Sensor Logger's units reference): Android's
    // TotalAcceleration.csv (calibrated, m/s²); AccelerometerUncalibrated.csv (m/s², or on
    // iPhones in g with the opposite sign, below). Accelerometer.csv has gravity taken out
    // (linear acceleration): kept only when neither exists.
    let total = find(dir, "TotalAcceleration.csv");
    let uncal = find(dir, "AccelerometerUncalibrated.csv");
    let with_gravity = total.or(uncal.clone());
    let linear = if with_gravity.is_some() {
        None
    } else {
        find(dir, "Accelerometer.csv")
    };
    let streams = [
        (linear, SensorKind::LinearAcceleration),
        (with_gravity.clone(), SensorKind::Accelerometer),
        (find(dir, "Gyroscope.csv"), SensorKind::Gyroscope),
        (find(dir, "Magnetometer.csv"), SensorKind::Magnetometer),
    ];
    for (path, kind) in streams {
        let Some(path) = path else {
            continue;
        };
        let events = &mut log.events;
        read_csv(&path, &["time", "x", "y", "z"], |f| {
            let t_ns = parse_ns(f[0])?;
            let v = parse_fields(&f[1..])?;
            push(events, SensorEvent::vector(kind, t_ns, vec3(&v)))
        })?;
        log.note("read", display_name(&path));
    }
    if with_gravity.is_some() && with_gravity == uncal && iphone_units(&mut log.events) {
        log.note(
            "note",
            "AccelerometerUncalibrated.csv is in g with iOS's sign (gravity reads −1 g): turned into m/s² with Android's",
        );
    }
    if log.count(SensorKind::LinearAcceleration) > 0 {
        log.note(
            "note",
            "Accelerometer.csv has gravity removed: imported as linear acceleration",
        );
    }
    if let Some(path) = find(dir, "Orientation.csv") {
        let events = &mut log.events;
        read_csv(&path, &["time", "qx", "qy", "qz", "qw"], |f| {
            let t_ns = parse_ns(f[0])?;
            let v = parse_fields(&f[1..])?;
            let q = Quat::from_xyzw(v[0] as f32, v[1] as f32, v[2] as f32, v[3] as f32);
            push(events, SensorEvent::orientation(SensorKind::RotationVector, t_ns, q))
        })?;
        log.note("read", display_name(&path));
    }
    Ok(log.finish())
}

/// Sensor Logger on an iPhone, with its default "Standardise Units & Frames" off, writes the
/// uncalibrated accelerometer in g and with every axis negated against Android's convention
/// (its units and cross-platform references). The file does not say which phone made it, but
/// gravity does: the median magnitude of a hand-held recording is about 1 g, 9.8 in m/s² and
/// 1.0 in g, so a median under 3 (about the geometric mean of the two) can only be g.
/// Such readings are turned into m/s² with Android's sign; the answer is whether they were.
fn iphone_units(events: &mut [SensorEvent]) -> bool {
    let mut magnitudes: Vec<f32> = events
        .iter()
        .filter(|e| e.kind == SensorKind::Accelerometer)
        .map(|e| e.vec3().length())
        .filter(|m| m.is_finite())
        .collect();
    if magnitudes.is_empty() {
        return false;
    }
    let mid = magnitudes.len() / 2;
    let (_, median, _) = magnitudes.select_nth_unstable_by(mid, f32::total_cmp);
    if *median >= 3.0 {
        return false;
    }
    const STANDARD_GRAVITY_M_S2: f32 = 9.806_65;
    for e in events.iter_mut().filter(|e| e.kind == SensorKind::Accelerometer) {
        *e = SensorEvent::vector(e.kind, e.t_ns, e.vec3() * -STANDARD_GRAVITY_M_S2);
    }
    true
}

/// Integer nanoseconds, or a float (some exports write `1.76e18`).
fn parse_ns(field: &str) -> Result<i64, String> {
    let f = field.trim().trim_matches('"');
    if let Ok(t) = f.parse::<i64>()
        && phantogram_sensing::sensors::time_in_range(t)
    {
        return Ok(t);
    }
    let t = parse_f64(f)?;
    if t.is_finite() && t.abs() <= phantogram_sensing::sensors::MAX_ABS_T_NS as f64 {
        Ok(t.round() as i64)
    } else {
        Err(format!("time stamp {} is not usable", excerpt(field)))
    }
}

// ---------------------------------------------------------------------------------------------
// phyphox

pub fn import_phyphox(dir: &Path) -> Result<ImportedLog, LogError> {
    let mut log = started(SourceFormat::Phyphox, dir);
    let streams = [
        ("Accelerometer.csv", SensorKind::Accelerometer),
        ("Gyroscope.csv", SensorKind::Gyroscope),
        ("Magnetometer.csv", SensorKind::Magnetometer),
        ("Linear Accelerometer.csv", SensorKind::LinearAcceleration),
    ];
    let mut empty_rows = 0usize;
    for (name, kind) in streams {
        let Some(path) = find(dir, name) else { continue };
        let events = &mut log.events;
        read_csv(&path, &["time", "x", "y", "z"], |f| {
            let v = parse_fields(f)?;
            // phyphox fills the cells of a column shorter than the longest with "NaN": no data.
            if v.iter().any(|x| x.is_nan()) {
                empty_rows += 1;
                return Ok(());
            }
            push(events, SensorEvent::vector(kind, seconds_to_ns(v[0])?, vec3(&v[1..])))
        })?;
        log.note("read", display_name(&path));
    }
    if empty_rows > 0 {
        log.note("note", format!("{empty_rows} row(s) without data (NaN) skipped"));
    }
    Ok(log.finish())
}

// ---------------------------------------------------------------------------------------------
// BROAD

pub fn import_broad(path: &Path) -> Result<ImportedLog, LogError> {
    let mut log = started(SourceFormat::Broad, path);
    let cols = [
        "t_s", "acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z", "mag_x", "mag_y", "mag_z", "gt_qw", "gt_qx",
        "gt_qy", "gt_qz",
    ];
    let events = &mut log.events;
    read_csv(path, &cols, |f| {
        let v = parse_fields(f)?;
        let t_ns = seconds_to_ns(v[0])?;
        push(events, SensorEvent::accelerometer(t_ns, vec3(&v[1..4])))?;
        push(events, SensorEvent::gyroscope(t_ns, vec3(&v[4..7])))?;
        push(events, SensorEvent::magnetometer(t_ns, vec3(&v[7..10])))?;
        let q = Quat::from_xyzw(v[11] as f32, v[12] as f32, v[13] as f32, v[10] as f32);
        if q.is_finite() {
            push(events, SensorEvent::orientation(SensorKind::GroundTruth, t_ns, q))?;
        }
        Ok(())
    })?;
    log.note(
        "ground_truth",
        "optical motion capture, sensor → earth (east, north, up)",
    );
    Ok(log.finish())
}

/// BROAD's `movement` column: `(t_ns, moving)` per row, for scoring only the motion phases.
pub fn read_broad_movement(path: &Path) -> Result<Vec<(i64, bool)>, LogError> {
    let mut out = Vec::new();
    read_csv(path, &["t_s", "movement"], |f| {
        let t_ns = seconds_to_ns(parse_f64(f[0])?)?;
        let moving = match f[1].trim() {
            "1" | "1.0" | "true" => true,
            "0" | "0.0" | "false" => false,
            other => return Err(format!("movement flag must be 0 or 1, found {}", excerpt(other))),
        };
        out.push((t_ns, moving));
        Ok(())
    })?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn temp_dir(name: &str) -> phantogram_testkit::Scratch {
        phantogram_testkit::Scratch::new(&format!("unit-import-{name}"))
    }

    fn write_gz(path: &Path, text: &str) {
        let f = std::fs::File::create(path).unwrap();
        let mut gz = flate2::write::GzEncoder::new(f, flate2::Compression::fast());
        gz.write_all(text.as_bytes()).unwrap();
        gz.finish().unwrap();
    }

    #[test]
    fn android_raw_folder_with_ground_truth() {
        let dir = temp_dir("android");
        write_gz(&dir.join("accelerometer.txt.gz"), "0.5 0 0 9.81\n0.51 0 0.1 9.8\n");
        write_gz(&dir.join("gyroscope-calibrated.txt.gz"), "0.505 0.1 0.2 0.3\n");
        std::fs::write(dir.join("rotation-vector.txt"), "0.52 0 0 0 1 0.17\n").unwrap();
        std::fs::write(dir.join("timeAlignment.txt"), "  6.5000000e-01\n").unwrap();
        // Identity mocap at mocap time 1.2 s → phone time 0.55 s.
        write_gz(
            &dir.join("mocap.csv.gz"),
            "t_mocap_s,r00,r01,r02,r10,r11,r12,r20,r21,r22,up_x,up_y,up_z\n1.2,1,0,0,0,1,0,0,0,1,0,0,1\n1.3,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN\n",
        );
        assert_eq!(detect(&dir).unwrap(), SourceFormat::AndroidRaw);
        let log = import(&dir).unwrap();
        let kinds: Vec<_> = log.events.iter().map(|e| (e.t_ns, e.kind)).collect();
        assert_eq!(
            kinds,
            [
                (500_000_000, SensorKind::Accelerometer),
                (505_000_000, SensorKind::Gyroscope),
                (510_000_000, SensorKind::Accelerometer),
                (520_000_000, SensorKind::RotationVector),
                (550_000_000, SensorKind::GroundTruth),
            ]
        );
        assert_eq!(log.events[1].vec3(), Vec3::new(0.1, 0.2, 0.3));
    }

    #[test]
    fn mocap_orientation_convention() {
        // R maps world to body; pitched 30° about x, world up seen in the body is (0, sin, cos).
        let dir = temp_dir("mocap");
        let truth = Quat::from_rotation_x(30f32.to_radians()); // device → world
        let r = Mat3::from_quat(truth.inverse()); // world → device
        let rows = [r.row(0), r.row(1), r.row(2)];
        let cells: Vec<String> = rows.iter().flat_map(|v| v.to_array()).map(|x| x.to_string()).collect();
        let up = truth.inverse() * Vec3::Z;
        let text = format!(
            "t_mocap_s,r00,r01,r02,r10,r11,r12,r20,r21,r22,up_x,up_y,up_z\n0.0,{},{},{},{}\n",
            cells.join(","),
            up.x,
            up.y,
            up.z
        );
        std::fs::write(dir.join("mocap.csv"), text).unwrap();
        let mut out = Vec::new();
        import_mocap(&dir.join("mocap.csv"), 0.0, &mut out).unwrap();
        let q = out[0].quat().unwrap();
        assert!(q.angle_between(truth) < 1e-4);
        // The file's up column is R's third column, as the convention requires.
        assert!((rows[0].z - up.x).abs() < 1e-6 && (rows[1].z - up.y).abs() < 1e-6);
    }

    #[test]
    fn sensor_logger_and_phyphox_headers() {
        let dir = temp_dir("sl");
        std::fs::write(
            dir.join("Accelerometer.csv"),
            "time,seconds_elapsed,z,y,x\n1000,0.0,3,2,1\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("Gyroscope.csv"),
            "time,seconds_elapsed,z,y,x\n2000,0.0,0.3,0.2,0.1\n",
        )
        .unwrap();
        assert_eq!(detect(&dir).unwrap(), SourceFormat::SensorLogger);
        let log = import(&dir).unwrap();
        assert_eq!(log.events[0].kind, SensorKind::LinearAcceleration);
        assert_eq!(
            log.events[0].vec3(),
            Vec3::new(1.0, 2.0, 3.0),
            "columns by name, not position"
        );
        assert_eq!(log.events[1].t_ns, 2000);

        // Android's TotalAcceleration.csv (with gravity) is the accelerometer; the linear
        // acceleration beside it is not imported, and the folder is recognised without it.
        std::fs::write(
            dir.join("TotalAcceleration.csv"),
            "time,seconds_elapsed,z,y,x\n1000,0.0,9.7,0.5,0.2\n",
        )
        .unwrap();
        let log = import(&dir).unwrap();
        assert_eq!(log.count(SensorKind::LinearAcceleration), 0);
        assert_eq!(log.count(SensorKind::Accelerometer), 1);
        assert_eq!(log.events[0].vec3(), Vec3::new(0.2, 0.5, 9.7));
        std::fs::remove_file(dir.join("Accelerometer.csv")).unwrap();
        assert_eq!(detect(&dir).unwrap(), SourceFormat::SensorLogger);
        assert_eq!(import(&dir).unwrap().count(SensorKind::Accelerometer), 1);

        // An iPhone's uncalibrated accelerometer, in g with gravity reading −1 g face up:
        // m/s² with Android's sign. An Android one (m/s²) is left as it is.
        let dir = temp_dir("sl-iphone");
        std::fs::write(
            dir.join("AccelerometerUncalibrated.csv"),
            "time,seconds_elapsed,z,y,x\n1000,0.0,-0.98,-0.1,0.05\n2000,0.01,-1.02,-0.1,0.0\n3000,0.02,-0.5,-0.9,0.0\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("Accelerometer.csv"),
            "time,seconds_elapsed,z,y,x\n1000,0.0,0.1,0,0\n",
        )
        .unwrap();
        let log = import(&dir).unwrap();
        assert_eq!(log.count(SensorKind::LinearAcceleration), 0);
        let acc: Vec<Vec3> = log.events.iter().map(|e| e.vec3()).collect();
        assert_eq!(acc.len(), 3);
        assert!(
            (acc[0] - Vec3::new(-0.05, 0.1, 0.98) * 9.80665).length() < 1e-4,
            "{acc:?}"
        );
        assert!(
            log.meta.iter().any(|(_, v)| v.contains("in g with iOS's sign")),
            "{:?}",
            log.meta
        );
        std::fs::write(
            dir.join("AccelerometerUncalibrated.csv"),
            "time,seconds_elapsed,z,y,x\n1000,0.0,9.6,-1,0.5\n2000,0.01,10.1,-1,0.0\n",
        )
        .unwrap();
        let log = import(&dir).unwrap();
        assert_eq!(log.events[0].vec3(), Vec3::new(0.5, -1.0, 9.6));
        assert!(!log.meta.iter().any(|(_, v)| v.contains("iOS")));

        let dir = temp_dir("phyphox");
        std::fs::write(
            dir.join("Accelerometer.csv"),
            "\"Time (s)\",\"X (m/s^2)\",\"Y (m/s^2)\",\"Z (m/s^2)\"\n3.4E-3,-4.8E-1,1.7E0,9.4E0\n",
        )
        .unwrap();
        assert_eq!(detect(&dir).unwrap(), SourceFormat::Phyphox);
        let log = import(&dir).unwrap();
        assert_eq!(log.events[0].t_ns, 3_400_000);
        assert_eq!(log.events[0].kind, SensorKind::Accelerometer);
    }

    /// phyphox's five CSV exports (comma, tab or semicolon between fields; a decimal point or,
    /// with tabs and semicolons, a decimal comma) as its exporter writes them: quoted names,
    /// numbers as `0.000000000E0`, "NaN" where a column has no data.
    #[test]
    fn every_phyphox_csv_export_reads_the_same() {
        let rows = [
            [3.446083327e-3, -4.806504822e-1, 1.707798615, 9.449848938],
            [1.337908334e-2, -5.548960876e-1, 1.533411255, 9.562863922],
        ];
        let gyro = [[1.958608333e-2, 0.1314016283, 0.1265425533, 0.07930336893]];
        let write = |dir: &Path, name: &str, names: [&str; 4], values: &[[f64; 4]], sep: char, comma: bool| {
            let mut text = names.map(|n| format!("\"{n}\"")).join(&sep.to_string());
            text.push('\n');
            for r in values {
                let fields = r.map(|v| {
                    let f = format!("{v:.9E}");
                    if comma { f.replace('.', ",") } else { f }
                });
                text.push_str(&fields.join(&sep.to_string()));
                text.push('\n');
            }
            // A padded row, as the exporter writes one for a shorter column.
            text.push_str(&["NaN"; 4].join(&sep.to_string()));
            text.push('\n');
            std::fs::write(dir.join(name), text).unwrap();
        };
        let mut reference = None;
        for (sep, comma) in [(',', false), ('\t', false), (';', false), ('\t', true), (';', true)] {
            let dir = temp_dir(&format!("phyphox-{}-{comma}", sep as u32));
            write(
                &dir,
                "Accelerometer.csv",
                ["Time (s)", "X (m/s^2)", "Y (m/s^2)", "Z (m/s^2)"],
                &rows,
                sep,
                comma,
            );
            // A single-sensor experiment's column names: the axis is the name's last word.
            write(
                &dir,
                "Gyroscope.csv",
                [
                    "Time (s)",
                    "Gyroscope x (rad/s)",
                    "Gyroscope y (rad/s)",
                    "Gyroscope z (rad/s)",
                ],
                &gyro,
                sep,
                comma,
            );
            assert_eq!(detect(&dir).unwrap(), SourceFormat::Phyphox, "{sep:?} {comma}");
            let log = import(&dir).unwrap_or_else(|e| panic!("{sep:?} {comma}: {e}"));
            assert_eq!(log.count(SensorKind::Accelerometer), 2);
            assert_eq!(log.count(SensorKind::Gyroscope), 1);
            let acc = log.events.iter().find(|e| e.kind == SensorKind::Accelerometer).unwrap();
            assert_eq!(acc.t_ns, 3_446_083);
            let expected = |r: [f64; 4]| Vec3::new(r[1] as f32, r[2] as f32, r[3] as f32);
            assert!((acc.vec3() - expected(rows[0])).length() < 1e-6);
            let gyr = log.events.iter().find(|e| e.kind == SensorKind::Gyroscope).unwrap();
            assert!((gyr.vec3() - expected(gyro[0])).length() < 1e-6);
            assert!(
                log.meta
                    .iter()
                    .any(|(k, v)| k == "note" && v.contains("2 row(s) without data")),
                "{:?}",
                log.meta
            );
            match &reference {
                None => reference = Some(log.events),
                Some(r) => assert_eq!(&log.events, r, "{sep:?} {comma}"),
            }
        }
        // Two columns that could each be "x": refused by name, not guessed.
        let dir = temp_dir("phyphox-ambiguous");
        write(
            &dir,
            "Accelerometer.csv",
            [
                "Time (s)",
                "Acceleration x (m/s^2)",
                "Linear Acceleration x (m/s^2)",
                "Z (m/s^2)",
            ],
            &rows,
            ',',
            false,
        );
        let err = import(&dir).unwrap_err().to_string();
        assert!(err.contains("more than one column for \"x\""), "{err}");
    }

    #[test]
    fn broad_rows_split_into_events() {
        let dir = temp_dir("broad");
        let path = dir.join("trial.csv");
        std::fs::write(
            &path,
            "t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,mag_x,mag_y,mag_z,gt_qw,gt_qx,gt_qy,gt_qz,movement\n\
             0.0,0,0,9.8,0,0,0,0,20,-40,NaN,NaN,NaN,NaN,0\n\
             0.0035,0,0,9.8,0,0,0,0,20,-40,1,0,0,0,1\n",
        )
        .unwrap();
        let log = import(&path).unwrap();
        assert_eq!(log.count(SensorKind::Accelerometer), 2);
        assert_eq!(
            log.count(SensorKind::GroundTruth),
            1,
            "NaN ground truth is absence, not an error"
        );
        assert_eq!(log.events.last().unwrap().t_ns, 3_500_000);
    }

    #[test]
    fn malformed_input_names_file_and_line() {
        let dir = temp_dir("bad");
        std::fs::write(dir.join("accelerometer.txt"), "0.5 0 0 9.81\n0.6 0 zero 9.81\n").unwrap();
        let err = import(&dir).unwrap_err();
        assert_eq!(err.line(), Some(2));
        assert!(err.to_string().contains("accelerometer.txt:2:"), "{err}");

        std::fs::write(dir.join("accelerometer.txt"), "0.5 0 0 9.81\n0.6 0 9.81\n").unwrap();
        assert!(import(&dir).unwrap_err().to_string().contains("columns"));

        let empty = temp_dir("empty");
        assert!(matches!(import(&empty), Err(LogError::Format { .. })));
        let other = empty.join("x.txt");
        std::fs::write(&other, "hello\n").unwrap();
        assert_eq!(import(&other).unwrap_err().line(), Some(1));
        assert!(matches!(import(&empty.join("missing")), Err(LogError::Io { .. })));
    }

    /// A BROAD CSV written with decimal commas has more fields per row than its header: an
    /// error naming the line, never values shifted into the next column.
    #[test]
    fn rows_with_more_fields_than_the_header_are_refused_with_their_line() {
        let dir = temp_dir("decimal-comma");
        let header = "t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,mag_x,mag_y,mag_z,gt_qw,gt_qx,gt_qy,gt_qz\n";
        let good = "0.01,0.1,0.2,9.8,0,0,0,20,0,-40,1,0,0,0\n";
        let comma = "0,02,0,1,0,2,9,8,0,0,0,20,0,-40,1,0,0,0\n";
        let path = dir.join("trial.csv");
        std::fs::write(&path, format!("{header}{good}{comma}")).unwrap();
        let err = import(&path).unwrap_err();
        assert_eq!(err.line(), Some(3), "{err}");
        assert!(err.to_string().contains("fields where the header has 14"), "{err}");
        // Quoted fields and CRLF line ends are CSV too.
        std::fs::write(
            &path,
            format!("{}{}", header.replace('\n', "\r\n"), good.replace("0.1,", "\"0.1\",")),
        )
        .unwrap();
        assert_eq!(import(&path).unwrap().events.len(), 4);
    }

    /// Windows editors and some exporters start text with a byte-order mark.
    #[test]
    fn a_byte_order_mark_is_accepted_by_every_text_importer() {
        let dir = temp_dir("bom");
        let broad = dir.join("trial.csv");
        std::fs::write(
            &broad,
            "\u{feff}t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,mag_x,mag_y,mag_z,gt_qw,gt_qx,gt_qy,gt_qz\n0.01,0.1,0.2,9.8,0,0,0,20,0,-40,1,0,0,0\n",
        )
        .unwrap();
        assert_eq!(import(&broad).unwrap().events.len(), 4);
        let log = dir.join("log.pglog");
        std::fs::write(&log, "\u{feff}phantogram-sensor-log 1\nacc 1 0 0 9.81\n").unwrap();
        assert_eq!(import(&log).unwrap().events.len(), 1);
        let phyphox = temp_dir("bom-phyphox");
        std::fs::write(
            phyphox.join("Accelerometer.csv"),
            "\u{feff}\"Time (s)\",\"X (m/s^2)\",\"Y (m/s^2)\",\"Z (m/s^2)\"\n0.5,0,0,9.81\n",
        )
        .unwrap();
        assert_eq!(import(&phyphox).unwrap().events.len(), 1);
    }

    /// A gzip stream inflating to a line of gigabytes stops at the line limit.
    #[test]
    fn an_endless_csv_line_is_an_error_not_gigabytes() {
        let dir = temp_dir("long-csv");
        let path = dir.join("trial.csv.gz");
        let mut text = "t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,mag_x,mag_y,mag_z,gt_qw,gt_qx,gt_qy,gt_qz\n".to_owned();
        text.push_str(&"1".repeat(MAX_LINE_BYTES + 10));
        write_gz(&path, &text);
        let err = import(&path).unwrap_err().to_string();
        assert!(err.contains("longer than 1 MiB"), "{err}");
    }
}
