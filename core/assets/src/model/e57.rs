//! Point clouds in ASTM E57, the exchange format of terrestrial and handheld laser scanners (what
//! a museum's scanning team most often hands over), read by the `e57` crate: a pure-Rust reader
//! written for untrusted files (no `unsafe`, no panics by its own lints, every page's checksum
//! checked, its XML section's size capped).
//!
//! * **Scans**: a file holds one or more scans, each with its pose in the file's frame; every
//!   scan is read, its pose applied, so that they meet as the scanner software registered them.
//!   Points in spherical coordinates (range, azimuth, elevation) are turned into Cartesian ones;
//!   points whose coordinates the file marks invalid (no return) are left out.
//! * **Points kept**: every `stride`-th point over all scans, the stride chosen from the scans'
//!   counts so that at most [`RAW_POINTS_KEPT`] remain, as for LAS.
//! * **Frame**: metres, with +Z up for a levelled scanner (the standard's convention), turned by
//!   the caller into glTF's +Y up, and taken about their centre (`scan_points`).
//! * **Colour**: the points' colour, scaled by the file's colour limits, where every scan has
//!   colour (a scan without would otherwise read as black); else their intensity (scaled by its
//!   limits) shades them (`scan_points`).
//!
//! **Budget**: the caller read the file within the budget; each reader (one a thread) holds a
//! page and a packet at a time, and at most [`RAW_POINTS_KEPT`] points are kept (40 bytes each)
//! whatever the file's size. **Progress**: `keep_going` is told the share read every 65 536
//! points and stops the work by returning `false` (for a file of several scans, decoded a window
//! of scans at a time, after each window). **Threading**: a file of several scans has them
//! decoded on every core, each with its own reader of the same bytes (within
//! [`MOST_XML_PARSED_AGAIN`]), and put together in the file's order (the same points as read one
//! after another; tested). **Panics**: none (the reader's, should one slip through a damaged
//! file, are caught and reported as the file's error).

use std::io::Cursor;

use e57::{CartesianCoordinate, E57Reader};

use super::le_fields;
use super::mesh_file::Soup;
use super::scan_points::{CUT_SHORT, RAW_POINTS_KEPT, ScanPoints};

/// The signature an E57 file begins with.
const SIGNATURE: &[u8] = b"ASTM-E57";

/// Points between two calls of `keep_going`.
const POINTS_PER_STEP: u64 = 1 << 16;

/// The most XML the readers of a file decoded in parallel may parse again, bytes: each scan's
/// reader parses the file's XML section (up to 50 MiB, the `e57` crate's limit) before its
/// points, so a file of many scans or a large section (a hostile one: thousands of empty scans,
/// or a section padded out) is decoded one scan after another instead. A scan's share of the
/// section is a few kilobytes: files of a few dozen scans, a scan per scanner position as
/// scanning teams hand them over, stay well within it.
const MOST_XML_PARSED_AGAIN: u64 = 16 << 20;

/// Whether `bytes` begin as an E57 file does.
pub fn recognises(bytes: &[u8]) -> bool {
    bytes.starts_with(SIGNATURE)
}

/// The cloud in `bytes` (see the module docs); `Ok(None)` when `keep_going` stopped it.
pub fn parse(bytes: Vec<u8>, keep_going: impl FnMut(f64) -> bool) -> Result<Option<Soup>, String> {
    parse_keeping(bytes, RAW_POINTS_KEPT, keep_going)
}

/// [`parse`], keeping at most `most` points.
fn parse_keeping(bytes: Vec<u8>, most: u64, keep_going: impl FnMut(f64) -> bool) -> Result<Option<Soup>, String> {
    // The header's physical length (bytes 16–24): a file shorter than it was cut short, which
    // the reader reports only as pages it cannot check.
    if let Some(stated) = le_fields::u64_at(&bytes, 16)
        && stated > bytes.len() as u64
    {
        return Err(format!(
            "{CUT_SHORT}: its header counts {stated} bytes, the file has {}",
            bytes.len()
        ));
    }
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| decode(&bytes, most, keep_going, true)))
        .map_err(|_| "the E57 reader failed on damaged data".to_owned())?
}

