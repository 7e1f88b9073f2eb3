#!/usr/bin/env python3
"""Writes the example textures under examples/textures/ (standard library only:
the PNGs are written with zlib, byte for byte the same on every run).

color_checker.png: the 24 patches of the X-Rite ColorChecker Classic, 6 x 4,
16 x 16 texels each, in their published sRGB values (the post-November-2014
formulation as X-Rite and BabelColor give it; Wikipedia "ColorChecker"),
dark skin at the top left, black at the bottom right.
carbon_twill.png (RGBA, linear): a 2/2 twill of 8-texel tows; RGB the
tangent-space normal (0.5 + 0.5 n) of each tow's rounded top, A the tow's
direction (0 along U, 1 along V), as coated_carbon_fiber reads it.
carbon_metal_mask.png, gold_mask.png, sweat_mask.png, silk_weave.png (grey,
linear): the masks of coated_carbon_fiber (a ring), gold_sss_mix (diagonal
filigree bands), skin_coated (droplets) and silk_in_plastic (a plain weave).

Usage: scripts/make_example_textures.py [OUT_DIR]   (default examples/textures)
"""
import math
import pathlib
import struct
import sys
import zlib

COLOR_CHECKER = [  # row-major, sRGB 8-bit
    (115, 82, 68), (194, 150, 130), (98, 122, 157), (87, 108, 67), (133, 128, 177), (103, 189, 170),
    (214, 126, 44), (80, 91, 166), (193, 90, 99), (94, 60, 108), (157, 188, 64), (224, 163, 46),
    (56, 61, 150), (70, 148, 73), (175, 54, 60), (231, 199, 31), (187, 86, 149), (8, 133, 161),
    (243, 243, 242), (200, 200, 200), (160, 160, 160), (122, 122, 121), (85, 85, 85), (52, 52, 52),
]
PATCH = 16


def png(width, height, rows):
    """An 8-bit RGB, RGBA or grey PNG of `rows` (lists of (r, g, b), (r, g, b, a)
    or (v,) texels), no ancillary chunks."""
    channels = len(rows[0][0])
    color_type = {1: 0, 3: 2, 4: 6}[channels]
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, color_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


def color_checker():
    rows = []
    for y in range(4 * PATCH):
        rows.append([COLOR_CHECKER[(y // PATCH) * 6 + x // PATCH] for x in range(6 * PATCH)])
    return png(6 * PATCH, 4 * PATCH, rows)


def byte(v):
    return max(0, min(255, int(round(v * 255))))


def carbon_twill(size=64, tow=8):
    rows = []
    for y in range(size):
        row = []
        for x in range(size):
            cx, cy, fx, fy = x // tow, y // tow, (x % tow + 0.5) / tow, (y % tow + 0.5) / tow
            along_u = (cx - cy) % 4 < 2  # each row of tows shifts the over/under by one
            a = ((fy if along_u else fx) - 0.5) * 1.0  # the tow's rounded top, +-0.5 rad
            n = (0.0, math.sin(a), math.cos(a)) if along_u else (math.sin(a), 0.0, math.cos(a))
            row.append(tuple(byte(0.5 + 0.5 * c) for c in n) + (0 if along_u else 255,))
        rows.append(row)
    return png(size, size, rows)


def grey(size, f):
    return png(size, size, [[(byte(f((x + 0.5) / size, (y + 0.5) / size)),) for x in range(size)] for y in range(size)])


def ring(u, v):
    r = math.hypot(u - 0.5, v - 0.5)
    return 1.0 if 0.28 < r < 0.38 else 0.0


def filigree(u, v):
    return 1.0 if (4 * (u + v)) % 1.0 < 0.3 else 0.0


def droplets(u, v):
    value = 0.0
    for i in range(24):  # fixed pseudo-random drops
        cu, cv = (i * 0.618034) % 1.0, (i * 0.414214 + 0.1) % 1.0
        radius = 0.03 + 0.04 * ((i * 0.7548777) % 1.0)
        du, dv = min(abs(u - cu), 1 - abs(u - cu)), min(abs(v - cv), 1 - abs(v - cv))
        value = max(value, max(0.0, 1.0 - math.hypot(du, dv) / radius))
    return min(1.0, value * 2.0)


def plain_weave(u, v):
    return float((int(u * 8) + int(v * 8)) % 2)


def main():
    out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent / "examples/textures")
    out.mkdir(parents=True, exist_ok=True)
    files = {
        "color_checker.png": color_checker(),
        "carbon_twill.png": carbon_twill(),
        "carbon_metal_mask.png": grey(64, ring),
        "gold_mask.png": grey(64, filigree),
        "sweat_mask.png": grey(64, droplets),
        "silk_weave.png": grey(32, plain_weave),
    }
    for name, data in files.items():
        (out / name).write_bytes(data)
        print(out / name)


if __name__ == "__main__":
    main()
