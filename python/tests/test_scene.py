"""Scenes from Python: their scatters' placements as arrays."""
import numpy as np

import lattice


SCATTER = {
    "format": "lattice/1",
    "camera": {"eye": [0, -100, 0], "look_at": [0, 0, 0], "fov_y_deg": 30, "width": 32, "height": 32},
    "materials": {"m": {}},
    "primitives": {"hair": {"spheres": [[1, 1, 0.5, 0.5], [1, 1, 4, 0.5]], "cylinders": [[0, 1, 0.5]],
                            "lattice": {"sigma": 1.0, "cells": [2, 2, 5]}}},
    "objects": [
        {"type": "sphere", "name": "ball", "center": [1, 2, 3], "radius": 10, "material": "m"},
        {"type": "scatter", "name": "fur", "primitive": "hair", "on": "ball", "count": 200, "seed": 7,
         "scale": [0.5, 1.0], "material": "m"},
    ],
}


def test_scatter_placements():
    [s] = lattice.scatters(lattice.Scene(SCATTER))
    assert s["name"] == "fur" and s["primitive"] == "hair" and s["object"] == 1
    roots, frames, scales = s["roots"], s["frames"], s["scales"]
    assert roots.shape == (200, 3) and frames.shape == (200, 3, 3) and scales.shape == (200,)
    assert np.allclose(np.linalg.norm(roots - [1, 2, 3], axis=1), 10, atol=1e-6)
    assert np.allclose(np.einsum("nji,njk->nik", frames, frames), np.eye(3), atol=1e-9)
    assert ((scales >= 0.5) & (scales <= 1.0)).all()
    # align "normal": each instance's z axis is the sphere's normal at its root.
    normals = (roots - [1, 2, 3]) / 10
    assert np.allclose(frames[:, :, 2], normals, atol=1e-6)