/// The points of every scan in `bytes`, as [`parse_keeping`] returns them. With `in_parallel`,
/// a file of several scans (their readers' XML within [`MOST_XML_PARSED_AGAIN`]) has them
/// decoded on several threads, as many scans at a time as
/// there are threads (each thread its own reader of the same bytes), and put together in the
/// file's order: the same points as one after another. A single scan is decoded on the
/// caller's thread, which then reports its progress within it.
fn decode(
    bytes: &[u8],
    most: u64,
    mut keep_going: impl FnMut(f64) -> bool,
    in_parallel: bool,
) -> Result<Option<Soup>, String> {
    let open = || E57Reader::new(Cursor::new(bytes)).map_err(|e| e.to_string());
    let mut reader = open()?;
    let scans = reader.pointclouds();
    let total: u64 = scans.iter().map(|pc| pc.records).fold(0, u64::saturating_add);
    let stride = total.div_ceil(most.max(1)).max(1);
    let coloured = scans.iter().all(|pc| pc.has_color());
    // Each scan's first point's index among all the file's points: the stride counts across
    // scans.
    let firsts: Vec<u64> = scans
        .iter()
        .scan(0u64, |next, pc| {
            let first = *next;
            *next = next.saturating_add(pc.records);
            Some(first)
        })
        .collect();
    let mut kept = ScanPoints::default();
    let mut read = 0u64;
    let share = |read: u64| read as f64 / total.max(1) as f64;
    // The XML section's length (header bytes 32–40).
    let xml_bytes = le_fields::u64_at(bytes, 32).unwrap_or(u64::MAX);
    let xml_again = xml_bytes.saturating_mul(scans.len() as u64);
    if in_parallel && scans.len() > 1 && xml_again <= MOST_XML_PARSED_AGAIN {
        let order: Vec<usize> = (0..scans.len()).collect();
        for window in order.chunks(rayon::current_num_threads().max(1)) {
            let parts = crate::parallel::map(window, |&k| {
                let mut reader = open()?;
                read_scan(&mut reader, &scans[k], firsts[k], stride, coloured, &mut |_| true)
            });
            for part in parts {
                let Some((points, count)) = part? else {
                    return Ok(None);
                };
                kept.append(points);
                read += count;
            }
            if !keep_going(share(read)) {
                return Ok(None);
            }
        }
    } else {
        for (pc, &first) in scans.iter().zip(&firsts) {
            let Some((points, count)) = read_scan(&mut reader, pc, first, stride, coloured, &mut |at| {
                keep_going(share(at))
            })?
            else {
                return Ok(None);
            };
            kept.append(points);
            read += count;
        }
    }
    if kept.positions.is_empty() {
        return Err(if read == 0 {
            "no points".to_owned()
        } else {
            "no point has a valid position".to_owned()
        });
    }
    Ok(Some(kept.into_soup()))
}

/// The points of scan `pc` kept at `stride` (the scan's first point is the file's point `first`)
/// and the number read; `keep_going` is told the index of the file's point reached every
/// [`POINTS_PER_STEP`] points, and `None` is returned where it says stop.
fn read_scan(
    reader: &mut E57Reader<Cursor<&[u8]>>,
    pc: &e57::PointCloud,
    first: u64,
    stride: u64,
    coloured: bool,
    keep_going: &mut dyn FnMut(u64) -> bool,
) -> Result<Option<(ScanPoints, u64)>, String> {
    let mut kept = ScanPoints::default();
    let mut points = reader.pointcloud_simple(pc).map_err(|e| e.to_string())?;
    // The intensity stays an intensity (`scan_points` makes it grey where there is no colour);
    // the reader's default would make it a colour.
    points.intensity_to_color(false);
    let mut at = first;
    for point in points {
        let point = point.map_err(|e| e.to_string())?;
        let this = at;
        at += 1;
        if this % POINTS_PER_STEP == POINTS_PER_STEP - 1 && !keep_going(at) {
            return Ok(None);
        }
        let CartesianCoordinate::Valid { x, y, z } = point.cartesian else {
            continue;
        };
        if !this.is_multiple_of(stride) {
            continue;
        }
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return Err(format!("point {this} lies at ({x}, {y}, {z}): not a position"));
        }
        kept.positions.push([x, y, z]);
        if coloured {
            let c = point.color.map_or([0.0; 3], |c| [c.red, c.green, c.blue]);
            kept.colours
                .push(c.map(|v| if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 }));
        }
        kept.intensities
            .push(point.intensity.filter(|i| i.is_finite()).unwrap_or(0.0).max(0.0));
    }
    Ok(Some((kept, at - first)))
}

