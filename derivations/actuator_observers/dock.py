"""Where the docking run meets the dock: arrival at its entrance plane, miss, cross-track RMS until then."""

from __future__ import annotations

import numpy as np

from uvsym.sim.scenario import Scenario

__all__ = ["arrival", "cross_track_rms", "dock_miss"]


def arrival(result, scenario: Scenario) -> tuple[int, float]:
    """(first sample at or past the dock's entrance plane, distance (m) from the dock axis there).

    The dock sits at the last waypoint facing along the final leg; (len(t), NaN) if never reached.
    """
    points = np.asarray(scenario.controller.path.waypoints, dtype=float)
    dock, direction = points[-1], points[-1] - points[-2]
    direction /= np.linalg.norm(direction)
    position = np.column_stack([result["x"]["x"], result["x"]["y"]]) - dock
    along = position @ direction
    crossed = np.flatnonzero(along >= 0.0)
    if crossed.size == 0:
        return len(result.t), float("nan")
    k = crossed[0]
    w = -along[k - 1] / (along[k] - along[k - 1])  # interpolate to the plane
    at_plane = (1 - w) * position[k - 1] + w * position[k]
    return int(k), float(abs(at_plane @ np.array([-direction[1], direction[0]])))


def dock_miss(result, scenario: Scenario) -> float:
    """Distance (m) from the dock axis where the vehicle crosses the entrance plane."""
    return arrival(result, scenario)[1]


def cross_track_rms(result, scenario: Scenario) -> float:
    """RMS cross-track error (m) from the start until the vehicle reaches the dock."""
    k = arrival(result, scenario)[0]
    return float(np.sqrt(np.mean(result["reference"]["cross_track"][:k] ** 2)))
