//! The length units of a LAS file's coordinate system, so that a scan in feet or in degrees comes
//! out in metres. LAS coordinates are in whatever units the file's coordinate reference system
//! (CRS) uses: US state-plane systems are in feet (US survey or international), geographic ones in
//! degrees of longitude and latitude, with heights in their own unit.
//!
//! * **Where the units are read**: the CRS record as OGC WKT (record 2112, which LAS 1.4 asks
//!   for; WKT1, ESRI's variant or WKT2, parsed by `wkt`), else its GeoTIFF keys (records
//!   34735–34737): the model type (projected, geographic, geocentric; WKT also names local,
//!   engineering systems: a scanner's or a site's own frame) and the linear, angular and
//!   vertical unit keys. A unit is taken from the text's own factor (WKT) or from the EPSG unit
//!   codes in [`linear_unit_m`] and [`angular_unit_rad`] (GeoTIFF); a projected or vertical
//!   system named only by its EPSG code, with no unit key, has its unit from `epsg_units` (the
//!   990 EPSG systems not in metres, 13 kB of source, rather than the EPSG database's megabytes
//!   on a phone). An unknown unit code or a record that does not parse is read as metres, as
//!   before: the artifact is fitted to the diorama, so only its true size is off.
//! * **Heights**: in the vertical system's unit where the file names one; else, for a projected
//!   system, in its linear unit (files in state-plane feet have their heights in feet), and for a
//!   geographic one, in metres.
//! * **Degrees**: longitude and latitude become metres east and north of the cloud's centre
//!   (a local tangent plane on the WGS 84 ellipsoid: the radii of curvature at the centre's
//!   latitude). Over a scan's extent (well under a kilometre) that is exact to far below a
//!   millimetre; over tens of kilometres it bends. Points that cannot be degrees (a latitude
//!   beyond ±90°) mean the record is wrong: they are read as metres.
//!
//! **Panics**: none (the record is the file's; every read is checked).

use las::crs::{GeoTiffCrs, GeoTiffData};

use super::epsg_units;
use super::wkt::{self, Node};

/// How a LAS file's horizontal coordinates become metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Horizontal {
    /// Metres per unit of x and y (a projected or geocentric system).
    Linear(f64),
    /// Radians per unit of x (longitude) and y (latitude) (a geographic system).
    Angular(f64),
}

/// See the module docs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Units {
    pub horizontal: Horizontal,
    /// Metres per unit of z.
    pub vertical_m: f64,
}

impl Units {
    /// Coordinates already in metres: a file without a coordinate system, or one whose units
    /// could not be told.
    pub const METRES: Units = Units {
        horizontal: Horizontal::Linear(1.0),
        vertical_m: 1.0,
    };

    /// The units `header`'s CRS records name (see the module docs).
    pub fn of(header: &las::Header) -> Units {
        header
            .get_wkt_crs_bytes()
            .and_then(|bytes| from_wkt(&String::from_utf8_lossy(bytes)))
            .or_else(|| {
                header
                    .get_geotiff_crs()
                    .ok()
                    .flatten()
                    .and_then(|keys| from_geotiff(&keys))
            })
            .unwrap_or(Units::METRES)
    }

    /// `positions` (x, y, z in the file's units, after its scale and offset) in metres, x east
    /// and y north; degrees about the centre of their bounds (see the module docs).
    pub fn to_metres(self, positions: &mut [[f64; 3]]) {
        let horizontal = match self.horizontal {
            Horizontal::Linear(m) => m,
            Horizontal::Angular(rad) => match local_metres_per_unit(positions, rad) {
                Some(([east_m, north_m], [lon0, lat0])) => {
                    for p in positions.iter_mut() {
                        *p = [(p[0] - lon0) * east_m, (p[1] - lat0) * north_m, p[2] * self.vertical_m];
                    }
                    return;
                }
                // Not degrees after all: read as metres.
                None => return,
            },
        };
        for p in positions.iter_mut() {
            *p = [p[0] * horizontal, p[1] * horizontal, p[2] * self.vertical_m];
        }
    }
}

/// WGS 84's semi-major axis and first eccentricity squared.
const WGS84_A_M: f64 = 6_378_137.0;
const WGS84_E2: f64 = 6.694_379_990_14e-3;

