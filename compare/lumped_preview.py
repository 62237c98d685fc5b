"""Lumped models against the FEM reference on spl2782 (a preview of the harness).

    python -m compare.lumped_preview [--level 2] [--nodes 5 11 21 41]

Prints a Markdown table: nominal steady state (T1, T2, T_stator, the worst of the 22 array
sensors against the reference, P1, TCP) and the spl-16h peaks of T1 and P1.
"""

from __future__ import annotations

import argparse

KELVIN = 273.15


def main(argv: list[str] | None = None) -> None:
    from lumped import build
    from reference import ReferenceModel
    from spindle.cycles import load_cycle
    from spindle.drive import cycle_load_case, drive_for
    from spindle.spec import load_spec

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--level", type=int, default=2)
    ap.add_argument("--nodes", type=int, nargs="+", default=[5, 11, 21, 41])
    args = ap.parse_args(argv)
    spec = load_spec("spl2782")
    drive = drive_for(spec)
    nom = cycle_load_case(spec, load_cycle("nominal"), drive)
    cyc = cycle_load_case(spec, load_cycle("spl-16h"), drive)
    T0 = float(cyc.T_ambient_K(0))
    ref = ReferenceModel(spec, args.level)
    r = ref.steady(nom)
    tr = ref.transient(cyc, 120.0, T0=T0)
    rows = [(f"FEM P2 level {args.level}", r.sensors, r.growth_m, tr.sensor("T1").max(),
             tr.growth_m["P1"].max())]
    for n in args.nodes:
        m = build(spec, n)
        st, ts = m.steady(nom), m.transient(cyc, 120.0, T0=T0)
        rows.append((f"lumped {n}", st.sensors, st.growth_m, ts.sensor("T1").max(),
                     ts.growth_m["P1"].max()))
    arrays = [s.name for s in spec.temperature_sensors() if s.array]
    print("| model | T1 °C | T2 °C | T_stator °C | max error on the array sensors [K] | P1 µm "
          "| TCP µm | cycle T1 peak °C | cycle P1 peak µm |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, s, g, t1, p1 in rows:
        err = max(abs(s[k] - r.sensors[k]) for k in arrays)
        print(f"| {name} | {s['T1'] - KELVIN:.2f} | {s['T2'] - KELVIN:.2f} | "
              f"{s['T_stator'] - KELVIN:.1f} | {err:.2f} | {g['P1'] * 1e6:.2f} | "
              f"{g['TCP'] * 1e6:.2f} | {t1 - KELVIN:.2f} | {p1 * 1e6:.2f} |")


if __name__ == "__main__":
    main()
