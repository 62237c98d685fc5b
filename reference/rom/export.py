"""Export of a reduced model for a controller: NPZ (every matrix), JSON (the same, readable)
and a small C source (header + implementation) of the discrete step.

Speed in the C step: a table of the discrete matrices (Ad, Bd, Cd = O Ad, Dd = O Bd) at a
list of speeds, fixed sample time; between two table speeds the matrices are interpolated
linearly, and the error this adds is measured and stated (the interpolated against the exact
model over a staircase through every midpoint, in K and m: ``interpolation`` in the JSON, a
comment in the header). A speed outside the table is held at the table's end and reported in the
returned status (never a silent clamp).

What a CNC has: ``rom_step_cnc`` takes the speed [rpm], the load torque [N m] and the ambient
and coolant temperatures [K]; the heat of each source comes from the spec's power balance,
tabulated over speed and torque and interpolated bilinearly (``rom_losses``; its error against
the Python power balance is measured at every cell's centre and stated). No allocation, no
library beyond the C standard. The generated C compiles without warnings under
``-std=c99 -Wall -Wextra -pedantic -Werror`` (tests/test_rom.py builds it so).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from reference.rom.realtime import ROMPredictor

#: status bits of the C functions: the speed below or above the table, the torque outside it
STATUS = {"SPEED_BELOW": 1, "SPEED_ABOVE": 2, "TORQUE_OUTSIDE": 4}
#: torque points of the loss table (0 .. the largest torque), enough that the copper loss's
#: quadratic law is interpolated to under 1 % of its range (checked and stated at export)
TORQUE_POINTS = 11
#: the loss table reaches this multiple of the drive's nominal torque
TORQUE_OVERLOAD = 1.5


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


def _locate(table: np.ndarray, x: float) -> tuple[int, int, float]:
    """(k, k1, w): x between table[k] and table[k1] at weight w (held at the ends), as the
    C code does."""
    if len(table) == 1 or x <= table[0]:
        return 0, 0, 0.0
    if x >= table[-1]:
        return len(table) - 1, len(table) - 1, 0.0
    k = int(np.searchsorted(table, x, side="right") - 1)
    return k, k + 1, float((x - table[k]) / (table[k + 1] - table[k]))


#: how long :func:`interpolation_errors` holds each mid speed of its staircase [s]: two
#: hours, as the plateaus of a run-in cycle, about the housing's time constant, so that each
#: step carries the history of the ones before it
HOLD_S = 2 * 3600.0


def _staircase(steps_of, n: int, z0: np.ndarray, plan: list[tuple[float, np.ndarray]],
               steps: int) -> np.ndarray:
    """Outputs of the fused steps ``steps_of(speed)`` ([[Ad, Bd, 0], [Cd, Dd, offset]]) over
    the ``plan`` of (speed, constant inputs) held ``steps`` samples each, from the state z0."""
    x, out = np.asarray(z0, dtype=float).copy(), []
    for speed, u in plan:
        Z = steps_of(speed)
        xu = np.r_[x, u, 1.0]
        for _ in range(steps):
            y = Z @ xu
            xu[:n] = y[:n]
            out.append(y[n:])
        x = xu[:n]
    return np.array(out)


def loss_tables(drive, source_names: Sequence[str], defaults: Sequence[float],
                speeds_rpm: np.ndarray) -> dict[str, np.ndarray]:
    """Heat per source [W] over the speeds [rpm] and a torque grid [N m] from 0 to
    TORQUE_OVERLOAD times the nominal torque (only 0 without a nominal point); sources the
    power balance does not feed keep the spec's value (``defaults``)."""
    top = 0.0
    if drive.nominal is not None and drive.nominal.speed_rpm > 0:
        top = TORQUE_OVERLOAD * drive.nominal.P_mech_W / (drive.nominal.speed_rpm * np.pi / 30)
    torques = np.linspace(0.0, top, TORQUE_POINTS) if top > 0 else np.zeros(1)

    def heat(n: float, M: float) -> list[float]:
        h = drive.heat_W(n, M)
        return [float(h.get(s, d)) for s, d in zip(source_names, defaults, strict=True)]

    table = np.array([[heat(n, M) for M in torques] for n in speeds_rpm])
    return {"torques_Nm": torques, "loss_W": table, "heat": heat}


