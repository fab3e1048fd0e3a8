"""A user's mistakes raise lattice.InputError naming the file and the place, as the command line says."""
import json

import pytest

import lattice
from conftest import plate4_dict, with_singular_transform


def test_singular_transform_in_a_dict_names_the_object():
    d = with_singular_transform(plate4_dict(), 3)
    with pytest.raises(lattice.InputError, match=r"^scene: objects\[3\]\.transform: "):
        lattice.Scene(d)


def test_the_message_is_the_command_lines(cli, scene_file):
    path = scene_file(with_singular_transform(plate4_dict(), 5))
    with pytest.raises(lattice.InputError) as err:
        lattice.load(path)
    run = cli("render", path, "-o", path + ".png", check=False)
    assert run.returncode == 2
    assert run.stderr.strip() == "lattice: error: " + str(err.value)
    assert f"{path}: objects[5].transform" in str(err.value)


def test_input_error_is_a_value_error():
    assert issubclass(lattice.InputError, ValueError)


def test_missing_file_and_bad_json(tmp_path):
    with pytest.raises(lattice.InputError, match="nope.json"):
        lattice.load(str(tmp_path / "nope.json"))
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    with pytest.raises(lattice.InputError, match="bad.json"):
        lattice.load(str(bad))


def test_a_dict_path_names_it_in_messages():
    d = plate4_dict()
    d["camera"]["fov_y_deg"] = 200
    with pytest.raises(lattice.InputError, match=r"^mine\.json: camera\.fov_y_deg: "):
        lattice.Scene(d, path="mine.json")


def test_render_budget_is_checked(plate4):
    with pytest.raises(lattice.InputError, match="over the limit|too many"):
        lattice.render(lattice.Scene(plate4_dict(4096, 4096)), spp=65536)


def test_images_of_different_sizes_do_not_compare():
    import numpy as np
    with pytest.raises(lattice.InputError, match="differ in size"):
        lattice.compare(np.zeros((4, 4, 3), np.uint8), np.zeros((4, 5, 3), np.uint8))
    with pytest.raises(lattice.InputError, match="H x W x 3"):
        lattice.to_srgb8(np.zeros((4, 4), np.float32))