#[cfg(test)]
mod tests {
    use e57::{E57Writer, Quaternion, Record, RecordDataType, RecordName, RecordValue, Transform, Translation};

    use super::*;

    /// A scan of `points` (x, y, z in metres, intensity 0–1, colour 0–255 or none) in an E57 file
    /// written by the crate's writer, its pose a translation by `at`.
    struct Scan {
        at: [f64; 3],
        points: Vec<([f64; 3], f32, Option<[u8; 3]>)>,
    }

    fn e57_bytes(scans: &[Scan]) -> Vec<u8> {
        let mut cursor = Cursor::new(Vec::new());
        {
            let mut writer = E57Writer::new(&mut cursor, "file").expect("writer");
            for (k, scan) in scans.iter().enumerate() {
                let double = || RecordDataType::Double { min: None, max: None };
                let mut prototype = vec![
                    Record {
                        name: RecordName::CartesianX,
                        data_type: double(),
                    },
                    Record {
                        name: RecordName::CartesianY,
                        data_type: double(),
                    },
                    Record {
                        name: RecordName::CartesianZ,
                        data_type: double(),
                    },
                    Record {
                        name: RecordName::Intensity,
                        data_type: RecordDataType::Single {
                            min: Some(0.0),
                            max: Some(1.0),
                        },
                    },
                ];
                let coloured = scan.points.iter().all(|p| p.2.is_some());
                if coloured {
                    for name in [RecordName::ColorRed, RecordName::ColorGreen, RecordName::ColorBlue] {
                        prototype.push(Record {
                            name,
                            data_type: RecordDataType::Integer { min: 0, max: 255 },
                        });
                    }
                }
                let mut pc = writer.add_pointcloud(&format!("scan-{k}"), prototype).expect("scan");
                pc.set_transform(Some(Transform {
                    rotation: Quaternion {
                        w: 1.0,
                        x: 0.0,
                        y: 0.0,
                        z: 0.0,
                    },
                    translation: Translation {
                        x: scan.at[0],
                        y: scan.at[1],
                        z: scan.at[2],
                    },
                }));
                for &(p, intensity, colour) in &scan.points {
                    let mut values = vec![
                        RecordValue::Double(p[0]),
                        RecordValue::Double(p[1]),
                        RecordValue::Double(p[2]),
                        RecordValue::Single(intensity),
                    ];
                    if let (true, Some(c)) = (coloured, colour) {
                        values.extend(c.map(|v| RecordValue::Integer(i64::from(v))));
                    }
                    pc.add_point(values).expect("point");
                }
                pc.finalize().expect("scan written");
            }
            writer.finalize().expect("file written");
        }
        cursor.into_inner()
    }

    fn all(bytes: Vec<u8>) -> Result<Soup, String> {
        parse(bytes, |_| true).map(|s| s.expect("not stopped"))
    }

