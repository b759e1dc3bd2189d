"""PNG files from numpy arrays, with nothing but the standard library: a
depth image or a mask out of a cast, written for a look."""

import struct
import zlib

import numpy as np


def write_png(path, image):
    """Writes an (H, W) grey or (H, W, 3) RGB image of uint8 to `path`
    (8 bits a channel, no interlace). Other dtypes are refused: scale a
    depth image to 0..255 first."""
    a = np.asarray(image)
    if a.dtype != np.uint8 or a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] != 3) or a.size == 0:
        raise ValueError(f"write_png: an (H, W) or (H, W, 3) uint8 image expected, not {a.dtype} {a.shape}")
    height, width = a.shape[:2]
    colour = 2 if a.ndim == 3 else 0
    # Every row starts with filter byte 0 (none).
    rows = np.concatenate([np.zeros((height, 1), np.uint8), a.reshape(height, -1)], axis=1)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, colour, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
                + chunk(b"IEND", b""))
