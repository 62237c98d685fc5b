"""``mount_conduction``: heat leaves the housing's front through its mounting flange into the
machine structure, which stays near the room's temperature. No signature test: a conductance
to the room acts like the housing's air film, so the open-loop fit judges it, against the
generic competitor."""

from __future__ import annotations

from dataclasses import replace

from compare.fit.effects.base import Effect
from compare.fit.params import Param
from lumped.blocks import Convection, FixedTemperature
from spindle.loads import SpeedTable


class MountConduction(Effect):
    name = "mount_conduction"
    explanation = ("Heat leaves the housing through its mounting flange into the machine "
                   "structure, which stays near the room temperature.")
    params = (Param("G_mount_W_K", "W/K", 0.0, 0.0, 200.0,
                    "conductance from the housing's front face to the structure", log=False,
                    source="a bolted flange of 0.01-0.05 m2 at 500-5000 W/m2/K: 5-250 W/K"),)
    in_conductance = ("G_mount_W_K",)
    hint = ("the housing's mounting (its flange to the machine structure): a path to the room "
            "the spec lacks")

    def extend_network(self, net, spec, power_measured):
        hous = [p for p in net.parts.values() if p.part.role == "housing"][0]
        amb = next(b for b in net.network.blocks if isinstance(b, FixedTemperature)
                   and b.source == "ambient")
        c = net.network.add(Convection("mount", Gc_W_K=1.0))  # set per parameter set
        net.network.connect(hous.masses[-1].block.port, c.port_a)
        net.network.connect(c.port_b, amb.port)

    def edge_conductances(self, theta):
        return {"mount": theta.get("G_mount_W_K", 0.0)}

    def draw(self, rng):
        return {"G_mount_W_K": float(rng.uniform(2.0, 5.0))}

    def synth_spec(self, spec, truth):
        """The housing's front-face film raised by G / A (A its area)."""
        from spindle.faces import exposed_faces, surface_faces

        faces = exposed_faces(spec)
        front = [s for s in spec.surfaces if s.side == "front" and s.h_W_m2K is not None
                 and any(spec.part(p).role == "housing" for p in s.parts)]
        if not front:
            raise ValueError("mount_conduction needs a convective front face of the housing")
        s = front[0]
        area = sum(f.area_m2 for f in surface_faces(s, faces, spec))
        h = SpeedTable(s.h_W_m2K.speed_rpm,
                       tuple(v + truth["G_mount_W_K"] / area for v in s.h_W_m2K.values))
        return replace(spec, surfaces=tuple(replace(x, h_W_m2K=h) if x is s else x
                                            for x in spec.surfaces))
