"""What Liu et al. 2014 reports, what its reproduction must meet, and uvsym's choices.

Every number of the study that is not computed lives here.
"""

from __future__ import annotations

DOCKING, SECOND = "docking_faults", "remus100_stern_plane_bias"  # the shipped scenarios it runs
DOCK_RADIUS_M = 0.5  # capture radius of the dock's entrance funnel (uvsym's choice; the paper gives none)
PAPER = {"isolation_time_s": 3.1788, "thruster_fault_type": "bias", "f_bar_a": 13.0043,
         "rudder_fault_type": "proportional", "f_bar_p": 0.8001}
TARGETS = {"f_bar_a": 0.01, "f_bar_p": 0.001, "isolation_time_s": 5.0, "cross_track_ratio": 5.0}
TRUE = {"f_a": 13.0, "f_p": 0.8}  # the faults injected in the docking experiment
ROUNDING_SHOWN_AS_ZERO = 1e-12  # coefficients this small in derived matrices are M M^-1 rounding residues
