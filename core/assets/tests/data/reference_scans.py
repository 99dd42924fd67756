# Scans of a sphere of radius 0.1 m (200 Fibonacci points, +z red) written by other programs'
# writers, so that the loader is checked against files its own crates did not write: E57 by the
# reference library libE57Format (PyPI pye57 0.4.19), LAS 1.4 point format 7 by laspy 2.7.0 and
# its LAZ by the reference LASzip (PyPI laszip 0.3.0). Georeferenced: 512 345.678 m east,
# 5 412 345.678 m north, 200 m up. Run once, 2026-12-06, in a throwaway virtual environment
# (never a dependency of the project):
#   python3 -m venv /tmp/v && /tmp/v/bin/pip install pye57==0.4.19 "laspy[laszip]==2.7.0" pyproj==3.7.2
#   /tmp/v/bin/python reference_scans.py .   # then move the files into las/ and e57/ (--big: below)
# Read by `scans_written_by_other_programs_read_alike` in core/assets/tests/mesh_files.rs. The two
# in feet and in degrees (below, added later the same day with pyproj 3.7.2 / PROJ 9.5.1) are read
# by `scans_in_feet_or_degrees_by_other_programs_read_in_metres`.
import sys, numpy as np, pye57, laspy, pyproj
n = 200
i = np.arange(n) + 0.5
phi = np.arccos(1 - 2 * i / n); theta = np.pi * (1 + 5 ** 0.5) * i
x, y, z = np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)
east, north, up = 512345.678, 5412345.678, 200.0
out = sys.argv[1]
# E57: two scans (top and bottom half), each in its scanner's frame 3 m to a side, posed.
e = pye57.E57(f"{out}/reference-sphere-200.e57", mode="w")
for top in (True, False):
    m = (z > 0) == top
    s = np.array([east + (3 if top else -3), north, up])
    k = int(m.sum())
    e.write_scan_raw({
        "cartesianX": east + 0.1 * x[m] - s[0], "cartesianY": north + 0.1 * y[m] - s[1],
        "cartesianZ": up + 0.1 * z[m] - s[2],
        "colorRed": np.full(k, 200 if top else 40, dtype=np.uint8),
        "colorGreen": np.full(k, 90, dtype=np.uint8), "colorBlue": np.full(k, 60, dtype=np.uint8),
    }, rotation=np.array([1.0, 0, 0, 0]), translation=s)
e.close()
# LAS 1.4, point format 7 (16-bit colour), and the same as LAZ.
h = laspy.LasHeader(point_format=7, version="1.4")
h.offsets = [east, north, up]; h.scales = [0.0001] * 3
las = laspy.LasData(h)
las.x, las.y, las.z = east + 0.1 * x, north + 0.1 * y, up + 0.1 * z
las.red = np.where(z > 0, 200 * 256, 40 * 256).astype(np.uint16)
las.green = np.full(n, 90 * 256, dtype=np.uint16); las.blue = np.full(n, 60 * 256, dtype=np.uint16)
las.classification = np.full(n, 2, dtype=np.uint8)
las.write(f"{out}/reference-sphere-200.las")
las.write(f"{out}/reference-sphere-200.laz", laz_backend=laspy.LazBackend.Laszip)
# The same sphere in other units, each with its coordinate system as PROJ names it. In feet: LAS
# 1.4 format 7 (LAZ) with PROJ's WKT2 of EPSG 2992 + 6360 (Oregon GIC Lambert in international
# feet, NAVD88 heights in US survey feet), its WKT flag set.
ft, us_ft = 0.3048, 1200 / 3937
east_ft, north_ft, up_ft = 1680000.0, 870000.0, 400.0
hf = laspy.LasHeader(point_format=7, version="1.4")
hf.offsets = [east_ft, north_ft, up_ft]; hf.scales = [0.0001] * 3
hf.global_encoding.wkt = True
hf.vlrs.append(laspy.vlrs.known.WktCoordinateSystemVlr(pyproj.CRS("EPSG:2992+6360").to_wkt("WKT2_2019")))
feet = laspy.LasData(hf)
feet.x, feet.y, feet.z = east_ft + 0.1 * x / ft, north_ft + 0.1 * y / ft, up_ft + 0.1 * z / us_ft
feet.red, feet.green, feet.blue = las.red, las.green, las.blue
feet.write(f"{out}/reference-sphere-200-feet.laz", laz_backend=laspy.LazBackend.Laszip)
# In degrees: LAS 1.2 format 3 with GeoTIFF keys (geographic model, EPSG 4326, degrees), the
# points' longitude and latitude from metres east and north of 120.5° W 45° N by PROJ's inverse
# azimuthal equidistant projection on WGS 84 (true distances from that centre).
lon0, lat0 = -120.5, 45.0
local = pyproj.Transformer.from_crs(
    f"+proj=aeqd +lat_0={lat0} +lon_0={lon0} +ellps=WGS84 +units=m", "EPSG:4326", always_xy=True)
lon, lat = local.transform(0.1 * x, 0.1 * y)
hd = laspy.LasHeader(point_format=3, version="1.2")
hd.offsets = [lon0, lat0, up]; hd.scales = [1e-10, 1e-10, 0.0001]
keys = laspy.vlrs.known.GeoKeyDirectoryVlr()
keys.geo_keys_header.key_directory_version, keys.geo_keys_header.key_revision = 1, 1
keys.geo_keys_header.minor_revision, keys.geo_keys_header.number_of_keys = 0, 3
keys.geo_keys = []
for key, value in ((1024, 2), (2048, 4326), (2054, 9102)):
    entry = laspy.vlrs.known.GeoKeyEntryStruct()
    entry.id, entry.tiff_tag_location, entry.count, entry.value_offset = key, 0, 1, value
    keys.geo_keys.append(entry)
hd.vlrs.append(keys)
degrees = laspy.LasData(hd)
degrees.x, degrees.y, degrees.z = lon, lat, up + 0.1 * z
degrees.red, degrees.green, degrees.blue = las.red, las.green, las.blue
degrees.write(f"{out}/reference-sphere-200-degrees.las")
# With `--big` also a 5-million-point LAZ (a bumpy sphere, colour by height; 48 MB, not kept in
# the repository) for timing the loader: `phantogram render --log assets/logs/tilt-sweep.pglog
# --every 20000 --anaglyph mono --out OUT big5m.laz` (the closing note of 2026-12-06).
if "--big" in sys.argv:
    m = 5_000_000
    v = np.random.default_rng(1).normal(size=(m, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    p = v * (0.1 * (1 + 0.05 * np.sin(20 * v[:, 0]) * np.cos(15 * v[:, 1])))[:, None]
    hb = laspy.LasHeader(point_format=7, version="1.4")
    hb.offsets = [500000, 4000000, 100]; hb.scales = [1e-5] * 3
    big = laspy.LasData(hb)
    big.x, big.y, big.z = 500000 + p[:, 0], 4000000 + p[:, 1], 100 + p[:, 2]
    c = ((v[:, 2] + 1) * 0.5 * 65535).astype(np.uint16)
    big.red, big.green, big.blue = c, 65535 - c, np.full(m, 20000, dtype=np.uint16)
    big.write(f"{out}/big5m.laz", laz_backend=laspy.LazBackend.Laszip)
