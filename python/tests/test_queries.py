"""The crowd queries on arrays: every access path gives the naive oracle's answer."""
import numpy as np
import pytest

import crowddb


def discs(n, seed):
    rng = np.random.default_rng(seed)
    return (rng.uniform(0, 50, n), rng.uniform(0, 50, n), rng.uniform(-1, 1, n),
            rng.uniform(-1, 1, n), rng.uniform(0.2, 0.6, n))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_ftc_methods_agree(seed):
    x, y, vx, vy, r = discs(300, seed)
    circles = [(25.0, 25.0, 3.0), (10.0, 40.0, 1.0)]
    polygons = [np.array([[40.0, 5.0], [45.0, 5.0], [42.0, 12.0]])]
    answers = [crowddb.ftc(x, y, vx, vy, r, 20.0, circles=circles, polygons=polygons, method=m)
               for m in crowddb.methods()["ftc"]]
    assert len(answers) >= 2
    for a in answers[1:]:
        for key in ("kind", "row", "time"):
            np.testing.assert_array_equal(a[key], answers[0][key])
    hit = answers[0]["kind"] == 1
    assert hit.any() and (answers[0]["time"][hit] <= 20).all()
    assert set(answers[0]["kind"].tolist()) == {0, 1, 2, 3}
    assert np.isinf(answers[0]["time"][answers[0]["kind"] == 0]).all()


def applicable(query, *args, **kwargs):
    """The answer of every access path that applies to these inputs (some need equal radii)."""
    out = {}
    for m in crowddb.methods()[query.__name__]:
        try:
            out[m] = query(*args, method=m, **kwargs)
        except crowddb.UsageError as e:
            assert "does not" in str(e), str(e)
    assert "naive" in out and len(out) >= 3, list(out)
    return list(out.values())


@pytest.mark.parametrize("equal_radii", [False, True])
def test_collisions_methods_agree(equal_radii):
    x, y, _, _, r = discs(500, 4)
    if equal_radii:
        r = np.full_like(r, 0.5)
    answers = applicable(crowddb.collisions, x, y, r)
    for a in answers[1:]:
        np.testing.assert_array_equal(a, answers[0])
    # Brute force in numpy.
    d = np.hypot(x[:, None] - x[None, :], y[:, None] - y[None, :])
    overlap = (d < r[:, None] + r[None, :]) & ~np.eye(len(x), dtype=bool)
    np.testing.assert_array_equal(answers[0], np.flatnonzero(overlap.any(axis=1)))


def test_field_methods_agree():
    x, y, _, _, _ = discs(200, 5)
    answers = applicable(crowddb.field, x, y, metric="l1")
    for a in answers[1:]:
        np.testing.assert_allclose(a["potential"], answers[0]["potential"], rtol=1e-9)
        np.testing.assert_allclose(a["grad_x"], answers[0]["grad_x"], rtol=1e-9, atol=1e-12)


def test_query_errors():
    with pytest.raises(crowddb.InvalidRow, match=r"polygons\[0\]: .*not simple"):
        crowddb.collisions([0.0], [0.0], [1.0], polygons=[[[0, 0], [4, 2], [4, 0], [0, 3]]])
    with pytest.raises(crowddb.InvalidRow, match=r"circles\[1\]"):
        crowddb.collisions([0.0], [0.0], [1.0], circles=[(5, 5, 1), (1, 1, -1)])
    with pytest.raises(crowddb.InputError):
        crowddb.ftc([0.0], [0.0], [1e300], [0.0], [1.0], 10.0)
    with pytest.raises(ValueError, match="expected 2 values"):
        crowddb.collisions([0.0, 1.0], [0.0, 1.0], [1.0, 1.0, 1.0])
    with pytest.raises(crowddb.UsageError):
        crowddb.ftc([0.0], [0.0], [1.0], [0.0], [1.0], 10.0, method="nope")
