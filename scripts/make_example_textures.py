#!/usr/bin/env python3
"""Writes the example textures under examples/textures/ (standard library only:
the PNGs are written with zlib, byte for byte the same on every run).

color_checker.png: the 24 patches of the X-Rite ColorChecker Classic, 6 x 4,
16 x 16 texels each, in their published sRGB values (the post-November-2014
formulation as X-Rite and BabelColor give it; Wikipedia "ColorChecker"),
dark skin at the top left, black at the bottom right.

Usage: scripts/make_example_textures.py [OUT_DIR]   (default examples/textures)
"""
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
    """An 8-bit RGB PNG of `rows` (lists of (r, g, b)), no ancillary chunks."""
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


def color_checker():
    rows = []
    for y in range(4 * PATCH):
        rows.append([COLOR_CHECKER[(y // PATCH) * 6 + x // PATCH] for x in range(6 * PATCH)])
    return png(6 * PATCH, 4 * PATCH, rows)


def main():
    out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent / "examples/textures")
    out.mkdir(parents=True, exist_ok=True)
    (out / "color_checker.png").write_bytes(color_checker())
    print(out / "color_checker.png")


if __name__ == "__main__":
    main()
