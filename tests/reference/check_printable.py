"""Independent checks of a cleaned 2D solid (the `--cleaned` .npy of `latvox topo`), with
SciPy only: face-connected components, point contacts, local thickness (the diameter of the
largest inscribed disc holding each pixel, from the Euclidean distance transform), and area.

Usage: python3 check_printable.py CLEANED.npy PIXEL_MM MIN_FEATURE_MM OUT.json
"""
import json
import sys

import numpy as np
from scipy import ndimage

solid = np.load(sys.argv[1]) > 0.5
h, lmin = float(sys.argv[2]), float(sys.argv[3])
# Void beyond the domain.
padded = np.pad(solid, 1)
labels, components = ndimage.label(padded, structure=[[0, 1, 0], [1, 1, 1], [0, 1, 0]])
a, b, c, d = padded[:-1, :-1], padded[:-1, 1:], padded[1:, :-1], padded[1:, 1:]
contacts = int(np.sum((a & d & ~b & ~c) | (b & c & ~a & ~d)))
# Distance from each solid pixel centre to the nearest void pixel centre; the inscribed radius
# reaches the void's edge, half a pixel closer.
dist = ndimage.distance_transform_edt(padded)
radius = np.where(padded, dist - 0.5, 0.0)
thickness = np.zeros_like(radius)
ys, xs = np.nonzero(padded)
order = np.argsort(radius[ys, xs])
for k in order:
    y, x, r = ys[k], xs[k], radius[ys[k], xs[k]]
    if r <= 0:
        continue
    R = int(np.ceil(r))
    y0, y1, x0, x1 = max(0, y - R), min(padded.shape[0], y + R + 1), max(0, x - R), min(padded.shape[1], x + R + 1)
    yy, xx = np.mgrid[y0:y1, x0:x1]
    disc = (yy - y) ** 2 + (xx - x) ** 2 <= r * r
    win = thickness[y0:y1, x0:x1]
    win[disc] = np.maximum(win[disc], 2 * r)
thin = padded & (thickness * h < lmin - 2 * h)
thin_labels, thin_parts = ndimage.label(thin, structure=np.ones((3, 3)))
sizes = ndimage.sum(thin, thin_labels, range(1, thin_parts + 1)) if thin_parts else []
json.dump({
    "components": int(components),
    "point_contacts": contacts,
    "solid_pixels": int(solid.sum()),
    "thin_pixels": int(thin.sum()),
    "largest_thin_part": int(max(sizes)) if len(sizes) else 0,
    "min_thickness_mm": float(thickness[padded].min() * h),
}, open(sys.argv[4], "w"))
