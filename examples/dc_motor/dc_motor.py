"""A permanent-magnet DC motor written as a uvsym System: the plant module a scenario file names.

    L di/dt = V - R i - k omega,      J domega/dt = k i - b omega - T_load

States i (A) and omega (rad/s), input V (V), disturbance T_load (N m), measured outputs the
current and the speed. ``dc_motor(**parameters)`` is what ``plant = "dc_motor:dc_motor"`` calls,
with the scenario's ``[plant_parameters]`` as keyword arguments.
"""

from uvsym.systems import signals, system

NOMINAL = {"R": 1.0, "L": 0.5, "k": 0.05, "J": 0.01, "b": 0.001}  # ohm, H, N m/A (= V s/rad), kg m^2, N m s


def dc_motor(**parameters):
    """The DC motor System; keyword arguments override NOMINAL (SI units)."""
    unknown = sorted(set(parameters) - set(NOMINAL))
    if unknown:
        raise TypeError(f"unknown parameter {unknown[0]!r}; known: {', '.join(NOMINAL)}")
    c = {**NOMINAL, **parameters}
    return system(
        "dc_motor", "permanent-magnet DC motor, armature voltage in, current and speed measured",
        x=signals(("i", "A", "armature current"), ("omega", "rad/s", "shaft speed"), group="state"),
        u=signals(("V", "V", "armature voltage"), group="input"),
        d=signals(("T_load", "N m", "load torque"), group="disturbance"),
        y=signals(("i_meas", "A", "measured current"), ("omega_meas", "rad/s", "measured speed"), group="output"),
        rhs=lambda x, u, d, p: [(u[0] - c["R"] * x[0] - c["k"] * x[1]) / c["L"],
                                (c["k"] * x[0] - c["b"] * x[1] - d[0]) / c["J"]],
        output=lambda x, u, p: [x[0], x[1]],
    )
