"""A check that a PNG written by the package shows a drawn figure, not just a file of some size."""

from __future__ import annotations

import pathlib

import numpy as np


def assert_png_drawn(path: pathlib.Path, min_pixels: int = 200_000) -> None:
    """`path` is a PNG of at least `min_pixels` pixels with drawn content: at least 1 % of it
    differs from the background colour (the most common one) and it holds many colours (lines,
    markers and antialiased text). A blank or a text-only canvas fails."""
    import matplotlib.image

    data = pathlib.Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path}: not a PNG"
    img = matplotlib.image.imread(str(path))
    assert img.ndim == 3 and img.shape[0] * img.shape[1] >= min_pixels, (path, img.shape)
    rgb = np.round(img[..., :3] * 255).astype(np.int32)
    codes = (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]
    values, counts = np.unique(codes, return_counts=True)
    background = values[np.argmax(counts)]
    drawn = float(np.mean(codes != background))
    assert drawn > 0.01, f"{path}: {100 * drawn:.2f} % of the pixels drawn"
    assert values.size >= 32, f"{path}: {values.size} colours"
