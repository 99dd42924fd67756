#!/usr/bin/env python3
"""VQF's orientation on phantogram sensor logs, for `cargo xtask bench orientation`'s VQF column.

Usage: vqf_reference.py OUT_DIR LOG...

Each LOG is a phantogram sensor log (text, optionally gzip; `phantogram import` writes them).
For each, OUT_DIR/<log name without .pglog>.csv gets one row per gyroscope sample:
`t_ns,w,x,y,z`, VQF's device -> earth quaternion (9-D where the log has a magnetometer, else
6-D) after that sample. VQF (Laidig & Seel 2023, PyPI `vqf`) runs with its default parameters.

VQF needs one sample rate for all sensors. BROAD rows carry all three sensors at one time stamp;
the phones' sensors are asynchronous (accelerometer and gyroscope ~200 Hz, magnetometer ~50 Hz),
so the accelerometer and magnetometer are linearly interpolated onto the gyroscope's time stamps
(held at the ends) and the sample time is the median gyroscope interval.

This script is a measuring tool, not part of the project: it runs in a throwaway virtual
environment that `cargo xtask bench orientation` makes (numpy, vqf), never as a dependency.
"""
import gzip
import os
import sys

import numpy as np
from vqf import VQF


def read_log(path):
    with open(path, "rb") as f:
        magic = f.read(2)
    opener = gzip.open if magic == b"\x1f\x8b" else open
    streams = {"acc": [], "gyr": [], "mag": []}
    with opener(path, "rt", encoding="utf-8") as f:
        first = f.readline().split()
        if first[:1] != ["phantogram-sensor-log"]:
            raise SystemExit(f"{path}: not a phantogram sensor log")
        for line in f:
            parts = line.split()
            if len(parts) >= 5 and parts[0] in streams:
                streams[parts[0]].append([float(parts[1])] + [float(v) for v in parts[2:5]])
    return {k: np.array(v, dtype=np.float64).reshape(-1, 4) for k, v in streams.items()}


def finite_increasing(rows):
    rows = rows[np.all(np.isfinite(rows), axis=1)]
    if len(rows) == 0:
        return rows
    keep = np.concatenate([[True], np.diff(rows[:, 0]) > 0])
    return rows[keep]


def on_grid(rows, t):
    return np.stack([np.interp(t, rows[:, 0], rows[:, i]) for i in (1, 2, 3)], axis=1)


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    out_dir = sys.argv[1]
    os.makedirs(out_dir, exist_ok=True)
    for path in sys.argv[2:]:
        s = {k: finite_increasing(v) for k, v in read_log(path).items()}
        gyr, acc, mag = s["gyr"], s["acc"], s["mag"]
        if len(gyr) < 2 or len(acc) < 2:
            raise SystemExit(f"{path}: needs a gyroscope and an accelerometer")
        t = gyr[:, 0]
        ts = float(np.median(np.diff(t))) * 1e-9
        g = np.ascontiguousarray(gyr[:, 1:])
        a = np.ascontiguousarray(on_grid(acc, t))
        vqf = VQF(ts)
        if len(mag) >= 2:
            m = np.ascontiguousarray(on_grid(mag, t))
            q = vqf.updateBatch(g, a, m)["quat9D"]
        else:
            q = vqf.updateBatch(g, a)["quat6D"]
        name = os.path.basename(path)
        for ext in (".gz", ".pglog"):
            if name.endswith(ext):
                name = name[: -len(ext)]
        out = os.path.join(out_dir, name + ".csv")
        with open(out, "w") as f:
            f.write("t_ns,w,x,y,z\n")
            for ti, qi in zip(t, q):
                f.write(f"{int(ti)},{qi[0]:.9f},{qi[1]:.9f},{qi[2]:.9f},{qi[3]:.9f}\n")
        print(f"{out}: {len(t)} rows, {1 / ts:.1f} Hz", file=sys.stderr)


if __name__ == "__main__":
    main()
