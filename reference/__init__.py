"""The FEM reference: axisymmetric heat conduction (and, later, thermoelasticity) in
scikit-fem on meshes of the spec. It is the ground truth the lumped models are judged by.
"""

from reference.results import SteadyResult, TransientResult
from reference.thermal import ThermalModel

__all__ = ["SteadyResult", "ThermalModel", "TransientResult"]
