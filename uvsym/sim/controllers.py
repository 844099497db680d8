"""Discrete-time controllers: PID loops for speed, heading and depth, and line-of-sight guidance.

A controller is built symbolically once (:meth:`Autopilot.law`), so the fixed-step path, the
integrator path and generated code run the same law. Every loop runs at the simulation's
sample period ``dt`` with forward-Euler integral states, clamped against wind-up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from uvsym.errors import ScenarioError
from uvsym.kinematics import ssa

__all__ = ["Loop", "LineOfSight", "Autopilot", "CHANNELS"]

CHANNELS = ("speed", "yaw", "pitch")


@dataclass(frozen=True)
class Loop:
    """One PID loop: ``c = feedforward + kp e + ki int(e) - kd rate``, ``|int(e)| <= i_limit``.

    ``reference`` is the set-point in the measured quantity's SI unit (m/s, rad, m). For depth,
    ``kp``/``ki`` act on the depth error (rad of pitch per m) and ``kp_inner``/``kd`` on the
    pitch error; the pitch set-point is limited to ``+-theta_max`` (rad).
    """

    reference: float
    kp: float
    ki: float = 0.0
    kd: float = 0.0
    feedforward: float = 0.0
    i_limit: float = math.inf
    kp_inner: float = 1.0
    theta_max: float = math.radians(20.0)


@dataclass(frozen=True)
class LineOfSight:
    """Lookahead-based LOS guidance along waypoints, with corners rounded to circular arcs.

    waypoints: (k, 2) north-east positions (m), k >= 2; lookahead Delta (m); turn_radius (m):
    0 keeps sharp corners (a waypoint is passed within ``acceptance`` m of its end), > 0 joins
    the legs by arcs of that radius (Dubins fillets) so that the path can be flown exactly.
    The desired course is ``chi_d = chi - atan(e / Delta)`` with chi the path's direction and e
    the cross-track error (positive to starboard) of the active segment (Fossen 2021, eq. 12.79);
    the autopilot steers the heading ``chi_d - beta``, beta = atan2(v, u) the sideslip. On an arc
    the yaw rate ``r_ff = u / radius`` (signed) keeps the vehicle on it and is fed forward.
    """

    waypoints: tuple[tuple[float, float], ...]
    lookahead: float = 10.0
    acceptance: float = 2.0
    turn_radius: float = 0.0

    def __post_init__(self):
        points = np.asarray(self.waypoints, dtype=float)
        if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 2:
            raise ScenarioError("path.waypoints: expected a list of at least two [north, east] pairs (m)")
        if not np.all(np.isfinite(points)):
            row = int(np.flatnonzero(~np.all(np.isfinite(points), axis=1))[0])
            raise ScenarioError(f"path.waypoints: waypoint {row} is {points[row].tolist()}; every waypoint must be "
                                "finite (m)")
        if np.any(np.linalg.norm(np.diff(points, axis=0), axis=1) <= self.acceptance):
            raise ScenarioError("path.waypoints: every segment must be longer than path.acceptance")
        if not self.lookahead > 0.0:
            raise ScenarioError(f"path.lookahead must be positive (m), got {self.lookahead}")
        if self.turn_radius < 0.0:
            raise ScenarioError(f"path.turn_radius must be >= 0 (m), got {self.turn_radius}")
        self.segments()  # raises for corners too tight for the radius

    def segments(self) -> list[dict]:
        """The path as lines {kind, start, angle, length} and arcs {kind, center, radius, sign, phi0, length}."""
        points = np.asarray(self.waypoints, dtype=float)
        angles = [math.atan2(*(points[k + 1] - points[k])[::-1]) for k in range(len(points) - 1)]
        if self.turn_radius == 0.0:
            return [{"kind": "line", "start": points[k], "angle": angles[k],
                     "length": float(np.linalg.norm(points[k + 1] - points[k]))} for k in range(len(angles))]
        turns = [0.0] + [float(ssa(angles[k] - angles[k - 1])) for k in range(1, len(angles))] + [0.0]
        offsets = [self.turn_radius * math.tan(abs(turn) / 2.0) for turn in turns]
        for k in range(len(angles)):
            if offsets[k] + offsets[k + 1] > np.linalg.norm(points[k + 1] - points[k]) + 1e-9:
                raise ScenarioError(f"path.turn_radius: {self.turn_radius} m is too large for the leg from waypoint "
                                    f"{k} to {k + 1} (its rounded corners need {offsets[k] + offsets[k + 1]:.3g} m)")
        segments, start = [], points[0]
        for k in range(1, len(points) - 1):
            turn, offset = turns[k], offsets[k]
            if abs(turn) < 1e-9:
                continue
            sign = math.copysign(1.0, turn)
            direction_in = np.array([math.cos(angles[k - 1]), math.sin(angles[k - 1])])
            direction_out = np.array([math.cos(angles[k]), math.sin(angles[k])])
            tangent_in, tangent_out = points[k] - offset * direction_in, points[k] + offset * direction_out
            center = tangent_in + sign * self.turn_radius * np.array([-direction_in[1], direction_in[0]])
            segments.append({"kind": "line", "start": start, "angle": angles[k - 1],
                             "length": float(np.linalg.norm(tangent_in - start))})
            segments.append({"kind": "arc", "center": center, "radius": self.turn_radius, "sign": sign,
                             "phi0": math.atan2(*(tangent_in - center)[::-1]),
                             "length": self.turn_radius * abs(turn)})
            start = tangent_out
        segments.append({"kind": "line", "start": start, "angle": angles[-1],
                         "length": float(np.linalg.norm(points[-1] - start))})
        return segments

    def guidance(self, north, east, segment, speed):
        """(psi_d rad, cross-track e m, next segment index, feed-forward yaw rate rad/s) for the active segment."""
        segments = self.segments()
        direction = e = r_ff = advance = 0.0
        margin = self.acceptance if self.turn_radius == 0.0 else 0.0
        for k, seg in enumerate(segments):
            active = segment == k
            if seg["kind"] == "line":
                (x0, y0), angle = seg["start"], seg["angle"]
                along = (north - x0) * math.cos(angle) + (east - y0) * math.sin(angle)
                cross = -(north - x0) * math.sin(angle) + (east - y0) * math.cos(angle)
                chi, rate = angle, 0.0
            else:
                (cx, cy), radius, sign = seg["center"], seg["radius"], seg["sign"]
                phi = ca.atan2(east - cy, north - cx)
                along = radius * ssa(sign * (phi - seg["phi0"]))
                cross = sign * (radius - ca.sqrt((north - cx) ** 2 + (east - cy) ** 2))
                chi, rate = phi + sign * math.pi / 2.0, sign * speed / radius
            direction += ca.if_else(active, chi, 0.0)
            e += ca.if_else(active, cross, 0.0)
            r_ff += ca.if_else(active, rate, 0.0)
            if k < len(segments) - 1:
                advance += ca.if_else(ca.logic_and(active, along >= seg["length"] - margin), 1.0, 0.0)
        return direction - ca.atan(e / self.lookahead), e, segment + advance, r_ff


@dataclass(frozen=True)
class Autopilot:
    """Speed, heading (or LOS path) and depth loops, mixed onto the vehicle's inputs.

    ``outputs`` maps a channel (``speed``, ``yaw``, ``pitch``) to {input label: coefficient}.

    Direct mode (``model_based = False``): each loop's output is an actuator command and
    ``u_d = sum over channels of coefficient * command``.

    Model-based mode: the speed loop gives a surge acceleration ``a_u = kp (u_ref - u) + ki int``
    (m/s^2), the heading loop a yaw-rate set-point ``r_ref = kp e_psi + ki int`` (rad/s) and a yaw
    acceleration ``a_r = kd (r_ref - r)`` (rad/s^2). The desired forces ``M a + h(eta, nu)`` in
    surge and yaw are then turned into the speed and yaw channels' commands by inverting the
    vehicle's actuation ``tau(eta, nu, u)`` (exact where tau is affine in those inputs). Without
    faults this cancels the vehicle's own dynamics in surge and yaw, so a loop has no steady
    error; with an actuator fault and no correction it has one, which is what correction removes.
    The pitch channel is a direct command in both modes. The depth loop needs 6 DOF.
    """

    speed: Loop | None = None
    heading: Loop | None = None
    depth: Loop | None = None
    path: LineOfSight | None = None
    outputs: dict = field(default_factory=dict)
    model_based: bool = False

    @property
    def state_labels(self) -> tuple[str, ...]:
        """Controller states: integrals of the speed, heading and depth errors, LOS segment index."""
        return ("int_speed_error", "int_heading_error", "int_depth_error", "segment")

    @property
    def reference_labels(self) -> tuple[str, ...]:
        """Logged references: speed, heading, depth, pitch set-points and the cross-track error."""
        return ("u_ref", "psi_ref", "z_ref", "theta_ref", "cross_track")

    @property
    def reference_units(self) -> tuple[str, ...]:
        return ("m/s", "rad", "m", "rad", "m")

    def check(self, input_labels: tuple[str, ...], dof: int) -> None:
        """ScenarioError unless the mixing names known channels and inputs and the loops fit the DOF."""
        for channel, mix in self.outputs.items():
            if channel not in CHANNELS:
                raise ScenarioError(f"controller.outputs: unknown channel {channel!r}; known: {', '.join(CHANNELS)}")
            for label in mix:
                if label not in input_labels:
                    raise ScenarioError(f"controller.outputs.{channel}: unknown input {label!r}; "
                                        f"the vehicle's inputs are {', '.join(input_labels)}")
        if self.depth is not None and dof != 6:
            raise ScenarioError("controller.depth needs a 6-DOF vehicle")
        if self.path is not None and self.heading is None:
            raise ScenarioError("controller.path needs controller.heading (the loop that follows psi_d)")
        if self.model_based and not {"speed", "yaw"} <= set(self.outputs):
            raise ScenarioError("controller.model_based needs controller.outputs.speed and controller.outputs.yaw")

    def law(self, xc, y, dt: float, model):
        """One controller sample: (xc_next (4,), u_d (m,), references (5,)) as SX.

        xc: (4,) controller state; y: (2 dof,) measured [eta; nu]; dt: sample period (s);
        model: the Model whose inputs are commanded (and, in model-based mode, inverted).
        """
        dof = model.dof
        eta, nu = y[:dof], y[dof:]
        north, east, psi, u, r = eta[0], eta[1], eta[dof - 1], nu[0], nu[dof - 1]
        commands = {channel: 0.0 for channel in CHANNELS}
        integrals = [xc[0], xc[1], xc[2]]
        segment = xc[3]
        refs = [0.0] * 5

        def integrate(index, error, loop):
            integrals[index] = ca.fmin(ca.fmax(xc[index] + dt * error, -loop.i_limit), loop.i_limit)

        if self.speed is not None:
            loop, error = self.speed, self.speed.reference - u
            commands["speed"] = loop.feedforward + loop.kp * error + loop.ki * xc[0]
            integrate(0, error, loop)
            refs[0] = loop.reference
        if self.heading is not None:
            loop, psi_ref, r_ff = self.heading, self.heading.reference, 0.0
            if self.path is not None:  # steer the course: heading = course - sideslip atan2(v, u)
                course_ref, refs[4], segment, r_ff = self.path.guidance(north, east, xc[3], u)
                psi_ref = course_ref - ca.atan2(nu[1], u + 1e-9)
            error = ssa(psi_ref - psi)
            if self.model_based:
                commands["yaw"] = loop.kd * (r_ff + loop.feedforward + loop.kp * error + loop.ki * xc[1] - r)
            else:
                commands["yaw"] = loop.feedforward + loop.kp * error + loop.ki * xc[1] + loop.kd * (r_ff - r)
            integrate(1, error, loop)
            refs[1] = psi_ref
        if self.depth is not None:
            loop, z, theta, q = self.depth, eta[2], eta[4], nu[4]
            error = loop.reference - z
            theta_ref = ca.fmin(ca.fmax(-(loop.kp * error + loop.ki * xc[2]), -loop.theta_max), loop.theta_max)
            commands["pitch"] = loop.feedforward + loop.kp_inner * (theta_ref - theta) - loop.kd * q
            integrate(2, error, loop)
            refs[2], refs[3] = loop.reference, theta_ref
        if self.model_based:
            commands.update(self._invert_actuation(model, eta, nu, commands))
        return ca.vertcat(*integrals, segment), self._mix(model.input_labels, commands), ca.vertcat(*refs)

    def _mix(self, input_labels, commands):
        u_d = [0.0] * len(input_labels)
        for channel, mix in self.outputs.items():
            for label, coefficient in mix.items():
                u_d[input_labels.index(label)] += coefficient * commands[channel]
        return ca.vertcat(*u_d)

    def _invert_actuation(self, model, eta, nu, commands) -> dict:
        """Speed and yaw channel commands giving the surge and yaw forces M a + h (see the class docstring)."""
        dof = model.dof
        acceleration = ca.vertcat(commands["speed"], *([0.0] * (dof - 2)), commands["yaw"])
        wanted = ca.mtimes(ca.DM(model.M), acceleration) + model.h(eta, nu)
        s = ca.SX.sym("s", 2)
        u = self._mix(model.input_labels, {"speed": s[0], "yaw": s[1], "pitch": commands["pitch"]})
        tau = model.tau(eta, nu, u, 0.0, 0.0)
        rows = [0, dof - 1]
        residual = ca.vertcat(*[tau[i] - wanted[i] for i in rows])
        jac = ca.jacobian(residual, s)
        at_zero = ca.substitute(residual, s, ca.DM.zeros(2))
        solution = -ca.solve(ca.substitute(jac, s, ca.DM.zeros(2)), at_zero)
        return {"speed": solution[0], "yaw": solution[1]}