/// Metres per unit of longitude and of latitude at the centre of `positions`' bounds, and that
/// centre (longitudes across the antimeridian taken on to 360°, which `positions` are changed
/// to); `None` where a latitude lies beyond ±90° or a longitude beyond ±540°.
fn local_metres_per_unit(positions: &mut [[f64; 3]], rad_per_unit: f64) -> Option<([f64; 2], [f64; 2])> {
    let half_turn = std::f64::consts::PI / rad_per_unit;
    let in_range = |p: &[f64; 3]| p[1].abs() <= half_turn / 2.0 && p[0].abs() <= half_turn * 3.0;
    if positions.is_empty() || !positions.iter().all(in_range) {
        return None;
    }
    let bounds = |k: usize, positions: &[[f64; 3]]| {
        positions
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[k]), hi.max(p[k]))
            })
    };
    // A cloud spanning more than half the globe in longitude is one across the antimeridian.
    let (west, east) = bounds(0, positions);
    if east - west > half_turn {
        for p in positions.iter_mut() {
            if p[0] < 0.0 {
                p[0] += 2.0 * half_turn;
            }
        }
    }
    let ((west, east), (south, north)) = (bounds(0, positions), bounds(1, positions));
    let centre = [(west + east) / 2.0, (south + north) / 2.0];
    let latitude = centre[1] * rad_per_unit;
    let w = 1.0 - WGS84_E2 * latitude.sin().powi(2);
    // Radii of curvature in the prime vertical and in the meridian.
    let prime_vertical_m = WGS84_A_M / w.sqrt();
    let meridian_m = WGS84_A_M * (1.0 - WGS84_E2) / (w * w.sqrt());
    Some((
        [
            prime_vertical_m * latitude.cos() * rad_per_unit,
            meridian_m * rad_per_unit,
        ],
        centre,
    ))
}

/// The units a WKT coordinate system names; `None` where it does not parse or names no
/// horizontal system.
pub fn from_wkt(text: &str) -> Option<Units> {
    let root = wkt::parse(text.trim_matches(|c: char| c == '\0' || c.is_whitespace()))?;
    let mut parts = Parts::default();
    parts.read(&root, 0);
    let horizontal = parts.horizontal?;
    Some(Units {
        horizontal,
        vertical_m: parts.vertical_m.unwrap_or(match horizontal {
            Horizontal::Linear(m) => m,
            Horizontal::Angular(_) => 1.0,
        }),
    })
}

/// The horizontal and vertical units found in a WKT tree so far.
#[derive(Default)]
struct Parts {
    horizontal: Option<Horizontal>,
    vertical_m: Option<f64>,
}

impl Parts {
    /// Takes what `node` (a coordinate system) names, where not already found. `depth` bounds
    /// the compound and bound systems followed (each a level of the already bounded tree).
    fn read(&mut self, node: &Node, depth: usize) {
        if depth > wkt::MAX_DEPTH {
            return;
        }
        if node.is(&["COMPD_CS", "COMPOUNDCRS"]) {
            for part in node.children() {
                self.read(part, depth + 1);
            }
        } else if node.is(&["BOUNDCRS"]) {
            if let Some(source) = node.child(&["SOURCECRS"]).and_then(|s| s.children().next()) {
                self.read(source, depth + 1);
            }
        } else if node.is(&[
            "PROJCS",
            "PROJCRS",
            "PROJECTEDCRS",
            "GEOCCS",
            // A local (engineering) system: a scanner's or a site's own frame.
            "LOCAL_CS",
            "ENGCRS",
            "ENGINEERINGCRS",
        ]) {
            self.horizontal
                .get_or_insert(Horizontal::Linear(unit_of(node, LINEAR).unwrap_or(1.0)));
        } else if node.is(&["GEOGCS", "GEOGCRS", "GEOGRAPHICCRS", "GEODCRS", "GEODETICCRS"]) {
            let cartesian = node
                .child(&["CS"])
                .and_then(Node::first_word)
                .is_some_and(|w| w.eq_ignore_ascii_case("Cartesian"));
            if cartesian {
                self.horizontal
                    .get_or_insert(Horizontal::Linear(unit_of(node, LINEAR).unwrap_or(1.0)));
            } else {
                self.horizontal
                    .get_or_insert(Horizontal::Angular(unit_of(node, ANGULAR).unwrap_or(DEGREE_RAD)));
                // A 3D geographic system's height axis.
                if let Some(height_m) = unit_of(node, &["LENGTHUNIT"]) {
                    self.vertical_m.get_or_insert(height_m);
                }
            }
        } else if node.is(&["VERT_CS", "VERTCS", "VERTCRS", "VERTICALCRS"]) {
            self.vertical_m.get_or_insert(unit_of(node, LINEAR).unwrap_or(1.0));
        }
    }
}

