"""The plotted program of the path plot tests and the colours and pixels they check."""

from __future__ import annotations

import io

import numpy as np
from matplotlib import colormaps
from PIL import Image

# a line at F6000 (100 mm/s), a half circle (G2, r 10, centre (20, 10)) and a line at F3000
PROGRAM = b"G01 X0 Y0 F6000\nG01 X20 Y0\nG02 X20 Y20 I0 J10\nG01 X0 Y20 F3000\nM30\n"


TOP_SPEED_RGB = tuple(round(255 * c) for c in colormaps["viridis"](1.0)[:3])


FEED_RGB = (214, 39, 40)  # tab:red


def png_pixels(png: bytes) -> np.ndarray:
    """The (H, W, 3) 8-bit RGB pixels of a PNG."""
    with Image.open(io.BytesIO(png)) as image:
        assert image.format == "PNG"
        return np.asarray(image.convert("RGB"))
