"""Synchronous Data-Flow graphs: load SDF3 XML or JSON graphs, repetitions vectors, static
schedules and the thesis's online rule (docs/sdf.md; the ``sdfsched`` command does the same)."""

from ._core import _sdf as _impl

Graph = _impl.Graph
load = _impl.load
from_json = _impl.from_json
repetitions = _impl.repetitions
schedule = _impl.schedule
simulate = _impl.simulate

__all__ = ["Graph", "load", "from_json", "repetitions", "schedule", "simulate"]