def _bilinear(speeds, torques, table, n: float, M: float) -> np.ndarray:
    k, k1, w = _locate(speeds, n)
    j, j1, v = _locate(torques, M)
    low = table[k, j] + v * (table[k, j1] - table[k, j])
    high = table[k1, j] + v * (table[k1, j1] - table[k1, j])
    return low + w * (high - low)


def interpolation_errors(pred: ROMPredictor, tables: dict, losses: dict | None,
                         n_sensors: int) -> dict[str, float]:
    """What interpolation adds: the largest difference in an output (sensors [K], growth [m])
    between the interpolated matrices and the exact ones over a staircase through every
    midpoint of the speed table, up and down, each held HOLD_S under that speed's heat at no
    load (the spec's sources without a drive), ambient and coolant at the spec's initial
    temperature; and the largest error of the bilinear losses [W] against the power balance at
    each cell's centre."""
    speeds, n = tables["speeds_rpm"], pred.n
    T0 = float(pred.model.spec.T_initial_K)
    own = np.array([float(d.power_W(0.0)) for d in pred.model.source_defaults])
    mids = list(0.5 * (speeds[:-1] + speeds[1:]))
    plan = [(s, np.r_[np.array(losses["heat"](s, 0.0)) if losses is not None else own, T0, T0])
            for s in mids + mids[-2::-1]]

    def interpolated(speed: float) -> np.ndarray:
        k, k1, w = _locate(speeds, speed)
        lerp = {key: tables[key][k] + w * (tables[key][k1] - tables[key][k])
                for key in ("Ad", "Bd", "Cd", "Dd")}
        return np.block([[lerp["Ad"], lerp["Bd"], np.zeros((n, 1))],
                         [lerp["Cd"], lerp["Dd"], tables["offset"][:, None]]])

    steps = max(int(round(HOLD_S / pred.dt_s)), 1)
    d = (np.abs(_staircase(interpolated, n, tables["z0"], plan, steps)
                - _staircase(pred.fused, n, tables["z0"], plan, steps)) if plan
         else np.zeros((1, len(tables["offset"]))))
    worst_W = None
    if losses is not None:
        worst_W = 0.0
        torques = losses["torques_Nm"]
        cells = 0.5 * (torques[:-1] + torques[1:]) if len(torques) > 1 else torques
        for s_mid in mids:
            for M in cells:
                got = _bilinear(speeds, torques, losses["loss_W"], s_mid, M)
                worst_W = max(worst_W, float(np.abs(got - losses["heat"](s_mid, M)).max()))
    return {"speed_staircase_K": float(d[:, :n_sensors].max(initial=0.0)),
            "speed_staircase_m": float(d[:, n_sensors:].max(initial=0.0)),
            "losses_W": worst_W}


def _c_array(name: str, a: np.ndarray) -> str:
    """A static const double array with one brace level per dimension (-Wmissing-braces)."""
    def nest(x: np.ndarray) -> str:
        if x.ndim == 1:
            return "{" + ", ".join(repr(float(v)) for v in x) + "}"
        return "{" + ", ".join(nest(row) for row in x) + "}"

    dims = "".join(f"[{d}]" for d in a.shape)
    return f"static const double {name}{dims} = {nest(np.asarray(a, dtype=float))};\n"


