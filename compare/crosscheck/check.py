"""The cross-check: solve a spec with the reference and with CalculiX on the same P2 mesh, and
with the quadrature twin; compare at the sensors and the growth readings (P1, TCP)."""

from __future__ import annotations

import math
import shutil
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from compare.crosscheck.ccx import CCX_MISSING, ccx_version, run_ccx
from compare.crosscheck.deck import write_elastic, write_thermal_deck
from compare.crosscheck.frd import half_ulp, read_frd
from compare.crosscheck.result import CrosscheckResult
from compare.crosscheck.twin import reading_rows, twin_gains, twin_thermal
from reference.simulation import ReferenceModel
from spindle.errors import InputError, SolverError
from spindle.loads import LoadCase
from spindle.spec import Spec
from spindle.spec_reader import load_spec
from spindle.units import MESH_LEVEL_MAX

#: ccx expands a CAX6 section into a 2-degree C3D15 wedge (+-1 degree): the hoop strain of the
#: expanded element is exact only to O(theta^2), theta = 1 degree in radians; the growth
#: readings' allowance for it [-]
EXPANSION_REL = (math.pi / 180.0) ** 2


@contextmanager
def ccx_folder() -> Iterator[Path]:
    """A temporary folder for ccx's decks, results and logs: removed when the cross-check
    gets through, kept when ccx fails (a SolverError), so that the log its message names can
    still be read."""
    work = Path(tempfile.mkdtemp(prefix="spindle-ccx-"))
    try:
        yield work
    except SolverError:
        raise
    except BaseException:
        shutil.rmtree(work, ignore_errors=True)
        raise
    shutil.rmtree(work, ignore_errors=True)


def crosscheck(spec: Spec | str | Path, level: int = 1, case: LoadCase | None = None, *,
               keep_dir: str | Path | None = None, timeout_s: float = 600) -> CrosscheckResult:
    """Solve ``spec`` at mesh ``level`` (P2) with the reference and with CalculiX; compare.

    ``case`` is a steady load case (default: the spec's own operating point), evaluated at
    t = 0. ccx runs in a temporary folder, which is kept when ccx fails (its message names the
    log there); ``keep_dir`` keeps its decks, result files and logs there. Raises SolverError
    when ccx is missing or fails.
    """
    if shutil.which("ccx") is None:
        raise SolverError(CCX_MISSING)
    if not isinstance(spec, Spec):
        spec = load_spec(spec)
    if not 0 <= int(level) <= MESH_LEVEL_MAX:
        raise InputError("crosscheck", "level", f"{level} is out of range",
                         f"give a level between 0 and {MESH_LEVEL_MAX}")
    case = case or spec.default_load_case()
    times: dict[str, float] = {}
    t0 = time.perf_counter()
    model = ReferenceModel(spec, int(level), 2)
    res = model.steady(case)
    res.check_plausible(spec.path)  # before ccx is asked to solve the same impossible case
    times["reference_s"] = time.perf_counter() - t0
    th = model.thermal
    names, pts = th.sensor_points()
    P = th.probe_matrix(pts)
    with ccx_folder() as work:
        t1 = time.perf_counter()
        # a file name: a spec's name may be any text (a 5000-character one was "File name
        # too long"); the decks' names only need to tell the thermal from the elastic one
        name = "".join(c if c.isalnum() or c in "-_" else "_" for c in spec.name)[:64] or "spec"
        info, cm, data, con = write_thermal_deck(model, case, work / f"{name}.inp")
        times["export_s"] = time.perf_counter() - t1
        t1 = time.perf_counter()
        frd = read_frd(run_ccx(info["thermal_deck"], timeout_s))
        times["ccx_thermal_s"] = time.perf_counter() - t1
        N = th.basis.N
        if frd["T"] is None or len(frd["T"]) < N or not np.all(np.isfinite(frd["T"][:N])):
            raise SolverError(f"{info['thermal_deck']}: ccx wrote no temperature for some "
                              f"nodes; fix: see {info['thermal_deck'].with_suffix('.log')}")
        rise = frd["T"][:N]
        datum = info["T_datum_K"]
        T_ccx = datum + rise
        rows = reading_rows(model)
        g_ccx: dict[str, float] = {}
        g_print: dict[str, float] = {}
        U_ccx = None
        if rows:
            t1 = time.perf_counter()
            deck = write_elastic(model, cm, con, work / f"{name}_elastic.inp", T_ccx, datum)
            info["elastic_deck"] = deck
            U = read_frd(run_ccx(deck, timeout_s))["U"]
            times["ccx_elastic_s"] = time.perf_counter() - t1
            if U is None or len(U) < N or not np.all(np.isfinite(U[:N, :2])):
                raise SolverError(f"{deck}: ccx wrote no displacement for some nodes; fix: "
                                  f"see {deck.with_suffix('.log')}")
            U_ccx = U[:N, 1]
            ulp = half_ulp(U_ccx)
            for k, row in rows.items():
                g_ccx[k] = float(row @ U_ccx)
                g_print[k] = float(np.abs(row) @ ulp)
        version = ccx_version(info["thermal_deck"].with_suffix(".log"))
        if keep_dir is not None:
            keep = Path(keep_dir)
            keep.mkdir(parents=True, exist_ok=True)
            for f in work.iterdir():
                if f.suffix in (".inp", ".frd", ".log"):
                    shutil.copy2(f, keep / f.name)
    t1 = time.perf_counter()
    T_twin = twin_thermal(model, cm, data)
    gains = twin_gains(model, cm, con)
    times["twin_s"] = time.perf_counter() - t1
    T0 = spec.T_initial_K
    g_twin = {k: float(g @ (T_twin - T0)) for k, g in gains.items()}
    g_twin_ccx = {k: float(g @ (T_ccx - T0)) for k, g in gains.items()}
    g_exp = {k: float(EXPANSION_REL * (np.abs(rows[k]) @ np.abs(U_ccx))) for k in gains}
    nodal = {"max_abs_diff_K": float(np.abs(T_ccx - res.T).max()),
             "max_abs_ccx_minus_twin_K": float(np.abs(T_ccx - T_twin).max()),
             "max_abs_skfem_minus_twin_K": float(np.abs(res.T - T_twin).max()),
             "max_print_bound_K": float(half_ulp(rise).max()),
             "max_rise_K": float(np.abs(rise).max())}
    sensors = th.spec.temperature_sensors()
    return CrosscheckResult(
        spec=spec.name, level=int(level), case=case.name, speed_rpm=float(case.speed_rpm(0.0)),
        T_ambient_K=float(case.T_ambient_K(0.0)), sensors=names,
        z_m=np.array([s.z for s in sensors]), r_m=np.array([s.r for s in sensors]),
        T_skfem_K=P @ res.T, T_ccx_K=P @ T_ccx, T_twin_K=P @ T_twin,
        T_print_K=abs(P) @ half_ulp(rise),
        growth_skfem_m=dict(res.growth_m), growth_ccx_m=g_ccx, growth_twin_m=g_twin,
        growth_twin_ccxT_m=g_twin_ccx, growth_print_m=g_print, growth_expansion_m=g_exp,
        nodal=nodal, deck={k: (v.name if isinstance(v, Path) else v) for k, v in info.items()},
        timings_s=times, ccx_version=version)
