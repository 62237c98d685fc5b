"""The input contract measured (issue 14): a corpus of malformed inputs (specs, cycles, bench
files, command-line options), each run through the ``spindle-verify`` command in-process, and
the outcomes counted.

    python benchmarks/bench_input_contract.py [--specs 200] [--cycles 80] [--bench 60]
                                              [--seed 1] [--json OUT.json]
                                              [--figures docs/figures/input-contract.json]

Each case writes its files into a fresh folder, runs one command with ``--out`` inside it and
records: the exit status; whether an exception escaped (a traceback); the number of message
lines on stderr and whether the first names a field and a fix; the seconds it took; whether an
input changed; whether anything was written on a refusal; and, for a run that succeeded,
whether its summary holds an impossible result (a temperature at or below 0 K, above iron's
melting point, or NaN).
Spec mutations that happen to be valid run a level-0 solve and count as accepted. Prints the
counts; the issue's figures: 100 % of the refused cases clean (exit 2, one line naming field
and fix), 0 tracebacks, 0 runs past 60 s, 0 impossible results written, 0 inputs modified.
The counts go to ``--figures`` (JSON with the date and the commit), from which docs/spec.md's
paragraph is checked (tests/test_docs_figures.py); ``--json`` writes every case's outcome.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import random
import re
import sys
import tempfile
import time
from pathlib import Path

from figures import write_figures
from verdicts import run_verdicts

from spindle.results import T_MELT_K

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "spindle" / "data" / "specs"
CYCLES = ROOT / "spindle" / "data" / "cycles"
NUMBER = re.compile(r"^(\s*\w+\s*=\s*)(-?[0-9][0-9.e+-]*)(.*)$", re.MULTILINE)
BAD_VALUES = ["nan", "inf", "-1.0", "0.0", "1e300", "-1e300", "1e-300", "9" * 400, '"text"', "[]"]
BAD_CELLS = ["nan", "inf", "-1e308", "1e308", "abc", "1e400", "-5", "0x10", "∞", "1e-320"]


def spec_cases(rng: random.Random, n: int) -> list[dict]:
    out = []
    for name in ("fin-shaft", "spl2782"):
        text = (SPECS / f"{name}.toml").read_text(encoding="utf-8")
        for m in NUMBER.finditer(text):
            for v in BAD_VALUES:
                out.append({"kind": "spec", "label": f"{name}:{m.group(0).strip()[:30]}->{v[:12]}",
                            "files": {"s.toml": text[:m.start(2)] + v + text[m.end(2):]},
                            "argv": ["solve", "s.toml", "--level", "0"]})
    rng.shuffle(out)
    return out[:n]


def cycle_cases(rng: random.Random, n: int) -> list[dict]:
    steps = "speed_rpm,duration_s,load_torque_Nm\n1000,3600,0\n3000,1800,10\n0,3600,0\n"
    series = "time_s,speed_rpm,T_env_C,T_coolant_C\n0,0,20,19.8\n600,3000,20.2,19.9\n3600,0,20.5,20\n"
    toml = (CYCLES / "spl-16h.toml").read_text(encoding="utf-8")
    out = []
    for base, name in ((steps, "steps"), (series, "series")):
        lines = base.split("\n")
        for i in range(1, len(lines) - 1):
            for j in range(len(lines[i].split(","))):
                for v in BAD_CELLS:
                    cells = lines[i].split(",")
                    cells[j] = v
                    text = "\n".join([*lines[:i], ",".join(cells), *lines[i + 1:]])
                    out.append({"kind": "cycle", "label": f"{name}[{i},{j}]={v}",
                                "files": {"c.csv": text}})
        out.append({"kind": "cycle", "label": f"{name}:semicolons",
                    "files": {"c.csv": base.replace(",", ";")}})
        out.append({"kind": "cycle", "label": f"{name}:trailing comma",
                    "files": {"c.csv": base.replace("\n", ",\n")}})
        out.append({"kind": "cycle", "label": f"{name}:binary",
                    "files": {"c.csv": base.encode() + bytes(range(256))}})
    for m in NUMBER.finditer(toml):
        for v in ("nan", "-1.0", "1e-9", "1e300", '"x"'):
            out.append({"kind": "cycle", "label": f"toml:{m.group(0).strip()[:24]}->{v}",
                        "files": {"c.toml": toml[:m.start(2)] + v + toml[m.end(2):]}})
    rng.shuffle(out)
    for c in out[:n]:
        c["argv"] = ["solve", "fin-shaft", "--level", "0", "--dt", "600", "--cycle",
                     next(iter(c["files"]))]
    return out[:n]


def bench_cases(rng: random.Random, n: int) -> list[dict]:
    """Bench files broken in a way the reader must refuse (a valid one would start a fit)."""
    head = ("# spindle: spl2782\ntime_s,speed_rpm,power_kW,T_env_C,T_coolant_C,T1_C,T2_C,"
            "T_stator_C,P1_um\n")
    rows = [f"{10 * i},{0 if i < 60 else 3000},0.4,20,19.8,{20 + i / 100:.2f},20.1,20.3,"
            f"{i / 200:.2f}" for i in range(400)]
    good = head + "\n".join(rows) + "\n"
    breakers = {
        "time_s text": lambda r: r.replace("100,", "abc,", 1),
        "time repeats": lambda r: r.replace("\n110,", "\n100,", 1),
        "time 1e15": lambda r: r.rstrip("\n").rsplit("\n", 1)[0] + "\n1e15,0,0,20,20,20,20,20,0\n",
        "kelvin": lambda r: r.replace("T1_C", "T1_C").replace(",20.0", ",293.1"),
        "1e308 in T1": lambda r: r.replace(",20.50,", ",1e308,", 1),
        "negative speed": lambda r: r.replace(",3000,", ",-3000,", 1),
        "speed 1e9": lambda r: r.replace(",3000,", ",1e9,", 1),
        "power in W": lambda r: r.replace(",0.4,", ",38000,", 1),
        "no time column": lambda r: r.replace("time_s,", "t,", 1),
        "no speed column": lambda r: r.replace(",speed_rpm,", ",speed,", 1),
        "no channel": lambda r: re.sub(r",T1_C,T2_C,T_stator_C,P1_um", ",a_x,b_x,c_x,d_x", r),
        "empty": lambda r: "",
        "header only": lambda r: head,
        "ten rows": lambda r: "\n".join(r.split("\n")[:12]) + "\n",
        "binary": lambda r: r[:500].encode() + bytes(range(256)) * 8,
        "semicolons": lambda r: r.replace(",", ";"),
        "torque 1e9": lambda r: r.replace("P1_um\n", "P1_um,load_torque_Nm\n").replace(
            "\n", ",1e9\n").replace("P1_um,load_torque_Nm,1e9", "P1_um,load_torque_Nm"),
    }
    out = []
    for label, f in breakers.items():
        text = f(good)
        out.append({"kind": "bench", "label": label, "files": {"run.csv": text}})
    for v in BAD_CELLS:
        for col in (0, 1):
            lines = good.split("\n")
            k = rng.randrange(3, len(lines) - 2)
            cells = lines[k].split(",")
            cells[col] = v
            lines[k] = ",".join(cells)
            out.append({"kind": "bench", "label": f"column {col} line {k + 1} = {v}",
                        "files": {"run.csv": "\n".join(lines)}})
    rng.shuffle(out)
    for c in out:
        c["argv"] = ["fit", "run.csv", "--spec", "spl2782"]
    return out[:n]


def option_cases() -> list[dict]:
    opts = {"solve": (["solve", "fin-shaft"], {"--dt": "x", "--speed": "nan", "--level": "9",
                                                "--theta": "-1"}),
            "study": (["study", "fin-shaft"], {"--workers": "0", "--levels": "a"}),
            "fit": (["fit", "missing.csv"], {"--alpha": "2", "--fit-fraction": "1.5",
                                              "--cv-blocks": "1", "--blocks": "0",
                                              "--nodes": "1", "--fem-level": "-1"}),
            "synth": (["synth"], {"--seed": "x", "--effect": "nope"})}
    out = []
    for cmd, (argv, bad) in opts.items():
        for k, v in bad.items():
            for value in (v, "inf", "", "1e400"):
                out.append({"kind": "option", "label": f"{cmd} {k} {value!r}", "files": {},
                            "argv": [*argv, k, value]})
    out.append({"kind": "option", "label": "no command", "files": {}, "argv": []})
    out.append({"kind": "option", "label": "unknown command", "files": {}, "argv": ["solv"]})
    return out


def run_case(case: dict) -> dict:
    from compare.cli import main

    with tempfile.TemporaryDirectory() as d:
        folder = Path(d)
        for name, text in case["files"].items():
            (folder / name).write_bytes(text if isinstance(text, bytes) else text.encode())
        before = {p.name: p.read_bytes() for p in folder.iterdir()}
        out = folder / "out"
        argv = [str(folder / a) if a in case["files"] else a for a in case["argv"]]
        if argv and argv[0] in ("solve", "study", "fit", "synth"):
            argv += ["--out", str(out if argv[0] != "synth" else folder / "synth.csv")]
            argv += ["--quiet"] if argv[0] != "synth" else []
            argv += ["--no-pictures"] if argv[0] in ("solve", "fit") else []
        err, t0 = io.StringIO(), time.perf_counter()
        traceback = None
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            try:
                code = main(argv)
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else 1
            except BaseException as exc:  # noqa: BLE001  (what the contract forbids)
                code, traceback = -1, f"{type(exc).__name__}: {exc}"[:300]
        seconds = time.perf_counter() - t0
        lines = [ln for ln in err.getvalue().splitlines() if ln.strip()]
        after = {p.name: p.read_bytes() for p in folder.iterdir() if p.name in before}
        written = [p.name for p in folder.iterdir() if p.name not in before]
        impossible = False
        summary = out / "summary.json"
        if code == 0 and summary.exists():
            text = summary.read_text(encoding="utf-8")
            doc = json.loads(text)
            temps = [v for v in (doc.get("sensors_C") or {}).values() if v is not None]
            impossible = "NaN" in text or any(not -273.15 < v <= T_MELT_K - 273.15
                                              for v in temps)
    first = lines[0] if lines else ""
    row = {"kind": case["kind"], "label": case["label"], "exit": code, "traceback": traceback,
           "lines": len(lines), "seconds": round(seconds, 2),
           "clean": code == 2 and len(lines) >= 1 and ("fix:" in first or "usage:" in first
                                                       or "error:" in first),
           "one_line": code != 2 or len(lines) == 1 or first.startswith("usage:"),
           "written_on_refusal": bool(written) and code != 0,
           "inputs_modified": after != before, "impossible": impossible, "message": first[:200]}
    # the contract held: no traceback, a refusal clean and in one line, nothing impossible
    # written, no input touched, nothing left by a refusal, within a minute
    row["right"] = not (row["traceback"] or (code != 0 and not row["clean"])
                        or not row["one_line"] or impossible or row["inputs_modified"]
                        or row["written_on_refusal"] or seconds > 60)
    return row


class Case(dict):
    """A case (files, command line) with the label the runner's progress prints."""

    @property
    def label(self) -> str:
        return f"{self['kind']} {self['label']}"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--specs", type=int, default=200, help="spec mutations (default 200)")
    ap.add_argument("--cycles", type=int, default=80, help="cycle mutations (default 80)")
    ap.add_argument("--bench", type=int, default=60, help="bench-file breaks (default 60)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=2, help="cases at a time (default 2)")
    ap.add_argument("--json", type=Path, help="also write every case's outcome here")
    ap.add_argument("--figures", type=Path,
                    default=ROOT / "docs" / "figures" / "input-contract.json",
                    help="the counts the docs quote (default docs/figures/input-contract.json)")
    args = ap.parse_args(argv)
    import compare.entry  # noqa: F401  (one BLAS thread, as the command runs)

    rng = random.Random(args.seed)
    cases = (spec_cases(rng, args.specs) + cycle_cases(rng, args.cycles)
             + bench_cases(rng, args.bench) + option_cases())
    t0 = time.perf_counter()
    rows = run_verdicts(
        run_case, [Case(c) for c in cases], workers=args.workers, json_path=args.json,
        header="cases where the contract failed:",
        line=lambda r: "" if r["right"] else (f"  ! {r['kind']} {r['label']}: exit {r['exit']} "
                                              f"{r['traceback'] or ''} {r['message']}"))
    c = counts(rows, time.perf_counter() - t0)
    kinds = ", ".join(f"{k} {n}" for k, n in c["kinds"].items())
    print(f"{c['cases']} cases ({kinds}); {c['wall_s']:.0f} s")
    print(f"  accepted (exit 0): {c['accepted']}; refused: {c['refused']}")
    print(f"  refused cleanly (exit 2, a message naming field and fix): "
          f"{c['refused_cleanly']} of {c['refused']}")
    print(f"  refusals with more than one message line: {c['refusals_multi_line']}")
    print(f"  tracebacks: {c['tracebacks']}")
    print(f"  slower than 60 s: {c['slower_than_60_s']} (slowest {c['slowest_s']:.1f} s)")
    print(f"  impossible results written: {c['impossible_results']}")
    print(f"  inputs modified: {c['inputs_modified']}")
    print(f"  files written on a refusal: {c['written_on_refusal']}")
    write_figures(args.figures, " ".join(["python benchmarks/bench_input_contract.py",
                            *(argv if argv is not None else sys.argv[1:])]),
                  {"seed": args.seed, "cores": os.cpu_count(),
                   "load_average": round(os.getloadavg()[0], 1), **c})
    print(f"wrote {args.figures}")


def counts(rows: list[dict], wall_s: float) -> dict:
    """The outcomes counted: cases per kind, accepted and refused, and every way the contract
    can fail (the figures docs/spec.md quotes)."""
    refused = [r for r in rows if r["exit"] != 0]
    return {"cases": len(rows), "wall_s": round(wall_s, 1),
            "kinds": {k: sum(r["kind"] == k for r in rows)
                      for k in ("spec", "cycle", "bench", "option")},
            "accepted": len(rows) - len(refused), "refused": len(refused),
            "refused_cleanly": sum(r["clean"] for r in refused),
            "refusals_multi_line": sum(not r["one_line"] for r in refused),
            "tracebacks": sum(r["traceback"] is not None for r in rows),
            "slower_than_60_s": sum(r["seconds"] > 60 for r in rows),
            "slowest_s": max(r["seconds"] for r in rows),
            "impossible_results": sum(r["impossible"] for r in rows),
            "inputs_modified": sum(r["inputs_modified"] for r in rows),
            "written_on_refusal": sum(r["written_on_refusal"] for r in rows)}


if __name__ == "__main__":
    main()
