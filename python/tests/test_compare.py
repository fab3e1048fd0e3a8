"""lattice.compare gives `lattice compare`'s figures."""
import json
import math

import numpy as np

import lattice
from conftest import plate4_dict


def test_identical_images():
    img, _ = lattice.render(lattice.Scene(plate4_dict(32, 32)))
    s = lattice.compare(img, img)
    assert math.isinf(s["psnr_db"]) and s["ssim"] == 1.0 and s["share_over_8"] == 0.0


def test_figures_are_the_command_lines(cli, scene_file, tmp_path):
    path = scene_file(plate4_dict(48, 48))
    cli("render", path, "-o", tmp_path / "a.png", "-q")
    cli("render", path, "-o", tmp_path / "b.png", "-q", "--footprint", "on")
    expected = json.loads(cli("compare", tmp_path / "a.png", tmp_path / "b.png", "--json").stdout)
    s = lattice.compare(lattice.read_png(str(tmp_path / "a.png")), lattice.read_png(str(tmp_path / "b.png")))
    for key, cli_key in (("psnr_db", "psnr_db"), ("ssim", "ssim"), ("rmse", "rmse"),
                         ("max_abs_error", "max_abs_error"), ("pixels_over_8", "pixels_over_threshold"),
                         ("share_over_8", "share_over_threshold")):
        assert s[key] == expected[cli_key], key
    assert 0 < s["share_over_8"] < 1


def test_the_figures_rules():
    rng = np.random.default_rng(1)
    a = rng.integers(0, 256, (40, 30, 3), dtype=np.uint8)
    b = np.clip(a.astype(int) + rng.integers(-12, 13, a.shape), 0, 255).astype(np.uint8)
    s = lattice.compare(a, b)
    diff = np.abs(a.astype(int) - b.astype(int))
    assert s["max_abs_error"] == diff.max()
    assert math.isclose(s["rmse"], math.sqrt((diff ** 2).mean()))
    assert math.isclose(s["psnr_db"], 20 * math.log10(255 / s["rmse"]))
    assert math.isclose(s["share_over_8"], (diff.max(axis=2) > 8).mean())
    assert 0 < s["ssim"] < 1


def test_exact_and_lattice_renders_are_close(tmp_path):
    scene = lattice.Scene(plate4_dict(64, 64))
    exact, _ = lattice.render(scene, mode="exact", footprint="on")
    lat, _ = lattice.render(scene, mode="lattice", lattice_dir=str(tmp_path))
    s = lattice.compare(exact, lat)
    assert s["psnr_db"] > 25