    #[test]
    fn scans_meet_where_their_poses_put_them() {
        // Two scans of one box's corners, each in its scanner's frame 1 km apart: with the poses
        // applied they are 2 m apart, not 1 km.
        let a = Scan {
            at: [500_000.0, 0.0, 0.0],
            points: vec![([0.0, 0.0, 0.0], 0.5, Some([255, 0, 0]))],
        };
        let b = Scan {
            at: [500_002.0, 0.0, 0.0],
            points: vec![([0.0, 0.0, 1.0], 0.5, Some([0, 0, 255]))],
        };
        let soup = all(e57_bytes(&[a, b])).expect("reads");
        assert_eq!(soup.positions.len(), 2);
        let d: Vec<f32> = (0..3).map(|k| soup.positions[1][k] - soup.positions[0][k]).collect();
        assert!(
            (d[0] - 2.0).abs() < 1e-4 && d[1].abs() < 1e-4 && (d[2] - 1.0).abs() < 1e-4,
            "{d:?}"
        );
        let colors = soup.colors.expect("coloured");
        assert_eq!(colors[0], [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(colors[1], [0.0, 0.0, 1.0, 1.0]);
    }

    #[test]
    fn without_colour_the_intensity_shades_the_points() {
        let points = (0..10)
            .map(|i| ([f64::from(i), 0.0, 0.0], 0.1 * i as f32, None))
            .collect();
        let soup = all(e57_bytes(&[Scan { at: [0.0; 3], points }])).expect("reads");
        let colors = soup.colors.expect("greys from the intensity");
        assert!(colors[0][0] < 0.01 && (colors[9][0] - 1.0).abs() < 1e-6, "{colors:?}");
    }

    #[test]
    fn a_large_cloud_is_strided_and_the_work_can_be_stopped() {
        let points = (0..1000)
            .map(|i| ([f64::from(i) * 0.01, 0.0, 0.0], 0.5, None))
            .collect();
        let bytes = e57_bytes(&[Scan { at: [0.0; 3], points }]);
        let strided = parse_keeping(bytes.clone(), 100, |_| true).unwrap().unwrap();
        assert_eq!(strided.positions.len(), 100);
        assert!((strided.positions[1][0] - strided.positions[0][0] - 0.1).abs() < 1e-5);
        // Stopped at the first step (every 65 536 points): a cloud that long is needed.
        let long = (0..70_000)
            .map(|i| ([f64::from(i) * 0.001, 0.0, 0.0], 0.5, None))
            .collect();
        assert!(
            parse(
                e57_bytes(&[Scan {
                    at: [0.0; 3],
                    points: long
                }]),
                |_| false
            )
            .unwrap()
            .is_none()
        );
    }

    #[test]
    fn spherical_points_become_cartesian_and_points_without_a_return_are_left_out() {
        let mut cursor = Cursor::new(Vec::new());
        {
            let mut writer = E57Writer::new(&mut cursor, "file").expect("writer");
            let double = || RecordDataType::Double { min: None, max: None };
            let prototype = vec![
                Record {
                    name: RecordName::SphericalRange,
                    data_type: double(),
                },
                Record {
                    name: RecordName::SphericalAzimuth,
                    data_type: double(),
                },
                Record {
                    name: RecordName::SphericalElevation,
                    data_type: double(),
                },
                Record {
                    name: RecordName::SphericalInvalidState,
                    data_type: RecordDataType::Integer { min: 0, max: 2 },
                },
            ];
            let mut pc = writer.add_pointcloud("scan", prototype).expect("scan");
            let quarter = std::f64::consts::FRAC_PI_2;
            // 2 m ahead (+x), 3 m to the left (+y, azimuth a quarter turn), 1 m straight up, and
            // a direction without a range (no return: state 1).
            for (range, azimuth, elevation, state) in [
                (2.0, 0.0, 0.0, 0),
                (3.0, quarter, 0.0, 0),
                (1.0, 0.0, quarter, 0),
                (0.0, 1.0, 0.0, 1),
            ] {
                pc.add_point(vec![
                    RecordValue::Double(range),
                    RecordValue::Double(azimuth),
                    RecordValue::Double(elevation),
                    RecordValue::Integer(state),
                ])
                .expect("point");
            }
            pc.finalize().expect("scan written");
            writer.finalize().expect("file written");
        }
        let soup = all(cursor.into_inner()).expect("reads");
        assert_eq!(soup.positions.len(), 3, "the point without a return is left out");
        // About the bounds' centre (1, 1.5, 0.5) of (2,0,0), (0,3,0), (0,0,1).
        let expected = [[1.0, -1.5, -0.5], [-1.0, 1.5, -0.5], [-1.0, -1.5, 0.5]];
        for (p, e) in soup.positions.iter().zip(expected) {
            assert!((0..3).all(|k| (p[k] - e[k]).abs() < 1e-5), "{p:?} against {e:?}");
        }
    }

    #[test]
    fn several_scans_decoded_together_are_the_same_points_in_order() {
        // Five scans of different lengths (one of a single point), coloured, each posed apart;
        // kept at a stride that runs across the scans' boundaries.
        let scans: Vec<Scan> = [7usize, 1, 40, 13, 25]
            .iter()
            .enumerate()
            .map(|(k, &n)| Scan {
                at: [k as f64 * 3.0, 0.0, 0.0],
                points: (0..n)
                    .map(|i| {
                        let c = ((k * 50 + i) % 256) as u8;
                        ([i as f64 * 0.01, k as f64, 0.5], 0.5, Some([c, 255 - c, 7]))
                    })
                    .collect(),
            })
            .collect();
        let bytes = e57_bytes(&scans);
        // Within the XML parsed again: the scans are decoded in parallel.
        let xml = le_fields::u64_at(&bytes, 32).expect("a header");
        assert!(xml * 5 <= MOST_XML_PARSED_AGAIN, "{xml} bytes of XML");
        for most in [u64::MAX, 20] {
            let together = decode(&bytes, most, |_| true, true).unwrap().unwrap();
            let in_turn = decode(&bytes, most, |_| true, false).unwrap().unwrap();
            assert_eq!(together.positions, in_turn.positions, "at most {most}");
            assert_eq!(together.colors, in_turn.colors, "at most {most}");
            let expected = if most == 20 { 86usize.div_ceil(5) } else { 86 };
            assert_eq!(together.positions.len(), expected, "at most {most}");
        }
        // Stopped after the first window of scans.
        assert!(decode(&bytes, u64::MAX, |_| false, true).unwrap().is_none());
    }

    /// Milliseconds to decode a file of eight scans of 250 000 points each, on every core against
    /// one scan after another, alternating five times (`benchmarks/scans.md`):
    /// `cargo test --release -p phantogram-assets --lib e57::tests::time_several_scans -- --ignored --nocapture`.
    #[test]
    #[ignore = "a timing, run by hand"]
    fn time_several_scans() {
        let scans: Vec<Scan> = (0..8)
            .map(|k| Scan {
                at: [k as f64, 0.0, 0.0],
                points: (0..250_000)
                    .map(|i| {
                        let t = i as f64 * 1e-5;
                        ([t.sin(), t.cos(), t], 0.5, Some([(i % 256) as u8, 40, 90]))
                    })
                    .collect(),
            })
            .collect();
        let bytes = e57_bytes(&scans);
        let (mut together, mut in_turn) = (Vec::new(), Vec::new());
        for _ in 0..5 {
            for (parallel, times) in [(true, &mut together), (false, &mut in_turn)] {
                let start = std::time::Instant::now();
                let soup = decode(&bytes, RAW_POINTS_KEPT, |_| true, parallel).unwrap().unwrap();
                times.push(start.elapsed().as_secs_f64() * 1e3);
                assert!(!soup.positions.is_empty());
            }
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let (t, s) = (median(&mut together), median(&mut in_turn));
        println!(
            "8 scans × 250 000 points, {} MiB, {} threads: together {t:.0} ms, one after another {s:.0} ms ({:.2}×)",
            bytes.len() >> 20,
            rayon::current_num_threads(),
            s / t
        );
    }

    #[test]
    fn damaged_files_are_errors() {
        let points = (0..100)
            .map(|i| ([f64::from(i), 0.0, 0.0], 0.5, Some([1, 2, 3])))
            .collect();
        let good = e57_bytes(&[Scan { at: [0.0; 3], points }]);
        assert!(all(good.clone()).is_ok());
        assert!(all(good[..good.len() / 2].to_vec()).is_err(), "cut short");
        let mut flipped = good.clone();
        let mid = flipped.len() / 3;
        flipped[mid] ^= 0xff;
        assert!(all(flipped).is_err(), "a page's checksum no longer matches");
        assert!(all(e57_bytes(&[])).is_err(), "no scans");
        assert!(recognises(&good) && !recognises(b"LASF"));
    }
}
