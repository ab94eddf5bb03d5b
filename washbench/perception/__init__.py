"""Pilot perception: vestibular models (otolith, semicircular canals) and perception thresholds."""

from washbench.perception.thresholds import ZACHARIAS, Thresholds
from washbench.perception.vestibular import (
    CanalParams,
    OtolithParams,
    Perceived,
    VestibularModel,
    VestibularParams,
    canal_model,
    otolith_model,
)

__all__ = [
    "ZACHARIAS",
    "CanalParams",
    "OtolithParams",
    "Perceived",
    "Thresholds",
    "VestibularModel",
    "VestibularParams",
    "canal_model",
    "otolith_model",
]
