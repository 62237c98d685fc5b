"""Reduced-order models of the FEM reference (issue 17): build, simulate, stream, export."""

from reference.rom.build import BuildReport, build_rom
from reference.rom.model import ReducedModel

__all__ = ["BuildReport", "ReducedModel", "build_rom"]
