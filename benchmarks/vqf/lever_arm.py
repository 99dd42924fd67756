#!/usr/bin/env python3
"""Whether the IMU's lever arm about the hand is worth estimating: an oracle check per trial.

Usage: lever_arm.py DIR...   (DIR: $PHANTOGRAM_DATA/imu/broad, imu/broad-extra)

A hand turns the IMU about a point a few centimetres away (the wrist, the grip), so the
accelerometer also reads that point's centripetal and tangential acceleration,
`[w]x^2 r + [dw/dt]x r`, linear in the lever arm r (sensor frame). Per trial this fits r by
least squares to what the accelerometer reads beyond the truth's gravity over the movement rows
(an oracle: it knows the truth), reports how much of that non-gravity acceleration it explains,
and runs VQF 2.1.2 (default parameters, 9-D) on the raw accelerometer and on the accelerometer
with the fitted lever-arm term taken out: the most any lever-arm estimate could give an
inclination filter of VQF's kind.

A measuring tool, not part of the project: run it with the throwaway virtual environment that
`cargo xtask bench orientation` makes (target/vqf-venv: numpy, vqf 2.1.2).
"""
import glob
import os
import sys

import numpy as np
from vqf import VQF

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from broad_floor import RATE_HZ, conj, gravity_in_sensor, moving_average, qmul, trial  # noqa: E402


def skew(w):
    x, y, z = w.T
    o = np.zeros_like(x)
    return np.stack([np.stack([o, -z, y], 1), np.stack([z, o, -x], 1), np.stack([-y, x, o], 1)], 1)


def inclination_rmse_deg(q, truth, rows):
    e = qmul(q, conj(truth))
    incl = 2 * np.arccos(np.clip(np.sqrt(e[:, 0] ** 2 + e[:, 3] ** 2), -1, 1))
    return np.degrees(np.sqrt(np.mean(incl[rows] ** 2)))


def main():
    paths = sorted(p for d in sys.argv[1:] for p in glob.glob(os.path.join(d, "*.csv.gz")))
    if not paths:
        sys.exit(__doc__)
    print(f"{'trial':44} {'r (cm, sensor frame)':>22} {'explained':>9} | VQF inclination RMSE: raw -> lever arm out")
    before, after = [], []
    for path in paths:
        acc, gyr, mag, truth, moving, known = trial(path)
        # The rate smoothed over 9 samples (31 ms) before differentiating it.
        rate = moving_average(gyr, 9)
        spin = np.gradient(rate, axis=0) * RATE_HZ
        lever = skew(rate) @ skew(rate) + skew(spin)
        rows = moving & known
        beyond = np.zeros_like(acc)
        beyond[known] = acc[known] - gravity_in_sensor(truth[known])
        r, *_ = np.linalg.lstsq(lever[rows].reshape(-1, 3), beyond[rows].reshape(-1), rcond=None)
        fitted = lever @ r
        explained = 1 - np.sum((beyond[rows] - fitted[rows]) ** 2) / np.sum(beyond[rows] ** 2)
        scored = rows.copy()
        scored[:10] = scored[-10:] = False
        run = lambda a: VQF(1.0 / RATE_HZ).updateBatch(  # noqa: E731
            np.ascontiguousarray(gyr), np.ascontiguousarray(a), np.ascontiguousarray(mag)
        )["quat9D"]
        b, a = inclination_rmse_deg(run(acc), truth, scored), inclination_rmse_deg(run(acc - fitted), truth, scored)
        before.append(b)
        after.append(a)
        name = os.path.basename(path).removesuffix(".csv.gz")
        cm = " ".join(f"{100 * v:5.1f}" for v in r)
        print(f"{name[:44]:44} {cm:>22} {explained:9.2f} | {b:.2f} -> {a:.2f}")
    print(f"{'mean':44} {'':>22} {'':>9} | {np.mean(before):.3f} -> {np.mean(after):.3f}")


if __name__ == "__main__":
    main()
