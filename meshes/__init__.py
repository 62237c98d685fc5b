"""Meshes of the (z, r) half-section built from a spec's CAD dimensions.

:func:`build_mesh` gives level L of a nested family: level 0 is a conforming triangulation
of the parts' sections, each further level halves every element edge (refinement ratio 2).
Subdomains are named per part, boundaries per named surface of the spec.
"""

from meshes.build import Region, SpindleMesh, build_mesh

__all__ = ["Region", "SpindleMesh", "build_mesh"]
