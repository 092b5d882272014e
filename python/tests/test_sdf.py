"""crowddb.sdf: the same answers as sdfsched."""
import json
import os
import subprocess

import pytest

import crowddb
from crowddb import sdf


def sdfsched(*args):
    exe = os.environ.get("SDFSCHED")
    if not exe:
        pytest.skip("SDFSCHED is not set (ctest sets it)")
    return json.loads(subprocess.run([exe, *args, "--json"], check=True, capture_output=True,
                                     text=True).stdout)


@pytest.mark.parametrize("name", ["cd2dat.json", "cd2dat.xml", "chain65537.json"])
def test_load_repetitions_schedule(source_dir, name):
    path = str(source_dir / "tests" / "sdf" / "data" / name)
    g = sdf.load(path)
    q = sdf.repetitions(g)
    assert q == sdfsched("repetitions", path)["repetitions"]
    assert list(q) == g.actors
    s = sdf.schedule(g)
    assert s["complete"] and s["firings"] == sum(q.values())
    assert s["firings"] == sdfsched("schedule", path)["period_firings"]
    assert sdf.from_json(g.to_json()).channels == g.channels


def test_errors(source_dir):
    with pytest.raises(crowddb.InputError, match="inconsistent"):
        sdf.repetitions(sdf.load(str(source_dir / "tests" / "sdf" / "data" / "inconsistent.json")))
    g = sdf.load(str(source_dir / "tests" / "sdf" / "data" / "deadlock.json"))
    s = sdf.schedule(g)
    assert not s["complete"] and s["stuck"]
    with pytest.raises(crowddb.IOError):
        sdf.load("/nonexistent.json")
    with pytest.raises(crowddb.InputError, match="<json>"):
        sdf.from_json("{")
