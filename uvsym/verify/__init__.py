"""Machine-checked claims: symbolic identities and Lyapunov/LMI certificates, as data."""

from uvsym.verify.certificate import STATUSES, Certificate
from uvsym.verify.exact import schur, shifted_hurwitz
from uvsym.verify.identity import prove_identity
from uvsym.verify.interval import IntervalFunction
from uvsym.verify.lmi import BlockLMI, block_lmi, solve_block_lmi
from uvsym.verify.lms import lms_step_claim
from uvsym.verify.lyapunov import discrete_lyapunov_decrease, exact_positive_definite, lyapunov_decrease
from uvsym.verify.region import region_decrease
from uvsym.verify.synthesis import GainSynthesis, synthesize_observer_gain
from uvsym.verify.uio import exact_zoh, uio_existence_claim

__all__ = ["STATUSES", "Certificate", "GainSynthesis", "IntervalFunction", "exact_positive_definite",
           "BlockLMI", "block_lmi", "solve_block_lmi",
           "lyapunov_decrease", "prove_identity", "region_decrease", "synthesize_observer_gain",
           "exact_zoh", "uio_existence_claim", "discrete_lyapunov_decrease", "schur", "shifted_hurwitz",
           "lms_step_claim"]
