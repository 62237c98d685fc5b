"""P1 under imposed temperature fields: the reference (scikit-fem, P2) against CalculiX (CAX6
on the same mesh and constraints), and P1's sensitivity to the rolling-element layer's
modulus (issue 15 §2: where a 0.8 % P1 gap to a separately built model can come from).

    python benchmarks/p1_fields.py [--spec spl2782] [--level 1] [--moduli 0.1 1 10 100]
                                   [--out docs/figures/p1-fields.json]

Prints, per field (uniform 10 K, linear in r and in z to 10 K, quadratic in r, the nominal
steady field): P1 from both codes [um] and their relative difference; then P1 per field
with the layer modulus (rolling_layer_equivalent, E = 50 GPa in the spec) times each factor.
Without ccx on the PATH the first table is skipped (and left out of the figures file).
The figures go to ``--out`` (with the date, the commit and the ccx version), from which
docs/verification.md quotes them (tests/test_docs_study_figures.py).
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from compare.crosscheck.ccx import ccx_version, run_ccx
from compare.crosscheck.ccx_mesh import ccx_mesh
from compare.crosscheck.deck import write_elastic
from compare.crosscheck.elastic_data import elastic_constraints
from compare.crosscheck.frd import read_frd
from compare.crosscheck.twin import reading_rows
from reference.simulation import ReferenceModel
from spindle.spec import Spec
from spindle.spec_reader import load_spec

sys.path.insert(0, str(Path(__file__).resolve().parent))
from figures import write_figures  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
LAYER = "rolling_layer_equivalent"


def fields(model: ReferenceModel) -> dict[str, np.ndarray]:
    """Nodal temperatures [K] of the imposed fields on ``model``'s P2 basis."""
    spec = model.spec
    z, r = model.thermal.basis.doflocs
    T0 = spec.T_initial_K
    return {"uniform": T0 + 10.0 + 0.0 * z,
            "r_linear": T0 + 10.0 * r / r.max(),
            "r_quadratic": T0 + 10.0 * (r / r.max()) ** 2,
            "z_linear": T0 + 10.0 * z / z.max(),
            "nominal": model.steady(spec.default_load_case()).T}


def p1_reference(model: ReferenceModel, T: np.ndarray) -> float:
    """P1 [m] of the reference's elastic model for nodal temperatures ``T`` [K]."""
    return float(model.elastic.growth(model.elastic.displacement(T))["P1"])


def p1_ccx(model: ReferenceModel, T: np.ndarray) -> tuple[float, str]:
    """P1 [m] from CalculiX on the same mesh and constraints, and the ccx version."""
    cm = ccx_mesh(model)
    with tempfile.TemporaryDirectory(prefix="spindle-p1-") as tmp:
        deck = write_elastic(model, cm, elastic_constraints(model, cm), Path(tmp) / "p1.inp",
                             T, model.spec.T_ambient_K)
        U = read_frd(run_ccx(deck, 600))["U"]
        version = ccx_version(deck.with_suffix(".log"))
    return float(reading_rows(model)["P1"] @ U[:model.thermal.basis.N, 1]), version


def with_layer_modulus(spec: Spec, factor: float) -> Spec:
    mats = dict(spec.materials)
    mats[LAYER] = replace(mats[LAYER], E_Pa=mats[LAYER].E_Pa * factor)
    return replace(spec, materials=mats)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default="spl2782")
    ap.add_argument("--level", type=int, default=1)
    ap.add_argument("--moduli", type=float, nargs="+", default=[0.1, 1.0, 10.0, 100.0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "p1-fields.json")
    args = ap.parse_args(argv)
    spec = load_spec(args.spec)
    t = time.perf_counter()
    model = ReferenceModel(spec, args.level, 2)
    imposed = fields(model)
    figures = {"spec": args.spec, "level": args.level, "layer": LAYER, "fields": list(imposed)}
    if shutil.which("ccx"):
        print(f"{args.spec}, level {args.level}: P1 [um], reference against CalculiX")
        print(f"{'field':12s} {'reference':>10s} {'ccx':>10s} {'relative':>10s}")
        rows, version = [], ""
        for k, T in imposed.items():
            a, (b, version) = p1_reference(model, T), p1_ccx(model, T)
            rows.append({"field": k, "reference_um": a * 1e6, "ccx_um": b * 1e6})
            print(f"{k:12s} {a * 1e6:10.5f} {b * 1e6:10.5f} {(b - a) / a:+10.1e}")
        figures["ccx"] = {"solver": f"CalculiX {version}", "rows": rows}
    else:
        print("ccx not on the PATH: the CalculiX table is skipped")
    print(f"\nP1 [um] with the {LAYER} modulus times a factor (same fields)")
    print(f"{'factor':>7s} " + " ".join(f"{k:>11s}" for k in imposed))
    figures["moduli"] = []
    for f in args.moduli:
        m = ReferenceModel(with_layer_modulus(spec, f), args.level, 2)
        p1 = {k: p1_reference(m, T) * 1e6 for k, T in imposed.items()}
        figures["moduli"].append({"factor": f, "P1_um": p1})
        print(f"{f:7g} " + " ".join(f"{v:11.4f}" for v in p1.values()))
    figures["runtime_s"] = round(time.perf_counter() - t, 1)
    print(f"\n{figures['runtime_s']:.0f} s")
    write_figures(args.out, "python benchmarks/p1_fields.py", figures)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
