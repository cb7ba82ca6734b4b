#!/usr/bin/env python3
"""The pages' numbers (daq/web/present.js, in the operator's and the fleet page) are written as
the terminal and the reports write them (cal::fixed_text): rounded half away from zero at the
last decimal place of the value as a decimal, never "-0.000". toFixed alone rounds the binary
value (0.0045 is stored a little under 9/2000: toFixed(3) gives "0.004", the terminal "0.005"),
so a page and a report could differ by one in the last digit.

The same values go through the C++ writer (fixed_text_print) and through present.fixed in headless
Chromium; both must give the same text, and the ties written out by hand below.
Usage: present_numbers_test.py FIXED_TEXT_PRINT PRESENT_JS
"""
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(__file__))
from page_checks import ok  # noqa: E402
from webdriver import Browser  # noqa: E402

PRINT, PRESENT = sys.argv[1], sys.argv[2]

# (value as text, decimals, what the terminal writes, by hand). The value texts are read by
# strtod and by JavaScript's Number() alike (the nearest double).
BY_HAND = [
    ("0.0045", 3, "0.005"),     # stored under the tie (0.00449999...): toFixed gives "0.004"
    ("-0.0045", 3, "-0.005"),
    ("0.0035", 3, "0.004"),     # stored over it
    ("1.0005", 3, "1.001"),     # stored 1.000499999...: toFixed "1.000"
    ("2.675", 2, "2.68"),       # stored 2.67499999...: toFixed "2.67"
    ("-2.675", 2, "-2.68"),
    ("0.125", 2, "0.13"),       # an exact binary tie: away from zero
    ("-0.125", 2, "-0.13"),
    ("2.5", 0, "3"),
    ("-2.5", 0, "-3"),
    ("-0.0004", 3, "0.000"),    # rounds to zero: no sign
    ("-0.0", 2, "0.00"),
    ("-0.00005", 4, "-0.0001"),
    ("12.34564", 4, "12.3456"),
    ("123456.5", 0, "123457"),
    ("100000000000000000000", 3, "100000000000000000000.000"),
]
# More ties and near-ties at the places the pages use (µm to 2 and 3, mm to 3 and 4, ppm to 2,
# n to 8): the C++ writer's text is the reference for these.
MORE = [(f"{k}{tail}", d) for k in ("0", "1", "-3", "12", "-250") for tail, d in
        (("", 2), (".005", 2), (".015", 2), (".0005", 3), (".00035", 4), (".000045", 5), (".25", 1),
         (".0000000045", 9), (".1449999", 2), (".00015", 4))]
MORE += [("-286.205", 2), ("1.000269045", 8), ("0.00000005", 7), ("4503599627370495.5", 1),
         ("1e21", 2), ("-1e300", 4), ("0.1", 20)]

cases = [(v, d) for v, d, _ in BY_HAND] + MORE
cpp = subprocess.run([PRINT, *[x for v, d in cases for x in (v, str(d))]], capture_output=True,
                     text=True, check=True).stdout.splitlines()
ok(len(cpp) == len(cases), f"fixed_text_print wrote {len(cpp)} numbers for {len(cases)} values")
for (v, d, want), got in zip(BY_HAND, cpp):
    ok(got == want, f"the C++ writer: {v} to {d} places is {got!r} (by hand {want!r})")

with open(PRESENT, encoding="utf-8") as f:
    source = f.read()
b = Browser(400, 300)
try:
    b.get("about:blank")
    page = b.js(source + "\nreturn arguments[0].map(([v, d]) => [present.fixed(Number(v), d), Number(v).toFixed(d)]);",
                [[v, d] for v, d in cases])
finally:
    b.close()
differs = 0
for (v, d), (js, to_fixed), c in zip(cases, page, cpp):
    ok(js == c, f"present.fixed({v}, {d}) = {js!r}, as the terminal writes it ({c!r})")
    differs += to_fixed != c and not to_fixed.startswith("-0") and "e" not in to_fixed
# The ties by hand where toFixed alone gives the other digit: what this test is for.
ok(differs >= 5, f"{differs} of the values are ties where toFixed alone writes another last digit")
print(f"{len(cases)} values written alike on the page and the terminal")