def write_c(tables: dict[str, np.ndarray], names: dict[str, list[str]], dt_s: float,
            out: Path, stem: str = "spindle_rom", losses: dict | None = None,
            errors: dict | None = None) -> list[Path]:
    """``<stem>.h`` and ``<stem>.c`` (module docstring): ``rom_initial_state``, ``rom_step``
    (inputs: the model's inputs then the speed [rpm]) and, with ``losses``, ``rom_losses``
    and ``rom_step_cnc``. Every step returns its status bits (STATUS)."""
    ns, n, _ = tables["Ad"].shape
    m, p = tables["Bd"].shape[2], tables["Cd"].shape[1]
    up = stem.upper()
    errors = errors or {}
    err = ""
    if errors:
        err = (f" * speed interpolation between table entries: outputs within "
               f"{errors['speed_staircase_K']:.2g} K and {errors['speed_staircase_m']:.2g} m of "
               f"the exact model (a staircase through every midpoint, {HOLD_S / 3600:g} h each)\n")
        if errors.get("losses_W") is not None:
            err += (f" * losses: bilinear in speed and torque, within {errors['losses_W']:.2g} W "
                    f"of the power balance (at every cell's centre)\n")
    sources = names["inputs"][:m - 2]
    cnc = ""
    if losses is not None:
        nt = len(losses["torques_Nm"])
        cnc = (f"#define {up}_SOURCES {m - 2}\n#define {up}_TORQUES {nt}\n"
               f"/* heat per source [W] ({', '.join(sources)}) at a speed [rpm] and a load\n"
               f" * torque [N m] (0 .. {losses['torques_Nm'][-1]:.4g}); returns the status */\n"
               f"int rom_losses(double speed_rpm, double load_torque_Nm, double *heat_W);\n"
               f"/* one sample from what a CNC has: speed [rpm], load torque [N m], ambient and\n"
               f" * coolant temperatures [K]; returns the status of both look-ups */\n"
               f"int rom_step_cnc(double *state, double speed_rpm, double load_torque_Nm,\n"
               f"                 double T_ambient_K, double T_coolant_K, double *outputs);\n")
    header = (f"/* Reduced thermal model of a spindle (spindle-verify rom): discrete step at "
              f"{dt_s:g} s.\n"
              f" * inputs: {', '.join(names['inputs'])}, speed_rpm\n"
              f" * outputs: {', '.join(names['outputs'])} (K, growth in m)\n"
              f" * speeds tabulated: {tables['speeds_rpm'][0]:g} .. "
              f"{tables['speeds_rpm'][-1]:g} rpm ({ns} entries)\n{err} */\n"
              f"#ifndef {up}_H\n#define {up}_H\n"
              f"#define {up}_STATES {n}\n#define {up}_INPUTS {m + 1}\n"
              f"#define {up}_OUTPUTS {p}\n#define {up}_SPEEDS {ns}\n"
              f"#define {up}_DT_S {dt_s!r}\n"
              + "".join(f"#define {up}_{k} {v}\n" for k, v in STATUS.items()) +
              "/* status: 0, or the bits above; outside a table the value is held at its end */\n"
              "/* the initial state (uniform initial temperature) */\n"
              "void rom_initial_state(double *state);\n"
              "/* one sample: state advanced in place, outputs at the sample's end */\n"
              "int rom_step(double *state, const double *inputs, double *outputs);\n"
              f"{cnc}#endif\n")
    body = [f'#include "{stem}.h"\n\n',
            _c_array("SPEEDS", tables["speeds_rpm"]), _c_array("AD", tables["Ad"]),
            _c_array("BD", tables["Bd"]), _c_array("CD", tables["Cd"]),
            _c_array("DD", tables["Dd"]), _c_array("OFFSET", tables["offset"]),
            _c_array("Z0", tables["z0"]),
            f"""
/* where x lies in table t of length len: entries *k, *k1 and the weight *w of *k1 */
static int locate(const double *t, int len, double x, int *k, int *k1, double *w) {{
    int j;
    *w = 0.0;
    if (len == 1 || x <= t[0]) {{
        *k = *k1 = 0;
        return x < t[0] ? 1 : (x > t[0] ? 2 : 0);
    }}
    if (x >= t[len - 1]) {{
        *k = *k1 = len - 1;
        return x > t[len - 1] ? 2 : 0;
    }}
    for (j = 0; j < len - 2 && t[j + 1] <= x; ++j) {{
    }}
    *k = j;
    *k1 = j + 1;
    *w = (x - t[j]) / (t[j + 1] - t[j]);
    return 0;
}}

void rom_initial_state(double *state) {{
    int i;
    for (i = 0; i < {n}; ++i) state[i] = Z0[i];
}}

int rom_step(double *state, const double *inputs, double *outputs) {{
    int k, k1, i, j, o, r;
    double w, next[{n}];
    const int status = locate(SPEEDS, {ns}, inputs[{m}], &k, &k1, &w);
    for (o = 0; o < {p}; ++o) {{
        double y = OFFSET[o];
        for (i = 0; i < {n}; ++i) y += (CD[k][o][i] + w * (CD[k1][o][i] - CD[k][o][i])) * state[i];
        for (j = 0; j < {m}; ++j) y += (DD[k][o][j] + w * (DD[k1][o][j] - DD[k][o][j])) * inputs[j];
        outputs[o] = y;
    }}
    for (r = 0; r < {n}; ++r) {{
        double x = 0.0;
        for (i = 0; i < {n}; ++i) x += (AD[k][r][i] + w * (AD[k1][r][i] - AD[k][r][i])) * state[i];
        for (j = 0; j < {m}; ++j) x += (BD[k][r][j] + w * (BD[k1][r][j] - BD[k][r][j])) * inputs[j];
        next[r] = x;
    }}
    for (r = 0; r < {n}; ++r) state[r] = next[r];
    return status;
}}
"""]
    if losses is not None:
        nt, ms = len(losses["torques_Nm"]), m - 2
        body += [_c_array("TORQUES", losses["torques_Nm"]), _c_array("LOSS", losses["loss_W"]),
                 f"""
int rom_losses(double speed_rpm, double load_torque_Nm, double *heat_W) {{
    int k, k1, j, j1, s;
    double w, v;
    int status = locate(SPEEDS, {ns}, speed_rpm, &k, &k1, &w);
    if (locate(TORQUES, {nt}, load_torque_Nm, &j, &j1, &v) != 0) status |= 4;
    for (s = 0; s < {ms}; ++s) {{
        const double low = LOSS[k][j][s] + v * (LOSS[k][j1][s] - LOSS[k][j][s]);
        const double high = LOSS[k1][j][s] + v * (LOSS[k1][j1][s] - LOSS[k1][j][s]);
        heat_W[s] = low + w * (high - low);
    }}
    return status;
}}

int rom_step_cnc(double *state, double speed_rpm, double load_torque_Nm,
                 double T_ambient_K, double T_coolant_K, double *outputs) {{
    double inputs[{m + 1}];
    const int status = rom_losses(speed_rpm, load_torque_Nm, inputs);
    inputs[{ms}] = T_ambient_K;
    inputs[{ms + 1}] = T_coolant_K;
    inputs[{m}] = speed_rpm;
    return status | rom_step(state, inputs, outputs);
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
           stem: str = "spindle_rom", drive=None) -> list[Path]:
    """NPZ, JSON and C of the predictor's discrete step at ``speeds_rpm``; with ``drive``
    (spindle.drive.drive_for(spec)), the loss table and the CNC step too. The JSON's
    ``interpolation`` holds the measured errors (module docstring)."""
    from spindle.outputs import atomic_write

    model = pred.model
    tables = discrete_tables(pred, speeds_rpm)
    names = {"inputs": list(model.input_names),
             "outputs": [*model.sensor_names, *model.readings]}
    losses = None
    if drive is not None:
        losses = loss_tables(drive, model.source_names,
                             [float(d.power_W(0.0)) for d in model.source_defaults],
                             tables["speeds_rpm"])
    errors = interpolation_errors(pred, tables, losses, len(model.sensor_names))
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    extra = {} if losses is None else {"torques_Nm": losses["torques_Nm"],
                                       "loss_W": losses["loss_W"]}
    npz = out / f"{stem}.npz"
    atomic_write(npz, lambda tmp: np.savez(tmp, dt_s=pred.dt_s, **tables, **extra))
    js = out / f"{stem}.json"
    doc = {"dt_s": pred.dt_s, "states": pred.n, **names,
           "step": "z_k = Ad(s) z_(k-1) + Bd(s) u_k; y_k = Cd(s) z_(k-1) + Dd(s) u_k + offset, "
                   "the matrices interpolated linearly between the tabulated speeds and held "
                   "at the table's ends; Cd = O Ad, Dd = O Bd",
           "status_bits": STATUS, "interpolation": errors,
           **{k: v.tolist() for k, v in {**tables, **extra}.items()}}
    atomic_write(js, lambda tmp: tmp.write_text(json.dumps(doc) + "\n", "utf-8"))
    return [npz, js, *write_c(tables, names, pred.dt_s, out, stem, losses, errors)]
