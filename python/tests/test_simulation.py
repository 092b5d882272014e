"""crowddb.Simulation: files and arrays in, steps, zero-copy columns, changes mid-run, output."""
import json
import sqlite3
import subprocess
import threading
import time

import numpy as np
import pytest

import crowddb


def corridor(n_each=5):
    w = crowddb.World((0, 0, 20, 6))
    w.add_goal("east", x=19, y=3, radius=0.5)
    w.add_goal("west", x=1, y=3, radius=0.5)
    y = 0.6 + 0.5 * np.arange(n_each)
    east = w.insert_agents(np.full(n_each, 2.0), y, "east", radius=0.2)
    west = w.insert_agents(np.full(n_each, 18.0), y, "west", radius=0.2, pref_speed=1.2)
    return w, east, west


def test_from_file_matches_the_command_line(source_dir, cli, tmp_path):
    scenario = source_dir / "scenarios" / "serpentine.json"
    summary = tmp_path / "s.json"
    subprocess.run([cli, "run", str(scenario), "--ticks", "150", "--no-output", "--quiet",
                    "--summary-json", str(summary)], check=True)
    want = json.loads(summary.read_text())["state_hash"]
    for threads in (1, 2):
        sim = crowddb.Simulation.from_file(scenario, threads=threads)
        m = sim.step(150)
        assert m["tick"] == 150 and sim.tick == 150
        assert f"{sim.state_hash:016x}" == want


def test_columns_are_read_only_views_without_copies(source_dir):
    sim = crowddb.Simulation.from_file(source_dir / "scenarios" / "airport.json")
    sim.step(3)
    a = sim.agents
    x1, x2 = a.x, sim.agents.x
    assert len(a) == x1.shape[0] > 0
    assert not x1.flags.writeable and not x1.flags.owndata
    # Two reads are views of the same memory: nothing was copied.
    assert x1.__array_interface__["data"][0] == x2.__array_interface__["data"][0]
    with pytest.raises(ValueError):
        x1[0] = 1.0
    for name, dtype in [("x", np.float64), ("y", np.float64), ("vx", np.float64),
                        ("vy", np.float64), ("radius", np.float64), ("pref_speed", np.float64),
                        ("max_speed", np.float64), ("target_x", np.float64),
                        ("goal", np.uint32), ("id", np.uint64), ("state", np.uint8)]:
        col = getattr(a, name)
        assert col.dtype == dtype and col.shape == (len(a),), name
    assert len(np.unique(a.id)) == len(a)
    # A view keeps the simulation alive.
    x = crowddb.Simulation.from_file(source_dir / "scenarios" / "circle.json").agents.x
    assert np.isfinite(x).all()


def test_world_from_arrays_with_changes_mid_run():
    w, east, west = corridor()
    assert east.dtype == np.uint64 and len(east) == len(west) == 5
    assert w.agent_count == 10
    sim = crowddb.Simulation(w, dt=0.1, threads=2)
    with pytest.raises(crowddb.UsageError, match="given to a Simulation"):
        w.add_circle(5, 5, 1)
    sim.step(10)
    late = sim.insert_agents([10.0], [5.5], "west", radius=0.2)
    sim.erase(int(east[0]))
    sim.retarget(int(west[0]), "east")
    sim.step()
    ids = set(sim.agents.id.tolist())
    assert int(late[0]) in ids and int(east[0]) not in ids
    row = sim.agents.id.tolist().index(int(west[0]))
    assert sim.agents.goal[row] == sim.goal("east")
    for _ in range(400):
        if len(sim.agents) == 0:
            break
        m = sim.step()
        assert m["overlapping_pairs"] == 0
    assert len(sim.agents) == 0 and sim.arrived_total == 10


def test_same_world_and_seed_same_hash_on_any_thread_count():
    hashes = set()
    for threads in (1, 2):
        w, _, _ = corridor()
        sim = crowddb.Simulation(w, threads=threads, seed=7)
        sim.step(60)
        hashes.add(sim.state_hash)
    assert len(hashes) == 1


