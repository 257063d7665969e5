#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Checks two viewer screenshots (level 0 and level 2): neither is blank, they differ, and each shows its
level's colour more than the other does (red for level 0, green for level 2; see level_color()).

Standard library only: the PNG decoder below handles what browsers write (8-bit greyscale, RGB, RGBA,
non-interlaced), which is all this test needs.
"""
import struct
import sys
import zlib


def read_png(path):
    """Returns (width, height, rows) with rows a list of bytes objects, 3 bytes (RGB) per pixel."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG")
    pos, idat, header = 8, [], None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace != 0:
        raise ValueError(f"{path}: unsupported PNG (depth {depth}, colour type {colour}, interlace {interlace})")
    raw = zlib.decompress(b"".join(idat))
    stride = width * channels
    rows, previous, offset = [], bytearray(stride), 0
    for _ in range(height):
        kind, line = raw[offset], bytearray(raw[offset + 1:offset + 1 + stride])
        offset += 1 + stride
        # Undo the per-row filter (PNG specification, section 9).
        for i in range(stride):
            left = line[i - channels] if i >= channels else 0
            up = previous[i]
            up_left = previous[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + left) & 255
            elif kind == 2:
                line[i] = (line[i] + up) & 255
            elif kind == 3:
                line[i] = (line[i] + (left + up) // 2) & 255
            elif kind == 4:
                p = left + up - up_left
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - up_left)
                predictor = left if pa <= pb and pa <= pc else up if pb <= pc else up_left
                line[i] = (line[i] + predictor) & 255
        previous = line
        if channels >= 3:
            rgb = bytes(b for x in range(width) for b in line[x * channels:x * channels + 3])
        else:
            rgb = bytes(line[x * channels] for x in range(width) for _ in range(3))
        rows.append(rgb)
    return width, height, rows


def pixels(rows):
    for row in rows:
        for x in range(0, len(row), 3):
            yield row[x], row[x + 1], row[x + 2]


def main():
    first, second = (read_png(path) for path in sys.argv[1:3])
    if first[:2] != second[:2]:
        sys.exit(f"screenshots differ in size: {first[:2]} vs {second[:2]}")
    total = first[0] * first[1]
    failures = []
    summaries = []
    for name, image in (("level 0", first), ("level 2", second)):
        counts = {}
        for p in pixels(image[2]):
            counts[p] = counts.get(p, 0) + 1
        background, background_count = max(counts.items(), key=lambda item: item[1])
        drawn = 1 - background_count / total
        summaries.append(f"{name}: {len(counts)} colours, {100 * drawn:.1f}% drawn over background {background}")
        if drawn < 0.02 or len(counts) < 50:
            failures.append(f"{name} looks blank")
    changed = sum(1 for a, b in zip(pixels(first[2]), pixels(second[2])) if a != b) / total
    summaries.append(f"{100 * changed:.1f}% of pixels differ between the levels")
    if changed < 0.005:
        failures.append("switching the level did not change the picture")

    def reddish(image):
        return sum(1 for r, g, b in pixels(image[2]) if r > g + 15 and r > b + 15)

    def greenish(image):
        return sum(1 for r, g, b in pixels(image[2]) if g > r + 10 and g > b + 10)

    summaries.append(f"red-dominant pixels {reddish(first)} vs {reddish(second)}, "
                     f"green-dominant {greenish(first)} vs {greenish(second)}")
    if reddish(first) <= reddish(second):
        failures.append("level 0 is not the redder picture (level 0's colour is red)")
    if greenish(second) <= greenish(first):
        failures.append("level 2 is not the greener picture (level 2's colour is green)")
    print("\n".join(summaries))
    if failures:
        sys.exit("; ".join(failures))


if __name__ == "__main__":
    main()
