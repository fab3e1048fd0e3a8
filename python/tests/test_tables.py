"""Tables as arrays: header, vectorised lookups, pairs, certification; scatter placements."""
import json

import numpy as np
import pytest

import lattice
from conftest import plate4_dict


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    out = tmp_path_factory.mktemp("tables") / "hair.lht"
    return lattice.rasterize(lattice.Scene(plate4_dict()), "hair", output=str(out), encoding="dense")


def test_header(table, cli):
    info = json.loads(cli("inspect", table.path, "--json", "--no-certify").stdout)
    assert table.encoding == info["encoding"] == "dense"
    assert list(table.cells) == info["cells"] and table.sigma_inv == info["sigma_inv"]
    assert table.n_lp == info["N_lp"] and table.stored_hits == info["stored_hits"]
    assert table.bytes == info["bytes"] and table.primitive == "hair"
    assert isinstance(table.metadata, dict) and "hair" in json.dumps(table.metadata)


def test_lookup_agrees_with_certification(table, cli):
    entry, exit_ = table.pairs()
    assert entry.dtype == np.uint32 and len(entry) == len(exit_)
    r = table.lookup(entry, exit_)
    hits = r["hit"]
    info = json.loads(cli("inspect", table.path, "--json").stdout)["certified"]
    assert len(entry) == info["pairs"]
    assert hits.sum() == info["exact_hits"] - info["false_misses"] + info["false_hits"]
    assert np.isnan(r["t"][~hits]).all() and not np.isnan(r["t"][hits]).any()
    # A hit lies on its segment, and its normal is a unit vector.
    pts = table.points().astype(float)
    a, b, t = pts[entry[hits]], pts[exit_[hits]], r["t"][hits]
    assert np.allclose(r["point"][hits], a + t[:, None] * (b - a))
    assert np.allclose(np.linalg.norm(r["normal"][hits], axis=1), 1.0, atol=1e-3)
    mine = table.certify()
    for key in ("pairs", "exact_hits", "false_hits", "false_misses"):
        assert mine[key] == info[key]


def test_one_call_over_many_pairs_equals_single_lookups(table):
    entry, exit_ = table.pairs()
    idx = np.random.default_rng(3).integers(0, len(entry), 3000)
    whole = table.lookup(entry[idx], exit_[idx])
    for i in range(0, 3000, 7):
        one = table.lookup(entry[idx[i:i + 1]], exit_[idx[i:i + 1]])
        assert one["hit"][0] == whole["hit"][i]
        assert np.array_equal(one["point"][0], whole["point"][i], equal_nan=True)


def test_same_face_pairs_miss_and_bad_ids_raise(table):
    pts = table.points()
    on_x0 = np.flatnonzero(pts[:, 0] == 0)[:5]
    r = table.lookup(on_x0, on_x0[::-1])
    assert not r["hit"].any()
    corner = np.flatnonzero((pts == 0).all(axis=1))
    assert not table.lookup(corner, corner)["hit"].any()
    with pytest.raises(lattice.InputError, match=r"exit\[1\]: .* is not a boundary point id"):
        table.lookup(np.array([0, 1]), np.array([1, table.point_count]))
    with pytest.raises(TypeError):
        table.lookup(np.array([0.5]), np.array([1.0]))


def test_open_table_rejects_other_files(tmp_path):
    bad = tmp_path / "bad.lht"
    bad.write_bytes(b"LATTICE" + bytes(200))
    with pytest.raises(lattice.InputError, match="bad.lht"):
        lattice.open_table(str(bad))


def test_rasterize_options_are_checked():
    with pytest.raises(lattice.InputError, match="max_point_error"):
        lattice.rasterize(lattice.Scene(plate4_dict()), "hair", output="/nonexistent/x.lht", max_point_error=-1.0)
    with pytest.raises(TypeError, match="sigma_inv: expected an integer"):
        lattice.rasterize(lattice.Scene(plate4_dict()), "hair", output="/nonexistent/x.lht", sigma_inv=1.5)
    with pytest.raises(lattice.InputError, match="no primitive named 'fur'"):
        lattice.rasterize(lattice.Scene(plate4_dict()), "fur", output="/nonexistent/x.lht")
