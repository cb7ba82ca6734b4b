#!/usr/bin/env python3
"""Writes a capture file (docs/capture-format.md) holding HEADER_TEXT and no records, for the
tests of what `daq replay` makes of a header: python3 write_capture.py OUT.cdq HEADER_TEXT."""
import struct
import sys


def crc32c(data, crc=0):
    crc ^= 0xFFFFFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ (0x82F63B78 if crc & 1 else 0)
    return crc ^ 0xFFFFFFFF


assert crc32c(b"123456789") == 0xE3069283  # the format's check value
out, header = sys.argv[1], sys.argv[2].encode("utf-8", "surrogateescape")
head = struct.pack("<HHI", 1, 0, len(header)) + header
total = struct.pack("<Q", 0)
end = struct.pack("<IIII", 0x444E4543, 8, 0, crc32c(total)) + total
with open(out, "wb") as f:
    f.write(b"CALDAQCP" + head + struct.pack("<I", crc32c(head)) + end)