def test_errors_are_typed_and_name_the_field(tmp_path):
    with pytest.raises(crowddb.IOError, match="nope.json"):
        crowddb.Simulation.from_file(tmp_path / "nope.json")
    bad = tmp_path / "bad.json"
    bad.write_text('{"bounds": [0, 0, 10, 10], "dt": -1}')
    with pytest.raises(crowddb.InputError, match="bad.json: /dt"):
        crowddb.Simulation.from_file(bad)
    with pytest.raises(ValueError):  # InputError is a ValueError too
        crowddb.Simulation.from_file(bad)
    w = crowddb.World((0, 0, 10, 10))
    w.add_goal("g", x=5, y=5)
    with pytest.raises(crowddb.InvalidRow) as e:
        w.insert_agents([1.0, 2.0], [1.0, 2.0], "g", radius=[0.2, -1.0])
    assert e.value.field == "radius" and "agent 1" in str(e.value)
    assert w.agent_count == 0  # a bad row inserts nothing
    with pytest.raises(crowddb.InputError, match="no goal named 'h'"):
        w.insert_agents([1.0], [1.0], "h")
    with pytest.raises(ValueError, match="3 values for 2 agents"):
        w.insert_agents([1.0, 2.0], [1.0, 2.0, 3.0], "g")
    w.add_circle(8, 8, 1)
    for x, y, where in [(-1.0, 5.0, "outside the bounds"), (8.2, 8.2, "inside circle obstacle 0")]:
        with pytest.raises(crowddb.InvalidRow, match=where) as e:
            w.insert_agents([x], [y], "g")
        assert e.value.field == "x"
    with pytest.raises(crowddb.InvalidRow, match="duplicate goal name 'g'"):
        w.add_goal("g", x=1, y=1)
    with pytest.raises(crowddb.InputError):
        crowddb.World((10, 0, 0, 10))  # inverted bounds
    with pytest.raises(crowddb.InputError):
        crowddb.World((0, 0, float("nan"), 10))
    with pytest.raises(crowddb.InputError, match="dt"):
        crowddb.Simulation(w, dt=0)


def test_record_writes_a_trajectory_file(tmp_path):
    w, _, _ = corridor(3)
    out = tmp_path / "run.sqlite"
    with crowddb.Simulation(w) as sim:
        sim.record(out, every=5)
        sim.step(20)
    con = sqlite3.connect(out)
    frames = [r[0] for r in con.execute("SELECT DISTINCT frame FROM trajectory_data ORDER BY frame")]
    assert frames == [0, 1, 2, 3, 4]  # frame = tick / every (JuPedSim: frames at its frame rate)
    (rows,) = con.execute("SELECT count(*) FROM trajectory_data WHERE frame = 0").fetchone()
    assert rows == 6


def test_the_trajectory_file_is_not_closed_or_replaced_mid_step(tmp_path):
    # step() runs without the GIL and writes through the recording: another thread's close()
    # or record() meanwhile is refused, not a race; afterwards both work.
    w = crowddb.World((0, 0, 400, 400))
    w.add_goal("g", x=399, y=200, radius=1)
    gx, gy = np.meshgrid(np.arange(5.0, 395.0, 3.0), np.arange(5.0, 395.0, 3.0))
    w.insert_agents(gx.ravel(), gy.ravel(), "g", radius=0.3)
    sim = crowddb.Simulation(w)
    sim.record(tmp_path / "run.sqlite", every=25)
    stepping = threading.Thread(target=sim.step, args=(200,))
    stepping.start()
    # Until the thread is inside step(), record() says "already recording" (and changes nothing).
    deadline = time.monotonic() + 30
    while True:
        with pytest.raises(crowddb.UsageError) as refused:
            sim.record(tmp_path / "other.sqlite")
        if "another thread" in str(refused.value) or time.monotonic() > deadline:
            break
        time.sleep(0.001)
    assert "another thread" in str(refused.value)
    with pytest.raises(crowddb.UsageError, match="another thread"):
        sim.close()  # the step takes seconds
    stepping.join()
    assert sim.tick == 200
    sim.close()
    con = sqlite3.connect(tmp_path / "run.sqlite")
    assert con.execute("SELECT max(frame) FROM trajectory_data").fetchone() == (8,)


def test_checkpoint_round_trip(source_dir):
    a = crowddb.Simulation.from_file(source_dir / "scenarios" / "bottleneck.json")
    a.step(30)
    state = a.save_state()
    a.step(30)
    b = crowddb.Simulation.from_file(source_dir / "scenarios" / "bottleneck.json")
    b.restore_state(state)
    b.step(30)
    assert a.state_hash == b.state_hash
    with pytest.raises(crowddb.InputError, match="damaged"):
        b.restore_state(state[:-1] + bytes([state[-1] ^ 1]))
