# Writes epsg_units.rs beside this script: every EPSG projected and vertical coordinate system
# (codes 1024-32766, the range GeoTIFF keys hold) whose axes are not in metres, with its unit's
# length in metres, from the EPSG database as PROJ holds it. Run in a throwaway virtual
# environment (never a dependency of the project):
#   python3 -m venv /tmp/v && /tmp/v/bin/pip install pyproj==3.7.2
#   /tmp/v/bin/python core/assets/src/model/epsg_units.py
import json, os, pyproj
from pyproj.database import query_crs_info
from pyproj.enums import PJType

rows, units = [], {}
for pj in (PJType.PROJECTED_CRS, PJType.VERTICAL_CRS):
    for info in query_crs_info(auth_name="EPSG", pj_types=[pj]):
        code = int(info.code)
        if not 1024 <= code <= 32766:
            continue
        axes = pyproj.CRS.from_epsg(code).axis_info
        factors = {(a.unit_name, a.unit_conversion_factor) for a in axes}
        # One length unit for every axis; metres need no entry.
        if len(factors) != 1:
            continue
        name, factor = factors.pop()
        if factor == 1.0 or name in ("degree", "radian"):
            continue
        units.setdefault((name, factor), len(units))
        rows.append((code, units[(name, factor)]))
rows.sort()
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "epsg_units.rs")
with open(out, "w") as f:
    f.write("//! The EPSG projected and vertical coordinate systems (codes 1024–32766, as GeoTIFF keys name\n")
    f.write("//! them) whose axes are not in metres, with their unit, so that a LAS naming its system only\n")
    f.write("//! by its code is read in metres (`las_crs`). Written by `epsg_units.py` from the EPSG database\n")
    f.write(f"//! as PROJ {pyproj.proj_version_str} holds it (pyproj {pyproj.__version__}); not edited by hand.\n")
    f.write(f"//! {len(rows)} systems in {len(units)} units.\n//!\n//! **Panics**: none.\n\n")
    f.write("/// Each unit's length in metres, with its name.\n#[rustfmt::skip]\n")
    f.write(f"const UNITS: [(f64, &str); {len(units)}] = [\n")
    for (name, factor), _ in sorted(units.items(), key=lambda kv: kv[1]):
        f.write(f"    ({factor!r}, {json.dumps(name)}),\n")
    f.write("];\n\n/// Each system's code and the index of its unit in `UNITS`, by code.\n#[rustfmt::skip]\n")
    f.write(f"const SYSTEMS: [(u16, u8); {len(rows)}] = [\n")
    for i in range(0, len(rows), 8):
        f.write("    " + " ".join(f"({c}, {u})," for c, u in rows[i:i + 8]) + "\n")
    f.write("];\n\n")
    f.write("/// Metres per unit of the EPSG projected or vertical system `code`, where it is not metres;\n")
    f.write("/// `None` for metres and for codes that are neither (or unknown).\n")
    f.write("pub fn metres_per_unit(code: u16) -> Option<f64> {\n")
    f.write("    let at = SYSTEMS.binary_search_by_key(&code, |&(c, _)| c).ok()?;\n")
    f.write("    UNITS.get(usize::from(SYSTEMS[at].1)).map(|&(metres, _)| metres)\n}\n")
print(out, len(rows), len(units))
