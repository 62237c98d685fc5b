"""The FEM reference: axisymmetric heat conduction and quasi-static thermoelasticity in
scikit-fem on meshes of the spec. It is the ground truth the lumped models are judged by.
"""

from reference.elastic import ThermoelasticModel
from reference.results import SteadyResult, TransientResult
from reference.simulation import ReferenceModel
from reference.thermal import ThermalModel

__all__ = ["ReferenceModel", "SteadyResult", "ThermalModel", "ThermoelasticModel",
           "TransientResult"]