const LINEAR: &[&str] = &["UNIT", "LENGTHUNIT"];
const ANGULAR: &[&str] = &["UNIT", "ANGLEUNIT"];
const DEGREE_RAD: f64 = std::f64::consts::PI / 180.0;

/// The factor of a system's own unit: a unit node among its children (WKT1, and WKT2 where all
/// axes share one), else its first axis's; not those of its base system or its projection's
/// parameters, which are nodes further down.
fn unit_of(system: &Node, keywords: &[&str]) -> Option<f64> {
    let factor = |node: &Node| {
        node.child(keywords)
            .and_then(Node::first_number)
            .filter(|f| plausible(*f))
    };
    factor(system).or_else(|| system.children().filter(|n| n.is(&["AXIS"])).find_map(factor))
}

/// A unit's factor that can be one: finite and within nine orders of magnitude of the SI unit.
fn plausible(factor: f64) -> bool {
    (1e-9..=1e9).contains(&factor)
}

/// GeoTIFF keys: the model type, and the unit keys with their user-defined sizes.
const GT_MODEL_TYPE: u16 = 1024;
const GEOG_LINEAR_UNITS: u16 = 2052;
const GEOG_LINEAR_UNIT_SIZE: u16 = 2053;
const GEOG_ANGULAR_UNITS: u16 = 2054;
const GEOG_ANGULAR_UNIT_SIZE: u16 = 2055;
const PROJECTED_CRS: u16 = 3072;
const PROJ_LINEAR_UNITS: u16 = 3076;
const PROJ_LINEAR_UNIT_SIZE: u16 = 3077;
const VERTICAL_CRS: u16 = 4096;
const VERTICAL_UNITS: u16 = 4099;
/// GeoTIFF's code for "user-defined": the size key then gives the unit.
const USER_DEFINED: u16 = 32767;

/// The units GeoTIFF keys name; `None` where they name no model type and no linear unit.
pub fn from_geotiff(keys: &GeoTiffCrs) -> Option<Units> {
    let short = |id: u16| {
        keys.entries.iter().find(|e| e.id == id).and_then(|e| match e.data {
            GeoTiffData::U16(v) => Some(v),
            _ => None,
        })
    };
    let double = |id: u16| {
        keys.entries.iter().find(|e| e.id == id).and_then(|e| match &e.data {
            GeoTiffData::Doubles(v) => v.first().copied().filter(|f| plausible(*f)),
            _ => None,
        })
    };
    let linear = |units: u16, size: u16| {
        short(units).and_then(|code| match code {
            USER_DEFINED => double(size),
            code => linear_unit_m(code),
        })
    };
    // A system named by its EPSG code alone: its unit from the EPSG table (`epsg_units`).
    let by_code = |id: u16| short(id).and_then(epsg_units::metres_per_unit);
    let vertical = linear(VERTICAL_UNITS, 0).or_else(|| by_code(VERTICAL_CRS));
    match short(GT_MODEL_TYPE) {
        Some(2) => {
            let angle = short(GEOG_ANGULAR_UNITS).and_then(|code| match code {
                USER_DEFINED => double(GEOG_ANGULAR_UNIT_SIZE),
                code => angular_unit_rad(code),
            });
            Some(Units {
                horizontal: Horizontal::Angular(angle.unwrap_or(DEGREE_RAD)),
                vertical_m: vertical.unwrap_or(1.0),
            })
        }
        Some(3) => {
            let m = linear(GEOG_LINEAR_UNITS, GEOG_LINEAR_UNIT_SIZE).unwrap_or(1.0);
            Some(Units {
                horizontal: Horizontal::Linear(m),
                vertical_m: m,
            })
        }
        model => {
            let m = linear(PROJ_LINEAR_UNITS, PROJ_LINEAR_UNIT_SIZE).or_else(|| by_code(PROJECTED_CRS));
            (model == Some(1) || m.is_some()).then(|| {
                let m = m.unwrap_or(1.0);
                Units {
                    horizontal: Horizontal::Linear(m),
                    vertical_m: vertical.unwrap_or(m),
                }
            })
        }
    }
}

