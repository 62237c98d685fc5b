"""What both models read: the spindle description (spec), materials, load cases and sensors.

`reference/` (FEM) and `lumped/` (function blocks) both import this package and never each
other, so a comparison between them measures the models, not two readings of the input.
All quantities are SI (m, K, W, s, Pa); degrees Celsius and micrometres appear only at the
edges, in fields that name their unit (``T1_C``, ``P1_um``).
"""

from spindle.errors import SpecError, SpindleVerifyError
from spindle.loads import LoadCase, TimeSeries
from spindle.spec import Spec
from spindle.spec_reader import load_spec, shipped_specs

__all__ = [
    "LoadCase",
    "Spec",
    "SpecError",
    "SpindleVerifyError",
    "TimeSeries",
    "load_spec",
    "shipped_specs",
]
