#!/usr/bin/env python3
"""How much of BROAD's inclination error any estimator can remove: two measurements per trial.

Usage: broad_floor.py DIR...   (DIR: $PHANTOGRAM_DATA/imu/broad, imu/broad-extra)

1. At rest (gyroscope under 0.03 rad/s, accelerometer within 0.15 m/s² of its 0.5-s mean), the
   angle between the measured acceleration and the truth's gravity in the sensor frame: what the
   motion-capture truth itself allows (IMU-to-marker mounting, truth noise), with and without the
   accelerometer's mean offset from the truth's gravity taken out ("oracle": it knows the truth).
2. VQF's inclination RMSE over the movement rows with its track shifted against the truth by
   -3..+3 samples: a minimum away from 0 is a time offset between the IMU's samples and the
   truth's, which no estimator running on the IMU alone can see.

A measuring tool, not part of the project: run it with the throwaway virtual environment that
`cargo xtask bench orientation` makes (target/vqf-venv: numpy, vqf 2.1.2).
"""
import glob
import gzip
import os
import sys

import numpy as np
from vqf import VQF

G = 9.81
RATE_HZ = 285.714


def load(path):
    with gzip.open(path, "rt") as f:
        f.readline()
        return np.genfromtxt(f, delimiter=",")


def trial(path):
    """One BROAD trial's columns: accelerometer, gyroscope, magnetometer, truth quaternion
    (sensor -> earth, w x y z), the movement flag, and where the truth is known."""
    d = load(path)
    acc, gyr, mag, truth, moving = d[:, 1:4], d[:, 4:7], d[:, 7:10], d[:, 10:14], d[:, 14] == 1
    return acc, gyr, mag, truth, moving, np.all(np.isfinite(truth), 1)


def moving_average(x, n):
    """Each column of x averaged over n samples, centred."""
    window = np.ones(n) / n
    return np.stack([np.convolve(x[:, i], window, "same") for i in range(x.shape[1])], 1)


def qmul(a, b):
    w1, x1, y1, z1 = a.T
    w2, x2, y2, z2 = b.T
    return np.stack(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ],
        1,
    )


def conj(q):
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def gravity_in_sensor(q):
    """The earth's up (z) in the sensor frame, for sensor -> earth quaternions q (w, x, y, z)."""
    w, x, y, z = q.T
    return G * np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], 1)


def angle_rms_deg(a, b):
    c = (a * b).sum(1) / np.linalg.norm(a, axis=1) / np.linalg.norm(b, axis=1)
    return np.degrees(np.sqrt(np.mean(np.arccos(np.clip(c, -1, 1)) ** 2)))


def main():
    paths = sorted(p for d in sys.argv[1:] for p in glob.glob(os.path.join(d, "*.csv.gz")))
    if not paths:
        sys.exit(__doc__)
    print(f"{'trial':44} {'rest':>6} {'oracle':>6} | VQF inclination RMSE, estimate shifted by s samples")
    for path in paths:
        acc, gyr, mag, truth, moving, known = trial(path)
        mean = moving_average(acc, 143)
        rest = (np.linalg.norm(gyr, axis=1) < 0.03) & (np.linalg.norm(acc - mean, axis=1) < 0.15) & known
        a, g = acc[rest], gravity_in_sensor(truth[rest])
        floor, oracle = angle_rms_deg(a, g), angle_rms_deg(a - (a - g).mean(0), g)
        q = VQF(1.0 / RATE_HZ).updateBatch(
            np.ascontiguousarray(gyr), np.ascontiguousarray(acc), np.ascontiguousarray(mag)
        )["quat9D"]
        scored = moving & known
        scored[:10] = scored[-10:] = False
        shifted = []
        for s in range(-3, 4):
            e = qmul(np.roll(q, -s, axis=0), conj(truth))
            incl = 2 * np.arccos(np.clip(np.sqrt(e[:, 0] ** 2 + e[:, 3] ** 2), -1, 1))
            shifted.append(f"{s:+d}: {np.degrees(np.sqrt(np.mean(incl[scored] ** 2))):.2f}")
        name = os.path.basename(path).removesuffix(".csv.gz")
        print(f"{name[:44]:44} {floor:6.2f} {oracle:6.2f} | {'  '.join(shifted)}")


if __name__ == "__main__":
    main()