/// Metres in the EPSG length unit `code`: those that GeoTIFF 1.0's own table and EPSG agree on
/// (9001–9003, 9005, 9014) and EPSG's others that GeoTIFF 1.0 did not define (9030 on); GeoTIFF
/// 1.0 gave some codes in 9004–9015 other meanings than EPSG does, so those are not guessed.
pub fn linear_unit_m(code: u16) -> Option<f64> {
    Some(match code {
        9001 => 1.0,             // metre
        9002 => 0.3048,          // international foot
        9003 => 1200.0 / 3937.0, // US survey foot
        9005 => 0.304_797_265_4, // Clarke's foot
        9014 => 1.8288,          // fathom
        9030 => 1852.0,          // nautical mile
        9036 => 1000.0,          // kilometre
        9093 => 1609.344,        // statute mile
        9096 => 0.9144,          // yard
        _ => return None,
    })
}

/// Radians in the EPSG angle unit `code`.
pub fn angular_unit_rad(code: u16) -> Option<f64> {
    Some(match code {
        9101 => 1.0,                          // radian
        9102 | 9122 => DEGREE_RAD,            // degree
        9105 => std::f64::consts::PI / 200.0, // grad
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use las::crs::GeoTiffKeyEntry;

    use super::*;

    const US_SURVEY_FOOT_M: f64 = 1200.0 / 3937.0;

    fn linear(units: Option<Units>) -> (f64, f64) {
        match units {
            Some(Units {
                horizontal: Horizontal::Linear(m),
                vertical_m,
            }) => (m, vertical_m),
            other => panic!("{other:?}"),
        }
    }

    fn close(a: (f64, f64), b: (f64, f64)) -> bool {
        (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12
    }

    /// The projected system of las-rs's `autzen.las` (liblas's WKT1), cut after its unit.
    const OREGON_LAMBERT_FT: &str = "PROJCS[\"NAD83(HARN) / Oregon Lambert (ft)\",GEOGCS[\"NAD83(HARN)\",DATUM[\"NAD83_High_Accuracy_Regional_Network\",SPHEROID[\"GRS 1980\",6378137,298.257222101,AUTHORITY[\"EPSG\",\"7019\"]],TOWGS84[0,0,0,0,0,0,0],AUTHORITY[\"EPSG\",\"6152\"]],PRIMEM[\"Greenwich\",0,AUTHORITY[\"EPSG\",\"8901\"]],UNIT[\"degree\",0.0174532925199433,AUTHORITY[\"EPSG\",\"9122\"]],AUTHORITY[\"EPSG\",\"4152\"]],UNIT[\"foot\",0.3048,AUTHORITY[\"EPSG\",\"9002\"]],PROJECTION[\"Lambert_Conformal_Conic_2SP\"],PARAMETER[\"standard_parallel_1\",43],PARAMETER[\"false_easting\",1312335.958]]";

    #[test]
    fn wkt1_projected_in_feet_has_its_heights_in_feet() {
        assert!(close(linear(from_wkt(OREGON_LAMBERT_FT)), (0.3048, 0.3048)));
        // Padded with NULs, as records are.
        assert!(close(
            linear(from_wkt(&format!("{OREGON_LAMBERT_FT}\0\0\0"))),
            (0.3048, 0.3048)
        ));
    }

    #[test]
    fn wkt1_compound_takes_the_vertical_systems_unit() {
        let compound = format!(
            "COMPD_CS[\"NAD83 / Oregon GIC Lambert (ft) + NAVD88 height (ftUS)\",{OREGON_LAMBERT_FT},VERT_CS[\"NAVD88 height (ftUS)\",VERT_DATUM[\"North American Vertical Datum 1988\",2005,AUTHORITY[\"EPSG\",\"5103\"]],UNIT[\"US survey foot\",0.304800609601219,AUTHORITY[\"EPSG\",\"9003\"]],AXIS[\"Gravity-related height\",UP],AUTHORITY[\"EPSG\",\"6360\"]]]"
        );
        assert!(close(linear(from_wkt(&compound)), (0.3048, 0.304800609601219)));
    }

    #[test]
    fn esri_wkt_in_us_feet() {
        let esri = "PROJCS[\"NAD_1983_StatePlane_California_VI_FIPS_0406_Feet\",GEOGCS[\"GCS_North_American_1983\",DATUM[\"D_North_American_1983\",SPHEROID[\"GRS_1980\",6378137.0,298.257222101]],PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]],PROJECTION[\"Lambert_Conformal_Conic\"],PARAMETER[\"False_Easting\",6561666.666666666],UNIT[\"Foot_US\",0.3048006096012192]]";
        assert!(close(linear(from_wkt(esri)), (0.3048006096012192, 0.3048006096012192)));
        // ESRI names a vertical system VERTCS; in a compound system, its unit is the heights'.
        let esri_vertical = format!(
            "COMPD_CS[\"x\",{esri},VERTCS[\"NAVD_1988\",VDATUM[\"North_American_Vertical_Datum_1988\"],PARAMETER[\"Vertical_Shift\",0.0],PARAMETER[\"Direction\",1.0],UNIT[\"Meter\",1.0]]]"
        );
        assert!(close(linear(from_wkt(&esri_vertical)), (0.3048006096012192, 1.0)));
    }

    #[test]
    fn wkt2_takes_the_axes_unit_not_the_projections_parameters() {
        let projected = "PROJCRS[\"NAD83 / Oregon GIC Lambert (ft)\",BASEGEOGCRS[\"NAD83\",DATUM[\"North American Datum 1983\",ELLIPSOID[\"GRS 1980\",6378137,298.257222101,LENGTHUNIT[\"metre\",1]]],PRIMEM[\"Greenwich\",0,ANGLEUNIT[\"degree\",0.0174532925199433]]],CONVERSION[\"Oregon GIC Lambert (ft)\",METHOD[\"Lambert Conic Conformal (2SP)\"],PARAMETER[\"False easting\",400000,LENGTHUNIT[\"metre\",1]]],CS[Cartesian,2],AXIS[\"easting (X)\",east,ORDER[1],LENGTHUNIT[\"foot\",0.3048]],AXIS[\"northing (Y)\",north,ORDER[2],LENGTHUNIT[\"foot\",0.3048]],ID[\"EPSG\",2992]]";
        assert!(close(linear(from_wkt(projected)), (0.3048, 0.3048)));
        // One unit after the axes, for all of them.
        let shared = "PROJCRS[\"x\",BASEGEOGCRS[\"y\",ELLIPSOID[\"GRS 1980\",6378137,298.257222101,LENGTHUNIT[\"metre\",1]]],CONVERSION[\"z\",PARAMETER[\"False easting\",0,LENGTHUNIT[\"metre\",1]]],CS[Cartesian,2],AXIS[\"(E)\",east],AXIS[\"(N)\",north],LENGTHUNIT[\"US survey foot\",0.304800609601219]]";
        assert!(close(linear(from_wkt(shared)), (0.304800609601219, 0.304800609601219)));
        // Wrapped in a bound system: its source.
        let bound =
            format!("BOUNDCRS[SOURCECRS[{shared}],TARGETCRS[GEOGCRS[\"WGS 84\"]],ABRIDGEDTRANSFORMATION[\"t\"]]");
        assert!(close(linear(from_wkt(&bound)), (0.304800609601219, 0.304800609601219)));
    }

    #[test]
    fn geographic_systems_are_in_degrees_with_heights_in_metres() {
        let wgs84 = "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]";
        assert_eq!(
            from_wkt(wgs84),
            Some(Units {
                horizontal: Horizontal::Angular(0.0174532925199433),
                vertical_m: 1.0
            })
        );
        let compound = "COMPOUNDCRS[\"WGS 84 + EGM96 height\",GEOGCRS[\"WGS 84\",CS[ellipsoidal,2],AXIS[\"latitude\",north,ANGLEUNIT[\"degree\",0.0174532925199433]],AXIS[\"longitude\",east,ANGLEUNIT[\"degree\",0.0174532925199433]]],VERTCRS[\"EGM96 height\",CS[vertical,1],AXIS[\"gravity-related height (H)\",up,LENGTHUNIT[\"US survey foot\",0.304800609601219]]]]";
        assert_eq!(
            from_wkt(compound),
            Some(Units {
                horizontal: Horizontal::Angular(0.0174532925199433),
                vertical_m: 0.304800609601219
            })
        );
        // A geocentric system is Cartesian, in its length unit.
        let geocentric = "GEODCRS[\"WGS 84\",CS[Cartesian,3],AXIS[\"(X)\",geocentricX],LENGTHUNIT[\"metre\",1]]";
        assert!(close(linear(from_wkt(geocentric)), (1.0, 1.0)));
    }

    #[test]
    fn what_names_no_unit_is_none_or_metres() {
        assert_eq!(from_wkt("not WKT"), None);
        assert_eq!(from_wkt("VERT_CS[\"h\",UNIT[\"foot\",0.3048]]"), None);
        // A local (engineering) system: in its unit, heights too; metres without one.
        assert!(close(linear(from_wkt("LOCAL_CS[\"x\"]")), (1.0, 1.0)));
        assert!(close(
            linear(from_wkt(
                "LOCAL_CS[\"site grid\",LOCAL_DATUM[\"d\",0],UNIT[\"foot\",0.3048],AXIS[\"X\",EAST]]"
            )),
            (0.3048, 0.3048)
        ));
        assert!(close(
            linear(from_wkt(
                "ENGCRS[\"scanner\",EDATUM[\"s\"],CS[Cartesian,3],AXIS[\"x\",east],LENGTHUNIT[\"millimetre\",0.001]]"
            )),
            (0.001, 0.001)
        ));
        // A projected system without a unit, or with one that cannot be, is in metres.
        assert!(close(linear(from_wkt("PROJCS[\"x\"]")), (1.0, 1.0)));
        assert!(close(
            linear(from_wkt("PROJCS[\"x\",UNIT[\"foot\",-0.3048]]")),
            (1.0, 1.0)
        ));
        assert!(close(
            linear(from_wkt("PROJCS[\"x\",UNIT[\"foot\",1e300]]")),
            (1.0, 1.0)
        ));
    }

    fn keys(entries: &[(u16, GeoTiffData)]) -> GeoTiffCrs {
        GeoTiffCrs {
            entries: entries
                .iter()
                .map(|(id, data)| GeoTiffKeyEntry {
                    id: *id,
                    data: data.clone(),
                })
                .collect(),
        }
    }

    #[test]
    fn geotiff_keys_name_linear_angular_and_vertical_units() {
        use GeoTiffData::{Doubles, U16};
        // autzen.laz's keys: projected, EPSG 2994, international feet, no vertical unit.
        let autzen = keys(&[
            (1024, U16(1)),
            (1025, U16(1)),
            (2054, U16(9102)),
            (3072, U16(2994)),
            (3076, U16(9002)),
        ]);
        assert!(close(linear(from_geotiff(&autzen)), (0.3048, 0.3048)));
        let us_feet_metres_up = keys(&[(1024, U16(1)), (3076, U16(9003)), (4099, U16(9001))]);
        assert!(close(linear(from_geotiff(&us_feet_metres_up)), (US_SURVEY_FOOT_M, 1.0)));
        let user_defined = keys(&[(1024, U16(1)), (3076, U16(32767)), (3077, Doubles(vec![0.25]))]);
        assert!(close(linear(from_geotiff(&user_defined)), (0.25, 0.25)));
        // A projected system named by its code alone: its unit from the EPSG table, heights in
        // it too unless the vertical system's code names another.
        let utm = keys(&[(1024, U16(1)), (3072, U16(25832)), (4096, U16(5941))]);
        assert!(close(linear(from_geotiff(&utm)), (1.0, 1.0)));
        let oregon_ft = keys(&[(1024, U16(1)), (3072, U16(2992))]);
        assert!(close(linear(from_geotiff(&oregon_ft)), (0.3048, 0.3048)));
        let oregon_ft_navd88_ftus = keys(&[(1024, U16(1)), (3072, U16(2992)), (4096, U16(6360))]);
        assert!(close(
            linear(from_geotiff(&oregon_ft_navd88_ftus)),
            (0.3048, US_SURVEY_FOOT_M)
        ));
        // An explicit unit key wins over the code's table.
        let explicit = keys(&[(1024, U16(1)), (3072, U16(2992)), (3076, U16(9001))]);
        assert!(close(linear(from_geotiff(&explicit)), (1.0, 1.0)));
        // A unit code not known: metres.
        let unknown = keys(&[(1024, U16(1)), (3076, U16(9004))]);
        assert!(close(linear(from_geotiff(&unknown)), (1.0, 1.0)));
        let geographic = keys(&[(1024, U16(2)), (2048, U16(4326)), (4099, U16(9003))]);
        assert_eq!(
            from_geotiff(&geographic),
            Some(Units {
                horizontal: Horizontal::Angular(DEGREE_RAD),
                vertical_m: US_SURVEY_FOOT_M
            })
        );
        let grads = keys(&[(1024, U16(2)), (2054, U16(9105))]);
        assert_eq!(
            from_geotiff(&grads).map(|u| u.horizontal),
            Some(Horizontal::Angular(std::f64::consts::PI / 200.0))
        );
        let geocentric = keys(&[(1024, U16(3)), (2052, U16(9036))]);
        assert!(close(linear(from_geotiff(&geocentric)), (1000.0, 1000.0)));
        assert_eq!(from_geotiff(&keys(&[(1025, U16(1))])), None);
    }

    /// The EPSG table (`epsg_units`, generated from PROJ's database) on systems whose units are
    /// in their names: state-plane systems in US survey feet and in international feet, a height
    /// in US survey feet; systems in metres are not in it.
    #[test]
    fn epsg_codes_name_their_units() {
        let in_us_feet =
            |code: u16| epsg_units::metres_per_unit(code).is_some_and(|m| (m - US_SURVEY_FOOT_M).abs() < 1e-12);
        // NAD83 / California zone 3 (ftUS), NAD83 / New York Long Island (ftUS), and the height
        // NAVD88 height (ftUS).
        for code in [2227, 2263, 6360] {
            assert!(in_us_feet(code), "{code}");
        }
        // NAD83(HARN) / Oregon Lambert (ft), NAD83 / Oregon GIC Lambert (ft).
        assert_eq!(epsg_units::metres_per_unit(2994), Some(0.3048));
        assert_eq!(epsg_units::metres_per_unit(2992), Some(0.3048));
        // WGS 84 / UTM zone 10N, WGS 84 / Pseudo-Mercator, OSGB36 / British National Grid,
        // ETRS89 / UTM zone 32N, a geographic system (WGS 84), and no system.
        for code in [32610, 3857, 27700, 25832, 4326, 0, 1] {
            assert_eq!(epsg_units::metres_per_unit(code), None, "{code}");
        }
    }

    #[test]
    fn degrees_become_metres_east_and_north_of_the_centre() {
        // A degree of longitude and of latitude at 45° N on WGS 84, by the series for a degree's
        // length (111 412.84 cos φ − 93.5 cos 3φ + 0.118 cos 5φ; 111 132.92 − 559.82 cos 2φ +
        // 1.175 cos 4φ − 0.0023 cos 6φ): 78 846.81 m and 111 131.75 m.
        let units = Units {
            horizontal: Horizontal::Angular(DEGREE_RAD),
            vertical_m: 1.0,
        };
        let mut points = vec![[10.0, 44.9995, 100.0], [10.001, 45.0005, 101.0]];
        units.to_metres(&mut points);
        let (east, north) = (points[1][0] - points[0][0], points[1][1] - points[0][1]);
        assert!((east - 78.84681).abs() < 1e-4, "{east}");
        assert!((north - 111.13175).abs() < 1e-4, "{north}");
        assert!((points[0][0] + points[1][0]).abs() < 1e-9 && points[1][2] == 101.0);
        // Across the antimeridian: two points 0.002° apart, not 359.998°.
        let mut across = vec![[179.999, 0.0, 0.0], [-179.999, 0.0, 0.0]];
        units.to_metres(&mut across);
        let span = across[1][0] - across[0][0];
        assert!((span - 0.002 * 111_319.49).abs() < 0.01, "{span}");
        // Latitudes that cannot be: the record is wrong, the numbers are read as metres.
        let mut metres = vec![[512_345.0, 5_412_345.0, 200.0]];
        units.to_metres(&mut metres);
        assert_eq!(metres, vec![[512_345.0, 5_412_345.0, 200.0]]);
    }

    #[test]
    fn feet_become_metres_heights_in_their_own_unit() {
        let units = Units {
            horizontal: Horizontal::Linear(0.3048),
            vertical_m: US_SURVEY_FOOT_M,
        };
        let mut points = vec![[1000.0, -2000.0, 3937.0]];
        units.to_metres(&mut points);
        assert!((points[0][0] - 304.8).abs() < 1e-9 && (points[0][1] + 609.6).abs() < 1e-9);
        assert!((points[0][2] - 1200.0).abs() < 1e-9);
    }
}
