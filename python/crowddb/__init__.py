"""crowddb: crowd simulation as an in-memory database.

Load a scenario of any format the ``crowddb`` command reads, or build a world from numpy
arrays, step it, and read the agents table as numpy views without copying::

    import crowddb
    sim = crowddb.Simulation.from_file("scenarios/airport.json")
    for _ in range(100):
        sim.step()
    x, y = sim.agents.x, sim.agents.y      # read-only views, valid until the next step

Units are metres and seconds. Errors are ``crowddb.Error`` subclasses carrying the same one-line
messages as the command line (``InputError`` is also a ``ValueError``, ``IOError`` an ``OSError``).
The SDF functions are in ``crowddb.sdf``.
"""

from ._core import (
    Agents,
    Error,
    InputError,
    InvalidRow,
    IOError,
    Simulation,
    UsageError,
    World,
    collisions,
    field,
    ftc,
    methods,
)
from . import sdf

__all__ = [
    "Agents",
    "Error",
    "InputError",
    "InvalidRow",
    "IOError",
    "Simulation",
    "UsageError",
    "World",
    "collisions",
    "field",
    "ftc",
    "methods",
    "sdf",
]
