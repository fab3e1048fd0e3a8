"""Renders from Python equal the command line's, pixel for pixel, through the same options."""
import os
import re
import signal
import threading
import time

import numpy as np
import pytest

import lattice
from conftest import example, plate4_dict


def cli_png(cli, scene_path, out, *options):
    cli("render", scene_path, "-o", out, "-q", *options)
    return lattice.read_png(str(out))


@pytest.mark.parametrize("options", [
    {"mode": "exact"},
    {"mode": "exact", "spp": 4},  # the PNG averages clamped samples: to_srgb8 must not re-derive it
    {"mode": "exact", "footprint": "on"},
    {"mode": "lattice", "lod": "off"},
])
def test_image_equals_command_line(cli, scene_file, tmp_path, plate4, options):
    path = scene_file(plate4)
    lattice_dir = tmp_path / "tables"
    lattice_dir.mkdir()
    img, stats = lattice.render(lattice.load(path), lattice_dir=str(lattice_dir), threads=2, **options)
    assert img.dtype == np.float32 and img.shape == (64, 64, 3)
    args = []
    for k, v in options.items():
        args += ["--" + k.replace("_", "-"), str(v)]
    expected = cli_png(cli, path, tmp_path / "cli.png", "--lattice-dir", lattice_dir, *args)
    got = lattice.to_srgb8(img)
    assert got.dtype == np.uint8
    assert np.array_equal(got, expected)
    assert stats["mode"] == options["mode"] and stats["spp"] == options.get("spp", 1)
    assert stats["primary_rays"] == 64 * 64 * options.get("spp", 1)


def test_clipped_samples_give_the_command_lines_png(cli, scene_file, tmp_path):
    """With bright lights many samples pass 1: the PNG averages clamped samples, which the mean
    radiance cannot give back, so to_srgb8 must use the render's own 8-bit image."""
    d = plate4_dict()
    for light in d["lights"]:
        light["intensity"] = [3 * c for c in light["intensity"]]
    path = scene_file(d)
    img, _ = lattice.render(lattice.load(path), spp=4)
    expected = cli_png(cli, path, tmp_path / "cli.png", "--spp", "4")
    naive = np.round(np.clip(img.astype(np.float64), 0, 1) * 255).astype(np.uint8)
    assert not np.array_equal(naive, expected)  # the case this test is for does arise
    assert np.array_equal(lattice.to_srgb8(img), expected)


def test_stats_have_the_command_lines_fields(cli, scene_file, tmp_path, plate4):
    path = scene_file(plate4)
    cli("render", path, "-o", tmp_path / "a.png", "-q", "--mode", "exact", "--footprint", "on",
        "--stats", tmp_path / "s.json")
    import json
    expected = json.loads((tmp_path / "s.json").read_text())
    _, stats = lattice.render(lattice.load(path), mode="exact", footprint="on")
    assert set(stats) == set(expected)


def test_to_srgb8_of_other_arrays_is_the_8_bit_rule():
    img = np.array([[[-1.0, 0.5, 2.0], [0.2, np.nan, 1.0]]], dtype=np.float32)
    assert lattice.to_srgb8(img).tolist() == [[[0, 128, 255], [51, 0, 255]]]


def test_a_modified_render_array_is_converted_afresh(plate4):
    img, _ = lattice.render(lattice.Scene(plate4), spp=4)
    before = lattice.to_srgb8(img)
    img[0, 0] = 0.0
    assert lattice.to_srgb8(img)[0, 0].tolist() == [0, 0, 0]
    assert np.array_equal(lattice.to_srgb8(img)[1:], before[1:])


def test_every_command_line_option_is_a_keyword(cli):
    """The help's long options, less the command line's own (files, terminal), are render()'s."""
    help_text = cli("render", "--help").stdout
    cli_options = set(re.findall(r"--([a-z][a-z-]*)", help_text)) - {"help", "output", "stats", "quiet"}
    python_options = set(lattice.render_options())
    assert python_options == {o.replace("-", "_") for o in cli_options}


def test_option_values_are_checked_as_on_the_command_line(plate4):
    scene = lattice.Scene(plate4)
    with pytest.raises(lattice.InputError, match=r"spp: 0 is not in 1 to 65536"):
        lattice.render(scene, spp=0)
    with pytest.raises(lattice.InputError, match=r"mode: 'fast' is not one of auto, exact, lattice"):
        lattice.render(scene, mode="fast")
    with pytest.raises(lattice.InputError, match=r"lod_budget: nan"):
        lattice.render(scene, lod_budget=float("nan"))
    with pytest.raises(TypeError, match=r"unexpected option 'sampels'"):
        lattice.render(scene, sampels=4)
    with pytest.raises(TypeError):
        lattice.render(scene, spp=1.5)


def test_notes_for_options_that_cannot_act(plate4):
    _, stats = lattice.render(lattice.Scene(plate4), mode="exact", sigma_inv=2)
    assert stats["option_notes"] == ["--sigma-inv has no effect in exact mode (it acts in: lattice, auto)"]


def test_another_python_thread_runs_during_a_render():
    scene = lattice.Scene(plate4_dict(160, 160))
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        start = time.perf_counter()
        _, stats = lattice.render(scene, spp=16, threads=1)
        end = time.perf_counter()
    finally:
        stop.set()
        t.join()
    during = [x for x in ticks if start < x < end]
    # With the GIL held through the render the thread could not tick at all meanwhile.
    assert end - start > 0.1
    assert len(during) >= 20


def test_ctrl_c_interrupts_a_render():
    scene = lattice.Scene(plate4_dict(256, 256))
    timer = threading.Timer(0.2, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        lattice.render(scene, spp=256, threads=1)
    assert time.perf_counter() - start < 5
    timer.join()
    # The next render is not interrupted, and Python's own handler is back.
    lattice.render(lattice.Scene(plate4_dict(16, 16)))
    with pytest.raises(KeyboardInterrupt):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(1)


def test_progress_callback():
    calls = []
    lattice.render(lattice.Scene(plate4_dict(96, 96)), spp=4,
                   progress=lambda label, done: calls.append((label, done)))
    assert calls and calls[-1][1] == 1.0
    assert all(0.0 <= done <= 1.0 for _, done in calls)


def test_memory_is_flat_over_100_renders():
    scene = lattice.Scene(plate4_dict(48, 48, hairs=50))

    def rss_kb():
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * 4

    for _ in range(10):
        lattice.render(scene)
    before = rss_kb()
    for _ in range(100):
        img, stats = lattice.render(scene)
        lattice.to_srgb8(img)
    # An image is 48 x 48 x 3 floats, 27 KB: 100 kept would be 2.7 MB.
    assert rss_kb() - before < 2000


def test_scene_edits_keep_the_objects(cli, scene_file, tmp_path, plate4):
    scene = lattice.Scene(plate4)
    small = scene.copy()
    small.camera = dict(small.camera, width=32, height=24)
    img, _ = lattice.render(small)
    assert img.shape == (24, 32, 3) and scene.width == 64
    with pytest.raises(lattice.InputError, match=r"camera\.width: must be between 1 and"):
        small.camera = dict(small.camera, width=0)
    d = plate4_dict(32, 24)
    expected = cli_png(cli, scene_file(d), tmp_path / "e.png")
    assert np.array_equal(lattice.to_srgb8(img), expected)
