"""Export of a reduced model for a controller: NPZ (every matrix), JSON (the same, readable)
and a small C source (header + implementation) of the discrete step.

Speed in the C step: a table of the discrete matrices (Ad, Bd, Cd = O Ad, Dd = O Bd) at a
list of speeds, fixed sample time; ``rom_step`` takes the speed as its last input and uses
the table entry of the nearest speed (a speed cycle with few distinct speeds is exact; for a
continuously varying speed, export a grid fine enough for its error, ``speed_step_rpm``).
No allocation, no library beyond the C standard (math.h: fabs).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from reference.rom.realtime import ROMPredictor


def discrete_tables(pred: ROMPredictor, speeds_rpm: Sequence[float]) -> dict[str, np.ndarray]:
    speeds = np.array(sorted({pred.key(s) for s in speeds_rpm}), dtype=float)
    Ad, Bd, Cd, Dd = [], [], [], []
    for s in speeds:
        Z = pred.fused(s)
        n, m = pred.n, pred.m
        Ad.append(Z[:n, :n])
        Bd.append(Z[:n, n:n + m])
        Cd.append(Z[n:, :n])
        Dd.append(Z[n:, n:n + m])
    return {"speeds_rpm": speeds, "Ad": np.array(Ad), "Bd": np.array(Bd), "Cd": np.array(Cd),
            "Dd": np.array(Dd), "offset": pred.offset.copy(), "z0": pred.state}


def _c_array(name: str, a: np.ndarray) -> str:
    dims = "".join(f"[{d}]" for d in a.shape)
    flat = ", ".join(repr(float(v)) for v in a.ravel())
    return f"static const double {name}{dims} = {{{flat}}};\n"


def write_c(tables: dict[str, np.ndarray], names: dict[str, list[str]], dt_s: float,
            out: Path, stem: str = "spindle_rom") -> list[Path]:
    """``<stem>.h`` and ``<stem>.c``: ``void rom_step(double *state, const double *inputs,
    double *outputs)``; inputs are the model's inputs then the speed [rpm]."""
    ns, n, _ = tables["Ad"].shape
    m, p = tables["Bd"].shape[2], tables["Cd"].shape[1]
    up = stem.upper()
    header = (f"/* Reduced thermal model of a spindle (spindle-verify rom): discrete step at "
              f"{dt_s:g} s.\n"
              f" * inputs: {', '.join(names['inputs'])}, speed_rpm\n"
              f" * outputs: {', '.join(names['outputs'])} (K, growth in m) */\n"
              f"#ifndef {up}_H\n#define {up}_H\n"
              f"#define {up}_STATES {n}\n#define {up}_INPUTS {m + 1}\n"
              f"#define {up}_OUTPUTS {p}\n#define {up}_SPEEDS {ns}\n"
              f"#define {up}_DT_S {dt_s!r}\n"
              f"/* the initial state (uniform initial temperature) */\n"
              f"void rom_initial_state(double *state);\n"
              f"/* one sample: state advanced in place, outputs at the sample's end */\n"
              f"void rom_step(double *state, const double *inputs, double *outputs);\n"
              f"#endif\n")
    body = [f'#include "{stem}.h"\n#include <math.h>\n\n',
            _c_array("SPEEDS", tables["speeds_rpm"]), _c_array("AD", tables["Ad"]),
            _c_array("BD", tables["Bd"]), _c_array("CD", tables["Cd"]),
            _c_array("DD", tables["Dd"]), _c_array("OFFSET", tables["offset"]),
            _c_array("Z0", tables["z0"]),
            f"""
void rom_initial_state(double *state) {{
    for (int i = 0; i < {n}; ++i) state[i] = Z0[i];
}}

void rom_step(double *state, const double *inputs, double *outputs) {{
    const double speed = inputs[{m}];
    int k = 0;
    for (int j = 1; j < {ns}; ++j)
        if (fabs(SPEEDS[j] - speed) < fabs(SPEEDS[k] - speed)) k = j;
    double next[{n}];
    for (int o = 0; o < {p}; ++o) {{
        double y = OFFSET[o];
        for (int i = 0; i < {n}; ++i) y += CD[k][o][i] * state[i];
        for (int j = 0; j < {m}; ++j) y += DD[k][o][j] * inputs[j];
        outputs[o] = y;
    }}
    for (int r = 0; r < {n}; ++r) {{
        double x = 0.0;
        for (int i = 0; i < {n}; ++i) x += AD[k][r][i] * state[i];
        for (int j = 0; j < {m}; ++j) x += BD[k][r][j] * inputs[j];
        next[r] = x;
    }}
    for (int r = 0; r < {n}; ++r) state[r] = next[r];
}}
"""]
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    h, c = out / f"{stem}.h", out / f"{stem}.c"
    from spindle.outputs import atomic_write

    atomic_write(h, lambda tmp: tmp.write_text(header, "utf-8"))
    atomic_write(c, lambda tmp: tmp.write_text("".join(body), "utf-8"))
    return [h, c]


def export(pred: ROMPredictor, speeds_rpm: Sequence[float], out: Path,
           stem: str = "spindle_rom") -> list[Path]:
    """NPZ, JSON and C of the predictor's discrete step at ``speeds_rpm``."""
    from spindle.outputs import atomic_write

    model = pred.model
    tables = discrete_tables(pred, speeds_rpm)
    names = {"inputs": list(model.input_names),
             "outputs": [*model.sensor_names, *model.readings]}
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    npz = out / f"{stem}.npz"
    atomic_write(npz, lambda tmp: np.savez(tmp, dt_s=pred.dt_s, **tables))
    js = out / f"{stem}.json"
    doc = {"dt_s": pred.dt_s, "states": pred.n, **names,
           "step": "z_k = Ad[s] z_(k-1) + Bd[s] u_k; y_k = Cd[s] z_(k-1) + Dd[s] u_k + offset, "
                   "s the nearest tabulated speed; Cd = O Ad, Dd = O Bd",
           **{k: v.tolist() for k, v in tables.items()}}
    atomic_write(js, lambda tmp: tmp.write_text(json.dumps(doc) + "\n", "utf-8"))
    return [npz, js, *write_c(tables, names, pred.dt_s, out, stem)]
