#!/usr/bin/env python3
"""Writes the CLI fixtures of `daq analyse circle` from an exact forward model of a two-axis
machine (independent of the C++ fit: the tool path is simulated with the injected errors and
the bar length computed as a distance). Usage: make_fixtures.py [OUTPUT_DIR]"""
import math
import os
import sys


def deviation_um(m, theta, s, r_mm, feed):
    """Bar length minus the nominal radius, tool commanded at theta moving in direction s."""
    w = feed / 60.0 / r_mm  # rad/s
    u = r_mm * math.cos(theta)
    v = r_mm * math.sin(theta - s * w * m.get("lag_ms", 0) * 1e-3)  # Y lags X
    du_dt, dv_dt = -s * math.sin(theta), s * math.cos(theta)
    ua = u - m.get("square_um_per_m", 0) * 1e-6 * v  # +: angle between +X and +Y above 90 deg
    va = v
    ua += 1e-3 * (-(m.get("backlash_x", 0) / 2) * (1 if du_dt > 0 else -1)
                  + m.get("cyclic_x", 0) * math.sin(2 * math.pi * u / m.get("period_mm", 10)))
    length = math.hypot(ua + m.get("cx", 0) * 1e-3, va + m.get("cy", 0) * 1e-3)
    return (length - r_mm) * 1e3


def angle_fixture(path):
    r_mm, feed = 50.0, 1000.0
    m = {"square_um_per_m": 20, "backlash_x": 4, "lag_ms": 1.0, "cx": 5, "cy": -3}
    with open(path, "w") as f:
        f.write("# Exact forward model (not the fit's basis): R 50 mm, feed 1000 mm/min, "
                "squareness +20 um/m,\n# backlash X 4 um, Y lags X by 1.0 ms, centre (5, -3) um;"
                " 4 samples per degree, no noise.\ndirection,angle_deg,deviation_um\n")
        for name, s in (("ccw", 1), ("cw", -1)):
            for i in range(1440):
                a = s * i * 0.25
                f.write(f"{name},{a:.6f},{deviation_um(m, math.radians(a), s, r_mm, feed):.6f}\n")


def time_fixture(path):
    """The program as a ballbar runs it: each arc move from its own t = 0, 30 degrees of
    overshoot before and after the 360 degree arc, 100 Hz; the ccw move starts at 90 degrees,
    the cw move where it ended (90 + 360 + 60). Absolute bar lengths (length_mm)."""
    r_mm, feed, rate, os_deg, start = 50.0, 1000.0, 100.0, 30.0, 90.0
    m = {"square_um_per_m": -15, "lag_ms": 0.5, "cyclic_x": 1.0, "period_mm": 5.0, "cx": -2,
         "cy": 4}
    deg_s = math.degrees(feed / 60.0 / r_mm)
    with open(path, "w") as f:
        f.write("# Timed ballbar program: R 50 mm, 1000 mm/min, 100 Hz, start 90 deg, overshoot "
                "30 deg;\n# squareness -15 um/m, Y lags X by 0.5 ms, cyclic X 1.0 um with a 5 mm "
                "period, centre (-2, 4) um.\ndirection,time_s,length_mm\n")
        for name, s, move_start in (("ccw", 1, start), ("cw", -1, start + 360 + 2 * os_deg)):
            i = 0
            while i / rate * deg_s <= 360 + 2 * os_deg:
                travelled = i / rate * deg_s
                theta = math.radians(move_start + s * travelled)
                # The overshoot arcs are not on the circle (the machine accelerates): 30 um off.
                off = 30.0 if travelled < os_deg or travelled > os_deg + 360 else 0.0
                dev = deviation_um(m, theta, s, r_mm, feed) + off
                f.write(f"{name},{i / rate:.2f},{r_mm + dev * 1e-3:.9f}\n")
                i += 1


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    angle_fixture(os.path.join(out, "model.csv"))
    time_fixture(os.path.join(out, "model_time.csv"))
