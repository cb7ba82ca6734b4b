"""E and M (ISO 230-2) of a stored run computed by hand from its stops, never from daq's output:
the mean deviation per target and direction; E the range of those means, M the range of their
bidirectional means (the mean of the two directions' at each target). Prints "E M" (6 decimals).

Usage: hand_em.py STORE.sqlite RUN_ID
"""
import sqlite3
import sys
from collections import defaultdict

stops = defaultdict(list)
for t, d, dev in sqlite3.connect(sys.argv[1]).execute(
        "SELECT target_index, direction, deviation_um FROM captured_targets WHERE run_id = ?",
        (int(sys.argv[2]),)):
    stops[(t, d)].append(dev)
mean = {k: sum(v) / len(v) for k, v in stops.items()}
bi = [(mean[(t, "+")] + mean[(t, "-")]) / 2 for t in {t for t, _ in mean}]
print(f"{max(mean.values()) - min(mean.values()):.6f} {max(bi) - min(bi):.6f}")
